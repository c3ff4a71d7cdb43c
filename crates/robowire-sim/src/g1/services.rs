//! The G1's services thread (on the shared skeleton of `crate::unitree`): reads `rt/lowcmd` and
//! `rt/arm_sdk` (accepted frames go to the state stream through seqlocks) and answers
//! `motion_switcher`, the loco service (`sport`) and the arm actions (`arm`) like the robot.

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use robowire_core::schedule::Time;
use robowire_dds::{Reader, Writer};
use robowire_rt::lock;
use serde_json::{Value, json};
use unitree_proto::api::{self, ApiRequest, g1_arm, g1_loco, status};
use unitree_proto::g1::{G1Variant, ModePr};
use unitree_proto::{HgLowCmd, HgLowState};

use super::{ArmSdkFrame, G1Robot, has_disabled_motor};
use crate::unitree::{Handover, Owner, Report, ServiceServer, answer_at_once, serve};

/// The simulator's DDS endpoints the services thread owns.
pub(super) struct Endpoints {
    pub(super) lowcmd: Reader<HgLowCmd>,
    pub(super) arm_sdk: Reader<ArmSdkFrame>,
    /// Immediate answers to LowCmds, if asked for.
    pub(super) answers: Option<Writer<HgLowState>>,
    pub(super) switcher: ServiceServer,
    pub(super) loco: ServiceServer,
    pub(super) arm: ServiceServer,
    /// `rt/lf/bmsstate`.
    pub(super) battery: Writer<unitree_proto::bms::HgBmsState>,
}

/// What the robot checks a LowCmd against.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rules {
    pub(super) variant: G1Variant,
    pub(super) mode_machine: u8,
    /// The loco service drives an onboard controller (`G1SimConfig::onboard_gait`).
    pub(super) onboard_gait: bool,
}

/// The loco FSM ids the simulator takes: Unitree's C++ `LocoClient` (0 zero torque, 1 damp,
/// 2 squat, 3 sit, 4 stand up, 500 start), its Python one (702 lie to stand, 706 squat/stand),
/// 501 (walking with the 3-dof waist) and 801 (running).
const FSM_IDS: [i64; 10] = [0, 1, 2, 3, 4, 500, 501, 702, 706, 801];

/// The FSMs in which the robot stands or walks under its own locomotion: 4 stand up, 500 start,
/// 501 walking with the 3-dof waist, 702 lie to stand, 706 squat/stand, 801 running.
const GAIT_FSMS: [i64; 6] = [4, 500, 501, 702, 706, 801];

/// The FSMs in which arm actions run (the walking and running controllers).
const ARM_ACTION_FSMS: [i64; 3] = [500, 501, 801];

/// The arm actions (Unitree's Python `action_map`): id and name.
const ARM_ACTIONS: [(i64, &str); 16] = [
    (99, "release arm"),
    (11, "two-hand kiss"),
    (12, "left kiss"),
    (13, "right kiss"),
    (15, "hands up"),
    (17, "clap"),
    (18, "high five"),
    (19, "hug"),
    (20, "heart"),
    (21, "right heart"),
    (22, "reject"),
    (23, "right hand up"),
    (24, "x-ray"),
    (25, "face wave"),
    (26, "high wave"),
    (27, "shake hand"),
];

/// The actions that end holding their pose: until the release action ([`g1_arm::RELEASE_ARM`],
/// 99) or the same action again, every other action is refused with `HOLDING` (7401).
/// robowire's choice, since which of the robot's actions hold is not public: the poses held
/// out to someone (15 hands up, 19 hug, 20 heart, 21 right heart, 27 shake hand).
pub const HOLDING_ACTIONS: [i64; 5] = [15, 19, 20, 21, 27];

/// The loco service's settings (what its Get* calls answer).
#[derive(Debug)]
struct Loco {
    fsm_id: i64,
    balance_mode: i64,
    swing_height_m: f64,
    stand_height_m: f64,
    /// The last SetVelocity: vx m/s, vy m/s, yaw rad/s.
    velocity: [f64; 3],
}

