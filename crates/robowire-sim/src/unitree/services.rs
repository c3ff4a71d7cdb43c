//! The services thread every simulated Unitree robot runs: a small tokio runtime reading the
//! robot's command topics and answering its services on `rt/api/<service>/request` and
//! `/response`; `motion_switcher`'s state ([`Owner`]); and the hand-over of accepted commands to
//! the state stream ([`CommandInbox`], a seqlock).

use std::future::Future;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use robowire_core::schedule::Time;
use robowire_core::timing::LatenessSummary;
use robowire_dds::Writer;
use robowire_dds::rpc::RpcServer;
use robowire_rt::stats::{Counter, SharedLateness, micros};
use robowire_rt::{Latest, lock};
use tokio::sync::watch;
use unitree_proto::api::{self, ApiRequest, ApiResponse, Response, motion_switcher, status};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

use super::Report;

/// A server of one of the robot's services (`rt/api/<service>/request` and `/response`).
pub(crate) type ServiceServer = RpcServer<ApiRequest, ApiResponse>;

/// A server of `service`.
pub(crate) fn service_server(
    participant: &robowire_dds::Participant,
    service: &str,
    tap: Option<robowire_tap::Tap>,
) -> Result<ServiceServer, robowire_dds::DdsError> {
    let (requests, answers) = (api::request_topic(service).to_string(), api::response_topic(service).to_string());
    RpcServer::tapped(participant, &requests, &answers, tap)
}

/// Starts the services thread `name`: it runs the future `tasks` makes on its own runtime until
/// `stop` says so.
pub(super) fn spawn<F, Fut>(
    name: String,
    report: Arc<Mutex<Report>>,
    mut stop: watch::Receiver<bool>,
    tasks: F,
) -> std::io::Result<JoinHandle<()>>
where
    F: FnOnce() -> Fut + Send + 'static,
    Fut: Future<Output = ()>,
{
    std::thread::Builder::new().name(name).spawn(move || {
        let Ok(runtime) = tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build() else {
            lock(&report).say("cannot start the services' runtime; the simulator answers nothing");
            return;
        };
        runtime.block_on(async {
            tokio::select! {
                _ = stop.changed() => {}
                () = tasks() => {}
            }
        });
    })
}

/// Requests of one service whose answers are kept, to answer them again when written again.
const ANSWERS_KEPT: usize = 8;

/// A request as a client writes it again: its id, API and parameter.
type Written = (i64, i64, String);

/// Answers every request of one service with `answer`, counting them in `answered`. A request
/// written again (its answer lost or late, a client resends it as it was, under its id) is
/// answered again with the answer it had, and neither acted on nor counted twice; a request
/// with id 0 (a client that does not number its calls, as Unitree's ROS 2 examples) is always
/// acted on.
pub(crate) async fn serve<S>(
    mut server: ServiceServer,
    services: &Mutex<S>,
    answered: &Counter,
    answer: fn(&mut S, &ApiRequest) -> (i32, String),
) {
    // The latest numbered requests acted on, and their answers, newest last.
    let mut kept: std::collections::VecDeque<(Written, (i32, String))> =
        std::collections::VecDeque::with_capacity(ANSWERS_KEPT);
    while let Ok(request) = server.next_request().await {
        let written =
            (request.header.id != 0).then(|| (request.header.id, request.header.api_id, request.parameter.clone()));
        let again = written.as_ref().and_then(|w| kept.iter().find(|(k, _)| k == w)).map(|(_, a)| a.clone());
        let (code, data) = match again {
            Some(again) => again,
            None => {
                let fresh = answer(&mut lock(services), &request);
                answered.add(1);
                if let Some(written) = written {
                    if kept.len() == ANSWERS_KEPT {
                        kept.pop_front();
                    }
                    kept.push_back((written, fresh.clone()));
                }
                fresh
            }
        };
        // A lost answer: the client writes its request again. No answer when none is asked for.
        if !request.header.noreply {
            let _ = server.answer(Response::to(&request.header, code, &data).into());
        }
    }
}

/// `motion_switcher`'s state on the services thread: the mode owning the motors (empty once
/// released), told to the user through the [`Report`].
#[derive(Debug)]
pub(crate) struct Owner {
    report: Arc<Mutex<Report>>,
    mode: String,
    /// The mode was said to ignore commands (once per ownership).
    ignore_logged: bool,
}

impl Owner {
    /// The mode the report names owns the motors.
    pub(crate) fn new(report: Arc<Mutex<Report>>) -> Self {
        let mode = lock(&report).mode.clone();
        Self { report, mode, ignore_logged: false }
    }

    /// Tells the user (a line of the log).
    pub(crate) fn say(&self, line: impl Into<String>) {
        lock(&self.report).say(line);
    }

    /// Whether a mode owns the motors.
    pub(crate) fn owns(&self) -> bool {
        !self.mode.is_empty()
    }

