//! Requests and answers of the robot's services over `rt/api/<service>/request` and
//! `/response` (spec `unitree-dds.md`): a client that matches answers to its calls by
//! `identity.id` (and checks `api_id`), and a server that hands out requests and answers them.
//!
//! DDS discovery takes a moment and the topics are volatile: a request written before the
//! service's reader is matched is lost. The client therefore waits for a matched reader before
//! its first write and writes the same request again (same id) until an answer comes or the
//! call times out; the services robowire calls are idempotent.

use std::collections::HashMap;
use std::sync::atomic::{AtomicI64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use lowcmd_proto::api::{self, ApiRequest, ApiResponse, RequestHeader, Response};
use tokio::sync::oneshot;
use tokio::task::JoinHandle;

use crate::qos::Qos;
use crate::{DdsError, Participant, Reader, Writer};

/// How often a request without an answer is written again.
pub const RESEND_EVERY: Duration = Duration::from_millis(250);

type Pending = Arc<Mutex<HashMap<i64, oneshot::Sender<ApiResponse>>>>;

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Calls one service. Needs a tokio runtime: a task reads the answers.
#[derive(Debug)]
pub struct RpcClient {
    service: String,
    requests: Writer<ApiRequest>,
    pending: Pending,
    next_id: AtomicI64,
    answers: JoinHandle<()>,
}

impl Drop for RpcClient {
    fn drop(&mut self) {
        self.answers.abort();
    }
}

impl RpcClient {
    /// A client of `service` (`motion_switcher`, `sport`, …).
    pub fn new(participant: &Participant, service: &str) -> Result<Self, DdsError> {
        let requests = participant.writer::<ApiRequest>(&api::request_topic(service).to_string(), Qos::WRITER)?;
        let mut answers =
            participant.reader::<ApiResponse>(&api::response_topic(service).to_string(), Qos::RPC_READER)?;
        let pending: Pending = Arc::default();
        let task = tokio::spawn({
            let pending = pending.clone();
            async move {
                while let Ok(answer) = answers.recv().await {
                    // An answer to another client's call, or to a call that gave up: dropped.
                    if let Some(waiter) = lock(&pending).remove(&answer.value.id) {
                        let _ = waiter.send(answer.value);
                    }
                }
            }
        });
        // Request ids as Unitree's SDKs make them: the monotonic clock in ns, unique per call.
        let first_id = i64::try_from(robowire_now_ns()).unwrap_or(1);
        Ok(Self { service: service.into(), requests, pending, next_id: AtomicI64::new(first_id), answers: task })
    }

    /// The service.
    pub fn service(&self) -> &str {
        &self.service
    }

    /// Calls `api_id` with `parameter` (JSON by convention) and waits up to `timeout` for the
    /// answer (whatever its status code: check [`ApiResponse::code`]).
    pub async fn call(&self, api_id: i64, parameter: &str, timeout: Duration) -> Result<ApiResponse, DdsError> {
        let id = self.next_id.fetch_add(1, Ordering::Relaxed);
        let (tx, mut rx) = oneshot::channel();
        lock(&self.pending).insert(id, tx);
        let request =
            ApiRequest { header: RequestHeader::call(id, api_id), parameter: parameter.into(), binary: Vec::new() };
        let deadline = Instant::now() + timeout;
        let no_answer = || DdsError::NoAnswer { service: self.service.clone(), api_id, timeout };
        let result = async {
            // Discovery first: a request nobody reads is lost.
            while self.requests.matched_readers() == 0 {
                if Instant::now() >= deadline {
                    return Err(no_answer());
                }
                tokio::time::sleep(Duration::from_millis(10)).await;
            }
            loop {
                self.requests.write(request.clone())?;
                let wait = RESEND_EVERY.min(deadline.saturating_duration_since(Instant::now()));
                match tokio::time::timeout(wait, &mut rx).await {
                    Ok(Ok(answer)) if answer.api_id == api_id => return Ok(answer),
                    Ok(Ok(_)) | Ok(Err(_)) => return Err(no_answer()),
                    Err(_) if Instant::now() >= deadline => return Err(no_answer()),
                    Err(_) => {}
                }
            }
        }
        .await;
        lock(&self.pending).remove(&id);
        result
    }
}

fn robowire_now_ns() -> u64 {
    let t = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
    u64::try_from(t.as_nanos()).unwrap_or(1)
}

/// Serves one service: hands out its requests, writes its answers.
#[derive(Debug)]
pub struct RpcServer {
    service: String,
    requests: Reader<ApiRequest>,
    answers: Writer<ApiResponse>,
}

impl RpcServer {
    /// A server of `service`.
    pub fn new(participant: &Participant, service: &str) -> Result<Self, DdsError> {
        Ok(Self {
            service: service.into(),
            requests: participant.reader(&api::request_topic(service).to_string(), Qos::RPC_READER)?,
            answers: participant.writer(&api::response_topic(service).to_string(), Qos::WRITER)?,
        })
    }

    /// The service.
    pub fn service(&self) -> &str {
        &self.service
    }

    /// The next request.
    pub async fn next_request(&mut self) -> Result<ApiRequest, DdsError> {
        Ok(self.requests.recv().await?.value)
    }

    /// Answers `request` with `code` and `data`, unless it asked for no answer.
    pub fn answer(&self, request: &RequestHeader, code: i32, data: &str) -> Result<(), DdsError> {
        if request.noreply {
            return Ok(());
        }
        self.answers.write(Response::to(request, code, data).into())
    }

    /// Counters of the request reader and the answer writer.
    pub fn stats(&self) -> (crate::TopicStats, crate::TopicStats) {
        (self.requests.stats(), self.answers.stats())
    }
}