/// What the services thread keeps: who owns the motors, the loco settings.
struct Services {
    handover: Arc<Handover<G1Robot>>,
    owner: Owner,
    rules: Rules,
    loco: Loco,
    /// A wrong `mode_machine` was said (once until the next accepted LowCmd).
    mode_machine_logged: bool,
    /// `rt/arm_sdk` after ReleaseMode was said (once per release).
    arm_sdk_logged: bool,
    /// The action whose pose the arms hold ([`HOLDING_ACTIONS`]); forgotten when the
    /// controller lets the motors go.
    held_action: Option<i64>,
}

impl Services {
    /// Applies one decoded LowCmd (arrived at `now`): whether the robot applies it.
    fn on_lowcmd(&mut self, cmd: &HgLowCmd, now: Time) -> bool {
        let inbox = &self.handover.inbox;
        if self.owner.owns() {
            inbox.lowcmd.ignored.add(1);
            self.owner.ignored("LowCmd");
            return false;
        }
        if cmd.mode_machine != self.rules.mode_machine {
            inbox.bad_mode_machine.add(1);
            if !self.mode_machine_logged {
                self.mode_machine_logged = true;
                self.owner.say(format!(
                    "LowCmd ignored: mode_machine {} is not the robot's {} (copy it from rt/lowstate); further ones are counted",
                    cmd.mode_machine, self.rules.mode_machine
                ));
            }
            return false;
        }
        if ModePr::from_byte(cmd.mode_pr).is_none() {
            inbox.bad_mode_pr.add(1);
            return false;
        }
        if has_disabled_motor(cmd, self.rules.variant) {
            inbox.disabled_motors.add(1);
        }
        self.mode_machine_logged = false;
        inbox.lowcmd.accept(cmd, now);
        true
    }

    /// Applies one `rt/arm_sdk` frame (arrived at `now`).
    fn on_arm_sdk(&mut self, frame: &ArmSdkFrame, now: Time) {
        let inbox = &self.handover.inbox;
        if !self.owner.owns() {
            inbox.arm_sdk.ignored.add(1);
            if !self.arm_sdk_logged {
                self.arm_sdk_logged = true;
                self.owner.say(
                    "rt/arm_sdk ignored: no mode owns the motors (it blends into the robot's controller; SelectMode gives \
                     the motors back); further ones are counted",
                );
            }
            return;
        }
        if !frame.sealed {
            inbox.arm_sdk_unsealed.add(1);
        }
        inbox.arm_sdk.accept(&frame.command, now);
    }

    /// After a `motion_switcher` call: the controller owns the motors while a mode is selected.
    fn sync_owner(&mut self) {
        let owns = self.owner.owns();
        let inbox = &self.handover.inbox;
        if inbox.controller.swap(owns, Ordering::AcqRel) != owns && owns {
            self.arm_sdk_logged = false;
            self.set_fsm(g1_loco::fsm::START);
        }
        if !owns {
            self.held_action = None;
        }
        self.sync_gait();
    }

    /// The weight `rt/arm_sdk` is blended in with, as the state stream last stepped the body.
    fn arm_sdk_weight(&self) -> f32 {
        self.handover.published.read().map_or(0.0, |(_, published)| published[super::JOINTS])
    }

    fn set_fsm(&mut self, id: i64) {
        self.loco.fsm_id = id;
        self.handover.inbox.fsm_id.store(id, Ordering::Relaxed);
        self.sync_gait();
    }

    /// The onboard locomotion runs while a mode owns the motors in a standing or walking FSM.
    fn sync_gait(&self) {
        if self.rules.onboard_gait {
            self.handover.inbox.ask.set_on(self.owner.owns() && GAIT_FSMS.contains(&self.loco.fsm_id));
        }
    }
}

