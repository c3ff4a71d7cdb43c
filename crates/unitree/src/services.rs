//! Unitree's services over `rt/api/<service>/request` and `/response` (spec `unitree-dds.md`):
//! the request/answer protocol as a [`Service`] of `robowire-dds`, request ids as Unitree's SDKs
//! make them, the calls robowire makes (`motion_switcher` CheckMode, ReleaseMode and SelectMode,
//! the Go2's `sport` StandDown), and [`ServiceHandle`]: a service called from any executor.

use std::sync::Arc;
use std::sync::atomic::{AtomicI64, Ordering};
use std::time::Duration;

use robowire_dds::rpc::{RpcClient, Service};
use robowire_dds::{DdsError, Participant};
use robowire_tap::Tap;
use unitree_proto::api::{self, ApiRequest, ApiResponse, RequestHeader, status};

use crate::UnitreeError;

/// ReleaseMode calls a release makes at most before it gives up ([`UnitreeError::NotReleased`]).
pub const RELEASE_ATTEMPTS: u32 = 10;

/// `text` with JSON's string escapes (quote, backslash, control characters).
fn json_escaped(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if u32::from(c) < 0x20 => out.push_str(&format!("\\u{:04x}", u32::from(c))),
            c => out.push(c),
        }
    }
    out
}

/// Unitree's request/answer protocol: `unitree_api` `Request_`/`Response_`, paired by
/// `identity.id`.
#[derive(Debug)]
pub struct UnitreeApi;

impl Service for UnitreeApi {
    type Request = ApiRequest;
    type Answer = ApiResponse;

    fn request_id(request: &ApiRequest) -> i64 {
        request.header.id
    }

    fn answer_id(answer: &ApiResponse) -> i64 {
        answer.id
    }
}

/// A client of one of the robot's services. Create it on a tokio runtime (its answers are read
/// by a task there); call it on that runtime. [`LowLevel`](crate::LowLevel) makes its own; this
/// is for a program on its own participant.
#[derive(Debug)]
pub struct ServiceClient {
    service: &'static str,
    rpc: RpcClient<UnitreeApi>,
    next_id: AtomicI64,
}

impl ServiceClient {
    /// A client of `service` (`motion_switcher`, `sport`, …).
    pub fn new(participant: &Participant, service: &'static str) -> Result<Self, DdsError> {
        Self::tapped(participant, service, None)
    }

    /// As [`new`](Self::new), its requests and answers handed to `tap` (a link described by
    /// `unitree_proto::description::API_CLIENT`).
    pub fn tapped(participant: &Participant, service: &'static str, tap: Option<Tap>) -> Result<Self, DdsError> {
        let rpc = RpcClient::tapped(
            participant,
            &api::request_topic(service).to_string(),
            &api::response_topic(service).to_string(),
            tap,
        )?;
        // Request ids as Unitree's SDKs make them: the clock in ns, unique per call.
        let first_id = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .ok()
            .and_then(|t| i64::try_from(t.as_nanos()).ok())
            .unwrap_or(1);
        Ok(Self { service, rpc, next_id: AtomicI64::new(first_id) })
    }

    /// Calls `api_id` with `parameter` (JSON by convention) and waits up to `timeout` for its
    /// answer. An answer with an error code is [`UnitreeError::Refused`]; one for another API id is
    /// [`UnitreeError::Unexpected`].
    pub async fn call(&self, api_id: i64, parameter: &str, timeout: Duration) -> Result<ApiResponse, UnitreeError> {
        let id = self.next_id.fetch_add(1, Ordering::Relaxed);
        let request =
            ApiRequest { header: RequestHeader::call(id, api_id), parameter: parameter.into(), binary: Vec::new() };
        let service = self.service;
        let answer = self.rpc.call(request, timeout).await.map_err(|source| UnitreeError::Service {
            service,
            api_id,
            source,
        })?;
        if answer.api_id != api_id {
            return Err(UnitreeError::Unexpected { service, data: format!("an answer for api {}", answer.api_id) });
        }
        if answer.code != status::OK {
            return Err(UnitreeError::Refused { service, api_id, code: answer.code });
        }
        Ok(answer)
    }
}

/// Runs `task` on `runtime` (a device's receive thread, where its services' answers arrive) and
/// waits for its outcome, on any executor. [`UnitreeError::Closed`] if the runtime has shut down.
pub(crate) async fn on_runtime<T, F>(runtime: &tokio::runtime::Handle, task: F) -> Result<T, UnitreeError>
where
    T: Send + 'static,
    F: Future<Output = Result<T, UnitreeError>> + Send + 'static,
{
    let (tx, rx) = tokio::sync::oneshot::channel();
    runtime.spawn(async move {
        let _ = tx.send(task.await);
    });
    rx.await.map_err(|_| UnitreeError::Closed)?
}

