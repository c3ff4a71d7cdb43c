//! The simulator's services thread: a small tokio runtime reading `rt/lowcmd` and answering
//! `motion_switcher` and `sport` requests like the robot.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use lowcmd_proto::LowState;
use lowcmd_proto::api::{self, ApiRequest, ApiResponse, Response, motion_switcher, sport, status};
use robowire_dds::Writer;
use robowire_dds::rpc::RpcServer;
use tokio::sync::watch;

use super::{LowCmdReader, Shared, Stats, lock, on_lowcmd};

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
) -> Result<ServiceServer, robowire_dds::DdsError> {
    RpcServer::new(participant, &api::request_topic(service).to_string(), &api::response_topic(service).to_string())
}

/// Runs until `stop` says so.
pub(super) fn run(
    shared: Arc<Mutex<Shared>>,
    stats: Arc<Stats>,
    endpoints: Endpoints,
    period: Duration,
    mut stop: watch::Receiver<bool>,
) {
    let Endpoints { lowcmd: mut reader, answers, switcher, sport } = endpoints;
    let Ok(runtime) = tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build() else {
        lock(&shared).say("cannot start the services' runtime; the simulator answers nothing");
        return;
    };
    runtime.block_on(async {
        let commands = async {
            while let Ok(sample) = reader.recv().await {
                let state = on_lowcmd(&shared, &stats, period, &sample.value, robowire_rt::now());
                if let (Some(answers), Some(state)) = (&answers, state) {
                    // A failed write is counted by the writer.
                    let _ = answers.write(state);
                }
            }
        };
        tokio::select! {
            _ = stop.changed() => {}
            () = commands => {}
            () = serve(switcher, &shared, &stats, answer_motion_switcher) => {}
            () = serve(sport, &shared, &stats, answer_sport) => {}
        }
    });
}

/// Answers every request of one service with `answer`.
async fn serve(
    mut server: ServiceServer,
    shared: &Mutex<Shared>,
    stats: &Stats,
    answer: fn(&mut Shared, &ApiRequest) -> (i32, String),
) {
    while let Ok(request) = server.next_request().await {
        let (code, data) = answer(&mut lock(shared), &request);
        stats.requests.add(1);
        // A lost answer: the client writes its request again. No answer when none is asked for.
        if !request.header.noreply {
            let _ = server.answer(Response::to(&request.header, code, &data).into());
        }
    }
}

fn answer_motion_switcher(s: &mut Shared, request: &ApiRequest) -> (i32, String) {
    match request.header.api_id {
        api::API_VERSION_ID => (status::OK, motion_switcher::API_VERSION.into()),
        motion_switcher::CHECK_MODE => (status::OK, motion_switcher::check_mode_data(&s.sport_mode).to_string()),
        motion_switcher::SELECT_MODE => match motion_switcher::mode_name(&request.parameter).map(str::to_owned) {
            Some(name) => {
                s.say(format!("SelectMode: sport mode \"{name}\" owns the motors"));
                s.sport_mode = name;
                s.ignore_logged = false;
                (status::OK, String::new())
            }
            None => (status::SERVER_API_PARAMETER, String::new()),
        },
        motion_switcher::RELEASE_MODE => {
            if !s.sport_mode.is_empty() {
                s.say(format!("ReleaseMode: sport mode \"{}\" released; LowCmds now drive the motors", s.sport_mode));
            }
            s.sport_mode.clear();
            (status::OK, String::new())
        }
        motion_switcher::SET_SILENT => (status::OK, String::new()),
        motion_switcher::GET_SILENT => (status::OK, r#"{"silent":false}"#.into()),
        _ => (status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}

fn answer_sport(s: &mut Shared, request: &ApiRequest) -> (i32, String) {
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