/// Runs until the simulator stops.
pub(super) async fn run(
    handover: Arc<Handover<G1Robot>>,
    report: Arc<Mutex<Report>>,
    endpoints: Endpoints,
    rules: Rules,
) {
    let Endpoints { lowcmd: lowcmd_reader, arm_sdk: mut arm_sdk_reader, answers, switcher, loco, arm, battery } =
        endpoints;
    let loco_state = Loco {
        fsm_id: super::BOOT_FSM_ID,
        balance_mode: 0,
        swing_height_m: 0.08,
        stand_height_m: 0.75,
        velocity: [0.0; 3],
    };
    let services = Arc::new(Mutex::new(Services {
        handover: handover.clone(),
        owner: Owner::new(report),
        rules,
        loco: loco_state,
        mode_machine_logged: false,
        arm_sdk_logged: false,
        held_action: None,
    }));
    lock(&services).sync_gait();
    let answered = &handover.requests_answered;
    // Each LowCmd is taken on the participant's background thread as it arrives: no task to wake
    // between the datagram and the stream's seqlock (or the answer's `sendto`).
    let _lowcmds = lowcmd_reader.listen({
        let (services, handover) = (services.clone(), handover.clone());
        move |sample| {
            let cmd = &sample.value;
            if lock(&services).on_lowcmd(cmd, robowire_rt::now()) {
                // robowire's simulator only: the command's `reserve` echoed, to match a state to it.
                answer_at_once(&handover.state, answers.as_ref(), |state| state.reserve = cmd.reserve);
            }
        }
    });
    let arm_sdk = async {
        while let Ok(sample) = arm_sdk_reader.recv().await {
            lock(&services).on_arm_sdk(&sample.value, robowire_rt::now());
        }
    };
    tokio::select! {
        () = arm_sdk => {}
        () = serve(switcher, &services, answered, answer_motion_switcher) => {}
        () = serve(loco, &services, answered, answer_loco) => {}
        () = serve(arm, &services, answered, answer_arm) => {}
        () = super::battery::publish(battery) => {}
    }
}

fn answer_motion_switcher(s: &mut Services, request: &ApiRequest) -> (i32, String) {
    let answer = s.owner.answer(request);
    s.sync_owner();
    answer
}

/// The JSON object of a request's parameter, if it is one.
fn parameter(request: &ApiRequest) -> Option<serde_json::Map<String, Value>> {
    match serde_json::from_str(&request.parameter) {
        Ok(Value::Object(map)) => Some(map),
        _ => None,
    }
}

/// `"data"` of a request's parameter.
fn data(request: &ApiRequest) -> Option<Value> {
    parameter(request)?.remove("data")
}

fn ok() -> (i32, String) {
    (status::OK, String::new())
}

fn bad_parameter() -> (i32, String) {
    (status::SERVER_API_PARAMETER, String::new())
}

fn answer_data(value: impl Into<Value>) -> (i32, String) {
    (status::OK, json!({ "data": value.into() }).to_string())
}

/// SetVelocity's `{"velocity": [vx, vy, omega], "duration": s}` (duration 1 s when absent).
fn velocity(request: &ApiRequest) -> Option<([f64; 3], f64)> {
    let p = parameter(request)?;
    let v = p.get("velocity")?.as_array()?;
    let v: Vec<f64> = v.iter().map(Value::as_f64).collect::<Option<_>>()?;
    let v: [f64; 3] = v.try_into().ok()?;
    let duration = match p.get("duration") {
        None => 1.0,
        Some(d) => d.as_f64().filter(|d| *d >= 0.0)?,
    };
    v.iter().all(|x| x.is_finite()).then_some((v, duration))
}

