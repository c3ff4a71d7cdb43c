//! The Go2's services thread (on the shared skeleton of `crate::unitree`): takes `rt/lowcmd` on
//! the participant's background thread as each arrives (an accepted LowCmd goes to the state
//! stream through a seqlock, and is answered at once if asked for) and answers `motion_switcher`
//! and `sport` like the robot.

use std::sync::{Arc, Mutex};
use std::time::Duration;

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
    /// The sport service drives an onboard controller (`Go2SimConfig::onboard_gait`).
    pub(super) onboard_gait: bool,
}

/// How long a `Move` velocity holds without another (robowire's choice: a client that stops
/// calling stops the robot).
pub const MOVE_HOLDS: Duration = Duration::from_secs(1);

/// What the services thread keeps: who owns the motors.
struct Services {
    handover: Arc<Handover<Go2Robot>>,
    owner: Owner,
    onboard_gait: bool,
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

    /// Switches the onboard locomotion on (while the sport mode owns the motors) or off.
    fn gait(&self, on: bool) {
        self.handover.inbox.ask.set_on(on && self.owner.owns());
    }
}

/// Runs until the simulator stops.
pub(super) async fn run(handover: Arc<Handover<Go2Robot>>, report: Arc<Mutex<Report>>, endpoints: Endpoints) {
    let Endpoints { lowcmd: reader, answers, switcher, sport, onboard_gait } = endpoints;
    let services =
        Arc::new(Mutex::new(Services { handover: handover.clone(), owner: Owner::new(report), onboard_gait }));
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
        () = serve(switcher, &services, answered, answer_motion_switcher) => {}
        () = serve(sport, &services, answered, answer_sport) => {}
    }
}

fn answer_motion_switcher(s: &mut Services, request: &ApiRequest) -> (i32, String) {
    let answer = s.owner.answer(request);
    if !s.owner.owns() {
        s.gait(false);
    }
    answer
}

/// Move's `{"x": vx, "y": vy, "z": vyaw}`, each finite.
fn move_velocity(request: &ApiRequest) -> Option<[f32; 3]> {
    let p: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&request.parameter).ok()?;
    let v = ["x", "y", "z"].map(|k| p.get(k).and_then(serde_json::Value::as_f64));
    let v = [v[0]?, v[1]?, v[2]?];
    v.iter().all(|x| x.is_finite()).then(|| v.map(|x| x as f32))
}

fn answer_sport(s: &mut Services, request: &ApiRequest) -> (i32, String) {
    let ok = (status::OK, String::new());
    let ask = &s.handover.inbox.ask;
    match request.header.api_id {
        api::API_VERSION_ID => (status::OK, sport::API_VERSION.into()),
        sport::STAND_DOWN => {
            s.owner.say("sport StandDown: lying down");
            s.gait(false);
            ok
        }
        sport::DAMP => {
            s.gait(false);
            ok
        }
        sport::BALANCE_STAND | sport::STAND_UP | sport::RECOVERY_STAND => {
            s.gait(s.onboard_gait);
            ok
        }
        sport::STOP_MOVE => {
            ask.set_velocity([0.0; 3], robowire_rt::now());
            ok
        }
        sport::MOVE if s.onboard_gait => match move_velocity(request) {
            Some(v) => {
                s.gait(true);
                s.handover.inbox.ask.set_velocity(v, robowire_rt::now() + MOVE_HOLDS);
                ok
            }
            None => (status::SERVER_API_PARAMETER, String::new()),
        },
        _ => (status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}