    fn set_mode(&mut self, mode: String) {
        lock(&self.report).mode.clone_from(&mode);
        self.mode = mode;
    }

    /// A command of `what` (`"LowCmd"`) was ignored because the mode owns the motors: said once
    /// per ownership.
    pub(crate) fn ignored(&mut self, what: &str) {
        if !self.ignore_logged {
            self.ignore_logged = true;
            self.say(format!(
                "{what} ignored: sport mode \"{}\" owns the motors (release it with motion_switcher ReleaseMode); \
                 further ones are counted",
                self.mode
            ));
        }
    }

    /// Answers a `motion_switcher` request as the robot does.
    pub(crate) fn answer(&mut self, request: &ApiRequest) -> (i32, String) {
        match request.header.api_id {
            api::API_VERSION_ID => (status::OK, motion_switcher::API_VERSION.into()),
            motion_switcher::CHECK_MODE => (status::OK, motion_switcher::check_mode_data(&self.mode).to_string()),
            motion_switcher::SELECT_MODE => match motion_switcher::mode_name(&request.parameter).map(str::to_owned) {
                Some(name) => {
                    self.say(format!("SelectMode: sport mode \"{name}\" owns the motors"));
                    self.set_mode(name);
                    self.ignore_logged = false;
                    (status::OK, String::new())
                }
                None => (status::SERVER_API_PARAMETER, String::new()),
            },
            motion_switcher::RELEASE_MODE => {
                if self.owns() {
                    let mut report = lock(&self.report);
                    if report.held_releases > 0 {
                        if report.held_releases != u32::MAX {
                            report.held_releases -= 1;
                        }
                        report.say(format!(
                            "ReleaseMode: sport mode \"{}\" does not let go (fault ModeHeld); CheckMode still names it",
                            self.mode
                        ));
                        return (status::OK, String::new());
                    }
                    drop(report);
                    self.say(format!(
                        "ReleaseMode: sport mode \"{}\" released; LowCmds now drive the motors",
                        self.mode
                    ));
                }
                self.set_mode(String::new());
                (status::OK, String::new())
            }
            motion_switcher::SET_SILENT => (status::OK, String::new()),
            motion_switcher::GET_SILENT => (status::OK, r#"{"silent":false}"#.into()),
            _ => (status::SERVER_API_NOT_IMPLEMENTED, String::new()),
        }
    }
}

/// Commands of one topic the services thread accepted, handed to the state stream (the
/// latest, through a seqlock), with their counts and arrival jitter.
#[derive(Debug)]
pub(crate) struct CommandInbox<C> {
    command: Latest<C>,
    /// Accepted: handed to the stream.
    pub(crate) accepted: Counter,
    /// Ignored (a mode owns the motors, or none does: the robot's rule for the topic).
    pub(crate) ignored: Counter,
    /// The period commands are expected at.
    period: Duration,
    /// When the last one was accepted; the services thread's only.
    last: Mutex<Option<Time>>,
    jitter: SharedLateness<4096>,
}

impl<C: FromBytes + IntoBytes + KnownLayout + Immutable> CommandInbox<C> {
    /// Nothing accepted yet; commands expected every `period`.
    pub(crate) fn new(period: Duration) -> Self {
        Self {
            command: Latest::new(),
            accepted: Counter::default(),
            ignored: Counter::default(),
            period,
            last: Mutex::new(None),
            jitter: SharedLateness::new(),
        }
    }

    /// The services thread: `command`, arrived at `now`, is accepted: counted, its interval
    /// since the last one recorded against the period, handed to the stream.
    pub(crate) fn accept(&self, command: &C, now: Time) {
        self.accepted.add(1);
        if let Some(last) = lock(&self.last).replace(now) {
            self.jitter.record(micros(now.saturating_duration_since(last).abs_diff(self.period)));
        }
        self.command.write(now, command);
    }

    /// The stream: the command accepted after `seen` (which it updates), if any. Never waits.
    pub(crate) fn newer(&self, seen: &mut Option<Time>) -> Option<C> {
        let (at, command) = self.command.read_newer(*seen)?;
        *seen = Some(at);
        Some(command)
    }

    /// |interval − period| between accepted commands as they arrive, µs.
    pub(crate) fn jitter(&self) -> LatenessSummary {
        self.jitter.summary()
    }
}

/// Answers an accepted command at once (round-trip measurements; a real robot only streams):
/// the state the stream sent last with `echo` applied, written on `answers` if it is there. A
/// failed write is counted by the writer.
pub(crate) fn answer_at_once<S>(state: &Latest<S>, answers: Option<&Writer<S>>, echo: impl FnOnce(&mut S))
where
    S: unitree_proto::Message + robowire_core::cdr::CdrType + Send + Sync,
{
    if let Some(answers) = answers
        && let Some((_, mut answer)) = state.read()
    {
        echo(&mut answer);
        let _ = answers.write(answer);
    }
}