fn answer_loco(s: &mut Services, request: &ApiRequest) -> (i32, String) {
    if request.header.api_id == api::API_VERSION_ID {
        return (status::OK, g1_loco::API_VERSION.into());
    }
    if !s.owner.owns() {
        return (g1_loco::error::LOCO_STATE_UNAVAILABLE, String::new());
    }
    let loco = &mut s.loco;
    match request.header.api_id {
        g1_loco::GET_FSM_ID => answer_data(loco.fsm_id),
        g1_loco::GET_FSM_MODE => answer_data(0),
        g1_loco::GET_BALANCE_MODE => answer_data(loco.balance_mode),
        g1_loco::GET_SWING_HEIGHT => answer_data(loco.swing_height_m),
        g1_loco::GET_STAND_HEIGHT => answer_data(loco.stand_height_m),
        g1_loco::SET_FSM_ID => match data(request).and_then(|d| d.as_i64()) {
            Some(id) if FSM_IDS.contains(&id) => {
                if id != loco.fsm_id {
                    s.owner.say(format!("loco SetFsmId {id}"));
                }
                s.set_fsm(id);
                ok()
            }
            Some(_) => (g1_loco::error::INVALID_FSM_ID, String::new()),
            None => bad_parameter(),
        },
        g1_loco::SET_BALANCE_MODE => match data(request).and_then(|d| d.as_i64()) {
            Some(mode @ (0 | 1)) => {
                loco.balance_mode = mode;
                ok()
            }
            _ => bad_parameter(),
        },
        g1_loco::SET_SWING_HEIGHT | g1_loco::SET_STAND_HEIGHT => {
            match data(request).and_then(|d| d.as_f64()).filter(|h| h.is_finite() && *h >= 0.0) {
                Some(height) if request.header.api_id == g1_loco::SET_SWING_HEIGHT => {
                    loco.swing_height_m = height;
                    ok()
                }
                Some(height) => {
                    loco.stand_height_m = height;
                    ok()
                }
                None => bad_parameter(),
            }
        }
        g1_loco::SET_VELOCITY => match velocity(request) {
            Some((v, duration_s)) => {
                // Said when it starts or stops moving, not on every call of a stream.
                if (v == [0.0; 3]) != (loco.velocity == [0.0; 3]) {
                    s.owner.say(format!("loco SetVelocity {v:?} for {duration_s} s"));
                }
                s.loco.velocity = v;
                let until = robowire_rt::now() + Duration::try_from_secs_f64(duration_s).unwrap_or(Duration::MAX);
                s.handover.inbox.ask.set_velocity(v.map(|x| x as f32), until);
                ok()
            }
            None => bad_parameter(),
        },
        g1_loco::SET_ARM_TASK => match data(request).and_then(|d| d.as_i64()) {
            Some(task @ 0..=3) => {
                s.owner.say(format!("loco SetArmTask {task}"));
                ok()
            }
            Some(_) => (g1_loco::error::INVALID_TASK_ID, String::new()),
            None => bad_parameter(),
        },
        g1_loco::SET_SPEED_MODE => match data(request).and_then(|d| d.as_i64()) {
            Some(_) => ok(),
            None => bad_parameter(),
        },
        g1_loco::SWITCH_TO_USER_CTRL => match data(request).and_then(|d| d.as_bool()) {
            Some(_) => ok(),
            None => bad_parameter(),
        },
        g1_loco::SWITCH_TO_INTERNAL_CTRL => match data(request).and_then(|d| d.as_i64()) {
            Some(0..=2) => ok(),
            _ => bad_parameter(),
        },
        _ => (status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}

fn answer_arm(s: &mut Services, request: &ApiRequest) -> (i32, String) {
    match request.header.api_id {
        api::API_VERSION_ID => (status::OK, g1_arm::API_VERSION.into()),
        g1_arm::GET_ACTION_LIST => {
            let actions: Vec<Value> = ARM_ACTIONS.iter().map(|(id, name)| json!({ "id": id, "name": name })).collect();
            answer_data(actions)
        }
        g1_arm::EXECUTE_ACTION => {
            let Some(id) = parameter(request).and_then(|p| p.get("data").or_else(|| p.get("action_id"))?.as_i64())
            else {
                return bad_parameter();
            };
            if !s.owner.owns() || !ARM_ACTION_FSMS.contains(&s.loco.fsm_id) {
                return (g1_arm::error::INVALID_FSM_ID, String::new());
            }
            if s.arm_sdk_weight() > 0.0 {
                return (g1_arm::error::ARM_SDK_OCCUPIED, String::new());
            }
            let Some((_, name)) = ARM_ACTIONS.iter().find(|(known, _)| *known == id) else {
                return (g1_arm::error::INVALID_ACTION_ID, String::new());
            };
            if s.held_action.is_some_and(|held| id != held && id != g1_arm::RELEASE_ARM) {
                return (g1_arm::error::HOLDING, String::new());
            }
            s.held_action = HOLDING_ACTIONS.contains(&id).then_some(id);
            s.owner.say(format!("arm action {id} ({name})"));
            ok()
        }
        _ => (status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}