/// One of the robot's services as a device calls it: a [`ServiceClient`] made on the device's
/// receive thread (its answers are read there), called from any executor, with the device's
/// service timeout. Made by [`LowLevel::service`](crate::LowLevel::service); cheap to clone.
#[derive(Debug, Clone)]
pub struct ServiceHandle {
    client: Arc<ServiceClient>,
    runtime: tokio::runtime::Handle,
    timeout: Duration,
}

impl ServiceHandle {
    /// A client of `service` on `participant`, its answers read by a task of `runtime`.
    pub(crate) fn new(
        participant: &Participant,
        service: &'static str,
        runtime: &tokio::runtime::Handle,
        timeout: Duration,
        tap: Option<Tap>,
    ) -> Result<Self, DdsError> {
        // The client's answer task is spawned on the current runtime: the device's.
        let _on_device = runtime.enter();
        let client = Arc::new(ServiceClient::tapped(participant, service, tap)?);
        Ok(Self { client, runtime: runtime.clone(), timeout })
    }

    /// The service's name.
    pub fn service(&self) -> &'static str {
        self.client.service
    }

    /// Calls `api_id` with `parameter` without waiting: the call runs on the device's receive
    /// thread, its outcome handed to `answered` there.
    pub(crate) fn call_detached(
        &self,
        api_id: i64,
        parameter: String,
        answered: impl FnOnce(Result<ApiResponse, UnitreeError>) + Send + 'static,
    ) {
        let (client, timeout) = (self.client.clone(), self.timeout);
        self.runtime.spawn(async move { answered(client.call(api_id, &parameter, timeout).await) });
    }

    /// Calls `api_id` with `parameter` (JSON by convention) and waits up to the service timeout
    /// for its answer, as [`ServiceClient::call`] does. Any executor.
    pub async fn call(&self, api_id: i64, parameter: impl Into<String>) -> Result<ApiResponse, UnitreeError> {
        let (client, parameter, timeout) = (self.client.clone(), parameter.into(), self.timeout);
        on_runtime(&self.runtime, async move { client.call(api_id, &parameter, timeout).await }).await
    }
}

/// The robot's `motion_switcher` and `sport` services, as the low-level client uses them.
#[derive(Debug)]
pub(crate) struct Services {
    switcher: ServiceClient,
    sport: ServiceClient,
    timeout: Duration,
}

impl Services {
    pub(crate) fn new(participant: &Participant, timeout: Duration, tap: Option<&Tap>) -> Result<Self, DdsError> {
        Ok(Self {
            switcher: ServiceClient::tapped(participant, api::motion_switcher::SERVICE, tap.cloned())?,
            sport: ServiceClient::tapped(participant, api::sport::SERVICE, tap.cloned())?,
            timeout,
        })
    }

    /// The sport mode owning the motors (empty: none), as CheckMode reports it.
    pub(crate) async fn sport_mode(&self) -> Result<String, UnitreeError> {
        let answer = self.switcher.call(api::motion_switcher::CHECK_MODE, "{}", self.timeout).await?;
        api::motion_switcher::mode_name(&answer.data)
            .map(str::to_owned)
            .ok_or(UnitreeError::Unexpected { service: api::motion_switcher::SERVICE, data: answer.data })
    }

    /// Releases the mode owning the motors: CheckMode; while a mode owns them, (with
    /// `stand_down`: the Go2's sport StandDown,) motion_switcher ReleaseMode, CheckMode again, at
    /// most [`RELEASE_ATTEMPTS`] ReleaseModes. Returns the ReleaseMode calls it took.
    pub(crate) async fn release(&self, stand_down: bool) -> Result<u32, UnitreeError> {
        let mut attempts = 0;
        loop {
            let mode = self.sport_mode().await?;
            if mode.is_empty() {
                return Ok(attempts);
            }
            if attempts == RELEASE_ATTEMPTS {
                return Err(UnitreeError::NotReleased { mode, attempts });
            }
            if stand_down {
                self.sport.call(api::sport::STAND_DOWN, "{}", self.timeout).await?;
            }
            self.switcher.call(api::motion_switcher::RELEASE_MODE, "{}", self.timeout).await?;
            attempts += 1;
        }
    }

    /// motion_switcher SelectMode `name`: the robot's controller `name` takes the motors again.
    pub(crate) async fn select_mode(&self, name: &str) -> Result<(), UnitreeError> {
        let parameter = format!(r#"{{"name":"{}"}}"#, json_escaped(name));
        self.switcher.call(api::motion_switcher::SELECT_MODE, &parameter, self.timeout).await.map(drop)
    }
}
