//! The Go2's services thread (on the shared skeleton of `crate::unitree`): takes `rt/lowcmd` on
//! the participant's background thread as each arrives (an accepted LowCmd goes to the state
//! stream through a seqlock, and is answered at once if asked for) and answers `motion_switcher`
//! and `sport` like the robot.

use std::sync::{Arc, Mutex};

use robowire_core::schedule::Time;
use robowire_dds::{Reader, Writer};
use robowire_rt::lock;
use unitree_proto::api::{self, ApiRequest, sport, status};
use unitree_proto::{LowCmd, LowState};

use super::{Go2Robot, head_ok};
use crate::unitree::{Handover, Owner, Report, ServiceServer, answer_at_once, serve};

/// The simulator's DDS endpoints the services thread owns.
pub(super) struct Endpoints {
    pub(super) lowcmd: Reader<LowCmd>,
    /// Immediate answers to LowCmds, if asked for.
    pub(super) answers: Option<Writer<LowState>>,
    pub(super) switcher: ServiceServer,
    pub(super) sport: ServiceServer,
}

/// What the services thread keeps: who owns the motors.
struct Services {
    handover: Arc<Handover<Go2Robot>>,
    owner: Owner,
}

impl Services {
    /// Applies one decoded LowCmd (arrived at `now`): whether the robot accepted it.
    fn on_lowcmd(&mut self, cmd: &LowCmd, now: Time) -> bool {
        let inbox = &self.handover.inbox;
        if !head_ok(cmd) {
            inbox.bad_head.add(1);
            return false;
        }
        if self.owner.owns() {
            inbox.lowcmd.ignored.add(1);
            self.owner.ignored("LowCmd");
            return false;
        }
        inbox.lowcmd.accept(cmd, now);
        true
    }
}

/// Runs until the simulator stops.
pub(super) async fn run(handover: Arc<Handover<Go2Robot>>, report: Arc<Mutex<Report>>, endpoints: Endpoints) {
    let Endpoints { lowcmd: reader, answers, switcher, sport } = endpoints;
    let services = Arc::new(Mutex::new(Services { handover: handover.clone(), owner: Owner::new(report) }));
    let answered = &handover.requests_answered;
    // Each LowCmd is taken on the participant's background thread as it arrives: no task to wake
    // between the datagram and the stream's seqlock (or the answer's `sendto`).
    let _commands = reader.listen({
        let (services, handover) = (services.clone(), handover.clone());
        move |sample| {
            let cmd = &sample.value;
            if lock(&services).on_lowcmd(cmd, robowire_rt::now()) {
                // What the body reports once it follows the command: its `reserve` echoed.
                answer_at_once(&handover.state, answers.as_ref(), |state| state.reserve = cmd.reserve);
            }
        }
    });
    tokio::select! {
        () = serve(switcher, &services, answered, |s, request| s.owner.answer(request)) => {}
        () = serve(sport, &services, answered, answer_sport) => {}
    }
}

fn answer_sport(s: &mut Services, request: &ApiRequest) -> (i32, String) {
    match request.header.api_id {
        api::API_VERSION_ID => (status::OK, sport::API_VERSION.into()),
        sport::STAND_DOWN => {
            s.owner.say("sport StandDown: lying down");
            (status::OK, String::new())
        }
        sport::DAMP | sport::BALANCE_STAND | sport::STOP_MOVE | sport::STAND_UP => (status::OK, String::new()),
        _ => (status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}
