//! The simulator's services thread: a small tokio runtime reading `rt/lowcmd` (an accepted LowCmd
//! goes to the state stream through a seqlock, and is answered at once if asked for) and
//! answering `motion_switcher` and `sport` requests like the robot. The sport mode is the
//! thread's own; the handle learns it through the [`Report`].

use std::cell::RefCell;
use std::sync::Mutex;
use std::time::Duration;

use lowcmd_proto::api::{self, ApiRequest, ApiResponse, Response, motion_switcher, sport, status};
use lowcmd_proto::{LowCmd, LowState};
use robowire_core::schedule::Time;
use robowire_dds::Writer;
use robowire_dds::rpc::RpcServer;
use robowire_rt::lock;
use robowire_rt::stats::micros;
use tokio::sync::watch;

use super::{BOOT_SPORT_MODE, Handover, LowCmdReader, Report, head_ok};

/// The simulator's DDS endpoints the services thread owns.
pub(super) struct Endpoints {
    pub(super) lowcmd: LowCmdReader,
    /// Immediate answers to LowCmds, if asked for.
    pub(super) answers: Option<Writer<LowState>>,
    pub(super) switcher: ServiceServer,
    pub(super) sport: ServiceServer,
}

/// A server of one of the robot's services (`rt/api/<service>/request` and `/response`).
pub(super) type ServiceServer = RpcServer<ApiRequest, ApiResponse>;

/// A server of `service`.
pub(super) fn service_server(
    participant: &robowire_dds::Participant,
    service: &str,
    tap: Option<robowire_tap::Tap>,
) -> Result<ServiceServer, robowire_dds::DdsError> {
    let (requests, answers) = (api::request_topic(service).to_string(), api::response_topic(service).to_string());
    RpcServer::tapped(participant, &requests, &answers, tap)
}

/// What the services thread keeps: who owns the motors, and the LowCmds' arrivals.
struct Services<'a> {
    handover: &'a Handover,
    report: &'a Mutex<Report>,
    period: Duration,
    /// The sport mode owning the motors; empty once released.
    sport_mode: String,
    /// The sport mode was said to ignore LowCmds (once per ownership).
    ignore_logged: bool,
    last_command: Option<Time>,
}

impl Services<'_> {
    /// Tells the user (a line of the log).
    fn say(&self, line: impl Into<String>) {
        lock(self.report).say(line);
    }

    fn set_sport_mode(&mut self, mode: String) {
        lock(self.report).sport_mode.clone_from(&mode);
        self.sport_mode = mode;
    }

    /// Applies one decoded LowCmd (arrived at `now`): whether the robot accepted it.
    fn on_lowcmd(&mut self, cmd: &LowCmd, now: Time) -> bool {
        let h = self.handover;
        if !head_ok(cmd) {
            h.bad_head.add(1);
            return false;
        }
        if !self.sport_mode.is_empty() {
            h.ignored.add(1);
            if !self.ignore_logged {
                self.ignore_logged = true;
                self.say(format!(
                    "LowCmd ignored: sport mode \"{}\" owns the motors (release it with motion_switcher ReleaseMode); \
                     further ones are counted",
                    self.sport_mode
                ));
            }
            return false;
        }
        h.accepted.add(1);
        if let Some(last) = self.last_command.replace(now) {
            h.jitter.record(micros(now.saturating_duration_since(last).abs_diff(self.period)));
        }
        h.command.write(now, cmd);
        true
    }

    /// The state right after `cmd` was accepted: the state the stream sent last, with the
    /// command's `reserve` echoed (what the body reports once it follows the command).
    fn answer(&self, cmd: &LowCmd) -> Option<LowState> {
        let (_, mut state) = self.handover.state.read()?;
        state.reserve = cmd.reserve;
        Some(state)
    }
}

/// Runs until `stop` says so.
pub(super) fn run(
    handover: &Handover,
    report: &Mutex<Report>,
    endpoints: Endpoints,
    period: Duration,
    mut stop: watch::Receiver<bool>,
) {
    let Endpoints { lowcmd: mut reader, answers, switcher, sport } = endpoints;
    let services = RefCell::new(Services {
        handover,
        report,
        period,
        sport_mode: BOOT_SPORT_MODE.into(),
        ignore_logged: false,
        last_command: None,
    });
    let Ok(runtime) = tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build() else {
        lock(report).say("cannot start the services' runtime; the simulator answers nothing");
        return;
    };
    runtime.block_on(async {
        let commands = async {
            while let Ok(sample) = reader.recv().await {
                let cmd = &sample.value;
                let mut s = services.borrow_mut();
                if s.on_lowcmd(cmd, robowire_rt::now())
                    && let Some(answers) = &answers
                    && let Some(state) = s.answer(cmd)
                {
                    // A failed write is counted by the writer.
                    let _ = answers.write(state);
                }
            }
        };
        tokio::select! {
            _ = stop.changed() => {}
            () = commands => {}
            () = serve(switcher, &services, answer_motion_switcher) => {}
            () = serve(sport, &services, answer_sport) => {}
        }
    });
}

/// Answers every request of one service with `answer`.
async fn serve(
    mut server: ServiceServer,
    services: &RefCell<Services<'_>>,
    answer: fn(&mut Services<'_>, &ApiRequest) -> (i32, String),
) {
    while let Ok(request) = server.next_request().await {
        let (code, data) = answer(&mut services.borrow_mut(), &request);
        services.borrow().handover.requests_answered.add(1);
        // A lost answer: the client writes its request again. No answer when none is asked for.
        if !request.header.noreply {
            let _ = server.answer(Response::to(&request.header, code, &data).into());
        }
    }
}

fn answer_motion_switcher(s: &mut Services<'_>, request: &ApiRequest) -> (i32, String) {
    match request.header.api_id {
        api::API_VERSION_ID => (status::OK, motion_switcher::API_VERSION.into()),
        motion_switcher::CHECK_MODE => (status::OK, motion_switcher::check_mode_data(&s.sport_mode).to_string()),
        motion_switcher::SELECT_MODE => match motion_switcher::mode_name(&request.parameter).map(str::to_owned) {
            Some(name) => {
                s.say(format!("SelectMode: sport mode \"{name}\" owns the motors"));
                s.set_sport_mode(name);
                s.ignore_logged = false;
                (status::OK, String::new())
            }
            None => (status::SERVER_API_PARAMETER, String::new()),
        },
        motion_switcher::RELEASE_MODE => {
            if !s.sport_mode.is_empty() {
                s.say(format!("ReleaseMode: sport mode \"{}\" released; LowCmds now drive the motors", s.sport_mode));
            }
            s.set_sport_mode(String::new());
            (status::OK, String::new())
        }
        motion_switcher::SET_SILENT => (status::OK, String::new()),
        motion_switcher::GET_SILENT => (status::OK, r#"{"silent":false}"#.into()),
        _ => (status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}

fn answer_sport(s: &mut Services<'_>, request: &ApiRequest) -> (i32, String) {
    match request.header.api_id {
        api::API_VERSION_ID => (status::OK, sport::API_VERSION.into()),
        sport::STAND_DOWN => {
            s.say("sport StandDown: lying down");
            (status::OK, String::new())
        }
        sport::DAMP | sport::BALANCE_STAND | sport::STOP_MOVE | sport::STAND_UP => (status::OK, String::new()),
        _ => (status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}
