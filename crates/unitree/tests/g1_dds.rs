//! The G1 client against a minimal robot made here from `robowire-dds` (a LowState publisher
//! with mode_machine 5, readers of `rt/lowcmd` and `rt/arm_sdk`, the motion_switcher, `sport` and
//! `arm` services answering as the robot's do), where loopback carries multicast
//! (`robowire_dds::netns`). Conditions are awaited with a generous timeout; nothing here measures
//! time (the arm stream's timing is its fake-clock tests).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::rpc::RpcServer;
use robowire_dds::{Participant, ParticipantOptions};
use unitree::g1::{
    ARM_JOINTS, ArmActions, CommandError, Device, G1, G1Error, G1Options, G1Variant, HgBmsState, HgLowCmd, HgLowState,
    JOINT_LIMITS, JOINTS, JointCommand, Loco,
};
use unitree_proto::Message;
use unitree_proto::api::{self, ApiRequest, ApiResponse, Response, g1_arm, g1_loco, motion_switcher};
use unitree_proto::bms::BMS_TOPIC;
use unitree_proto::g1::{ARM_SDK_TOPIC, slot};

mod common;
use common::{WAIT, pattern};
use robowire_fixtures::wait::{one_at_a_time, until_async};

/// What the robot's services hold.
#[derive(Debug)]
struct Model {
    /// The mode owning the motors (empty: released).
    mode: String,
    /// ReleaseModes until the mode lets go.
    releases_needed: u32,
    fsm: i64,
    holding: bool,
    /// `SetVelocity` parameters received.
    velocities: Vec<String>,
    /// Requests received, all services.
    requests: u32,
    /// When an `rt/arm_sdk` frame with a weight above 0 last arrived.
    arm_sdk_active: Option<Instant>,
}

/// Every `rt/lowcmd` and `rt/arm_sdk` frame the robot received, in order.
#[derive(Debug, Default)]
struct Received {
    lowcmd: Vec<HgLowCmd>,
    arm_sdk: Vec<HgLowCmd>,
}

struct Robot {
    model: Arc<Mutex<Model>>,
    received: Arc<Mutex<Received>>,
    publishing: Arc<AtomicBool>,
    _participant: Arc<Participant>,
}

/// A reader that loses nothing on loopback.
const KEEP_ALL: Qos = Qos { reliable: true, max_blocking_ms: 0, depth: 1024, transient_local: false };

impl Robot {
    /// The robot on `lo`, domain 0; LowStates from [`publish`](Self::publish) on.
    fn spawn() -> Self {
        let participant = Arc::new(Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap());
        let model = Arc::new(Mutex::new(Model {
            mode: "ai".into(),
            releases_needed: 1,
            fsm: 4,
            holding: false,
            velocities: Vec::new(),
            requests: 0,
            arm_sdk_active: None,
        }));
        let received = Arc::new(Mutex::new(Received::default()));
        let publishing = Arc::new(AtomicBool::new(false));
        let states = participant.writer::<HgLowState>(HgLowState::TOPIC, Qos::STREAM_WRITER).unwrap();
        let flag = publishing.clone();
        tokio::spawn(async move {
            let mut state = HgLowState::default();
            state.mode_machine = 5;
            for (i, m) in state.motor_state.iter_mut().enumerate().take(JOINTS) {
                m.q = (0.01 * i as f32).into();
            }
            let mut every = tokio::time::interval(Duration::from_millis(2));
            loop {
                every.tick().await;
                if flag.load(Ordering::Relaxed) {
                    state.tick = (state.tick.get() + 2).into();
                    let _ = states.try_write(state);
                }
            }
        });
        // The battery beside it (no CRC), as the robot publishes it.
        let bms = participant.writer::<HgBmsState>(BMS_TOPIC, Qos::STREAM_WRITER).unwrap();
        let flag = publishing.clone();
        tokio::spawn(async move {
            let mut state = HgBmsState::default();
            (state.soc, state.current) = (87, (-3200).into());
            state.cell_vol[..13].fill(4012.into());
            let mut every = tokio::time::interval(Duration::from_millis(20));
            loop {
                every.tick().await;
                if flag.load(Ordering::Relaxed) {
                    let _ = bms.try_write(state);
                }
            }
        });
        let mut lowcmd = participant.reader::<HgLowCmd>(HgLowCmd::TOPIC, KEEP_ALL).unwrap();
        let into = received.clone();
        tokio::spawn(async move {
            while let Ok(s) = lowcmd.recv().await {
                robowire_rt::lock(&into).lowcmd.push(s.value);
            }
        });
        let mut arm_sdk = participant.reader::<HgLowCmd>(ARM_SDK_TOPIC, KEEP_ALL).unwrap();
        let (into, active) = (received.clone(), model.clone());
        tokio::spawn(async move {
            while let Ok(s) = arm_sdk.recv().await {
                if s.value.motor_cmd[slot::ARM_SDK_WEIGHT].q.get() > 0.0 {
                    robowire_rt::lock(&active).arm_sdk_active = Some(Instant::now());
                }
                robowire_rt::lock(&into).arm_sdk.push(s.value);
            }
        });
        serve(&participant, motion_switcher::SERVICE, model.clone(), switcher);
        serve(&participant, g1_loco::SERVICE, model.clone(), loco);
        serve(&participant, g1_arm::SERVICE, model.clone(), arm);
        Self { model, received, publishing, _participant: participant }
    }

    fn publish(&self) {
        self.publishing.store(true, Ordering::Relaxed);
    }

    fn model(&self) -> MutexGuard<'_, Model> {
        robowire_rt::lock(&self.model)
    }

    fn received(&self) -> MutexGuard<'_, Received> {
        robowire_rt::lock(&self.received)
    }
}

/// Answers `service`'s requests with `answer(model, request)`: `(code, data)`.
fn serve(
    participant: &Participant,
    service: &'static str,
    model: Arc<Mutex<Model>>,
    answer: fn(&mut Model, &ApiRequest) -> (i32, String),
) {
    let request = api::request_topic(service).to_string();
    let response = api::response_topic(service).to_string();
    let mut server = RpcServer::<ApiRequest, ApiResponse>::new(participant, &request, &response).unwrap();
    tokio::spawn(async move {
        // A resent request (same id) is answered again, as the robot does, but acted on once.
        let mut last_id = None;
        let mut last_answer = (0, String::new());
        while let Ok(request) = server.next_request().await {
            if last_id != Some(request.header.id) {
                let mut model = robowire_rt::lock(&model);
                model.requests += 1;
                last_answer = answer(&mut model, &request);
                last_id = Some(request.header.id);
            }
            let (code, data) = &last_answer;
            let _ = server.answer(Response::to(&request.header, *code, data).into());
        }
    });
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or(serde_json::Value::Null)
}

fn switcher(model: &mut Model, request: &ApiRequest) -> (i32, String) {
    match request.header.api_id {
        motion_switcher::CHECK_MODE => (0, motion_switcher::check_mode_data(&model.mode).to_string()),
        motion_switcher::RELEASE_MODE => {
            model.releases_needed = model.releases_needed.saturating_sub(1);
            if model.releases_needed == 0 {
                model.mode.clear();
            }
            (0, String::new())
        }
        motion_switcher::SELECT_MODE => {
            model.mode = motion_switcher::mode_name(&request.parameter).unwrap_or_default().into();
            (0, String::new())
        }
        _ => (api::status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}

fn loco(model: &mut Model, request: &ApiRequest) -> (i32, String) {
    if model.mode.is_empty() {
        return (g1_loco::error::LOCO_STATE_UNAVAILABLE, String::new());
    }
    let parameter = json(&request.parameter);
    match request.header.api_id {
        g1_loco::GET_FSM_ID => (0, format!(r#"{{"data":{}}}"#, model.fsm)),
        g1_loco::GET_STAND_HEIGHT => (0, r#"{"data":0.75}"#.into()),
        g1_loco::SET_FSM_ID => match parameter["data"].as_i64() {
            Some(id @ (0..=4 | 500 | 501 | 702 | 706 | 801)) => {
                model.fsm = id;
                (0, String::new())
            }
            _ => (g1_loco::error::INVALID_FSM_ID, String::new()),
        },
        g1_loco::SET_VELOCITY => {
            model.velocities.push(request.parameter.clone());
            (0, String::new())
        }
        _ => (api::status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}

fn arm(model: &mut Model, request: &ApiRequest) -> (i32, String) {
    use g1_arm::error::*;
    match request.header.api_id {
        g1_arm::GET_ACTION_LIST => (0, r#"{"data":[11,12,13,15,17,18,19,20,26,27]}"#.into()),
        g1_arm::EXECUTE_ACTION => {
            let parameter = json(&request.parameter);
            let Some(action) = parameter["data"].as_i64().filter(|&a| parameter["action_id"].as_i64() == Some(a))
            else {
                return (api::status::SERVER_API_PARAMETER, String::new());
            };
            if model.arm_sdk_active.is_some_and(|at| at.elapsed() < Duration::from_millis(200)) {
                return (ARM_SDK_OCCUPIED, String::new());
            }
            if ![500, 501, 801].contains(&model.fsm) {
                return (INVALID_FSM_ID, String::new());
            }
            match action {
                99 => model.holding = false,
                11..=27 if model.holding => return (HOLDING, String::new()),
                19 => model.holding = true, // a hug holds
                11..=27 => {}
                _ => return (INVALID_ACTION_ID, String::new()),
            }
            (0, String::new())
        }
        _ => (api::status::SERVER_API_NOT_IMPLEMENTED, String::new()),
    }
}

/// `scenario` with the robot and an open client, in a fresh namespace.
fn with_g1<F>(scenario: impl FnOnce(Robot, G1) -> F + Send)
where
    F: Future<Output = ()>,
{
    let _turn = one_at_a_time();
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let robot = Robot::spawn();
            let client = G1::open(G1Options::on(Some("lo"), 0)).expect("client");
            scenario(robot, client).await;
        })
    });
}

fn refused(result: Result<(), G1Error>) -> CommandError {
    match result {
        Err(G1Error::Command(e)) => e,
        other => panic!("not a command refusal: {other:?}"),
    }
}

#[test]
fn commands_wait_for_the_robots_mode_machine_and_damping_keeps_it() {
    with_g1(|robot, g1| async move {
        // No LowState yet: nothing may be sent, not even damping.
        assert_eq!(refused(g1.set_joints(&pattern())), CommandError::NoModeMachine);
        assert_eq!(refused(g1.hold(&[0.0; JOINTS])), CommandError::NoModeMachine);
        assert_eq!(refused(g1.damp()), CommandError::NoModeMachine);
        assert_eq!(refused(g1.set_arm_joints(&[JointCommand::default(); ARM_JOINTS])), CommandError::NoModeMachine);
        assert_eq!((g1.mode_machine(), g1.variant()), (None, None));
        assert_eq!(g1.stats().low_level.commands_sent, 0);
        assert_eq!(g1.battery(), None);

        robot.publish();
        assert!(g1.wait_state(WAIT, |_| true).await.is_some(), "rt/lowstate");
        assert_eq!((g1.mode_machine(), g1.variant()), (Some(5), Some(G1Variant::Dof29)));
        assert!((g1.joint_positions().unwrap()[3] - 0.03).abs() < 1e-6);
        // rt/lf/bmsstate beside it: the latest, and its topic's counters.
        until_async(WAIT, "rt/lf/bmsstate", || g1.battery().is_some()).await;
        let battery = g1.battery_handle().latest().unwrap();
        assert_eq!((battery.soc, battery.current.get(), battery.cell_vol[12].get()), (87, -3200, 4012));
        assert_eq!(battery.cell_vol[13].get(), 0);
        let bmsstate = g1.stats().bmsstate;
        assert!(bmsstate.samples > 0 && bmsstate.decode_errors == 0, "{bmsstate:?}");

        // Damping before any command: the robot's mode_machine, its 29 joints.
        g1.damp().unwrap();
        until_async(WAIT, "damping on rt/lowcmd", || !robot.received().lowcmd.is_empty()).await;
        let damping = robot.received().lowcmd[0];
        assert_eq!((damping.mode_machine, damping.mode_pr), (5, 0));
        for (i, m) in damping.motor_cmd.iter().enumerate() {
            let on = i < JOINTS;
            assert_eq!((m.mode, m.kp.get(), m.kd.get()), (u8::from(on), 0.0, if on { 1.0 } else { 0.0 }), "slot {i}");
        }
        assert!(g1.stats().low_level.damping_sent > 0);

        // A command: field for field as set, with the robot's mode_machine.
        let joints = pattern();
        until_async(WAIT, "the pattern on rt/lowcmd", || {
            g1.set_joints(&joints).unwrap();
            robot.received().lowcmd.last().is_some_and(|c| c.motor_cmd[0].kp.get() == 40.0)
        })
        .await;
        let sent = *robot.received().lowcmd.last().unwrap();
        assert_eq!((sent.mode_machine, sent.mode_pr), (5, 0));
        for (i, j) in joints.iter().enumerate() {
            let m = &sent.motor_cmd[i];
            let fields = [m.q.get(), m.dq.get(), m.kp.get(), m.kd.get(), m.tau.get()];
            assert_eq!((m.mode, fields), (1, [j.q_rad, j.dq_radps, j.kp, j.kd, j.tau_nm]), "slot {i}");
        }
        assert!(sent.motor_cmd[JOINTS..].iter().all(|m| *m == Default::default()));

        // Refusals: nothing changes.
        let mut other_machine = sent;
        other_machine.mode_machine = 6;
        assert_eq!(refused(g1.set_command(other_machine)), CommandError::ModeMachine { expected: 5, found: 6 });
        let mut knee = pattern();
        knee[slot::LEFT_KNEE].q_rad = JOINT_LIMITS[slot::LEFT_KNEE].q_min - 0.1;
        assert!(matches!(refused(g1.set_joints(&knee)), CommandError::OutOfRange { motor: 3, .. }));

        // Silence from the controller: damping, mode_machine kept.
        let before = robot.received().lowcmd.len();
        until_async(WAIT, "damping after the command went stale", || {
            robot.received().lowcmd[before..].iter().any(|c| c.motor_cmd[0].kp.get() == 0.0)
        })
        .await;
        let stale = robot.received().lowcmd.iter().rev().find(|c| c.motor_cmd[0].kp.get() == 0.0).copied().unwrap();
        assert_eq!(stale.mode_machine, 5);
        assert!(stale.motor_cmd[..JOINTS].iter().all(|m| m.mode == 1 && m.kd.get() == 1.0));
        assert_eq!(g1.stats().low_level.command_timeouts, 1);

        // The variant option wins over mode_machine: a 23-dof G1 has no waist roll (slot 13).
        let dof23 = G1::open(G1Options { variant: Some(G1Variant::Dof23), ..G1Options::on(Some("lo"), 0) }).unwrap();
        assert!(dof23.wait_state(WAIT, |_| true).await.is_some());
        assert_eq!((dof23.mode_machine(), dof23.variant()), (Some(5), Some(G1Variant::Dof23)));
        assert_eq!(refused(dof23.set_joints(&pattern())), CommandError::UndrivenMotor { motor: 13 });
        let mut joints = pattern();
        for (slot, j) in joints.iter_mut().enumerate() {
            if !G1Variant::Dof23.drives(slot) {
                *j = JointCommand::default();
            }
        }
        dof23.set_joints(&joints).unwrap();
        dof23.close();
    });
}

#[test]
fn release_loop_then_the_loco_service_until_a_mode_is_selected() {
    with_g1(|robot, g1| async move {
        robot.model().releases_needed = 2;
        assert_eq!(g1.mode().await.unwrap(), "ai");
        assert_eq!(g1.release().await.unwrap(), 2, "ReleaseMode until CheckMode reports no mode");
        assert_eq!(g1.mode().await.unwrap(), "");
        assert_eq!(g1.release().await.unwrap(), 0, "nothing left to release");

        let loco: &Loco = g1.loco();
        let off = loco.fsm_id().await.unwrap_err();
        assert!(matches!(off, G1Error::LocoStateUnavailable { api_id: g1_loco::GET_FSM_ID }), "{off:?}");
        assert!(off.to_string().contains("select_mode"), "the error says what to do: {off}");
        g1.select_mode("ai").await.unwrap();
        assert_eq!(loco.fsm_id().await.unwrap(), 4);
        loco.start().await.unwrap();
        assert_eq!(loco.fsm_id().await.unwrap(), 500);
        assert!(matches!(loco.set_fsm(12345).await, Err(G1Error::InvalidFsmId { fsm: 12345 })));
        assert_eq!(loco.stand_height().await.unwrap(), 0.75);

        let requests = robot.model().requests;
        for bad in [(f32::NAN, 0.0, 0.0, 1.0), (0.0, 0.0, 5.0, 1.0), (0.0, 0.0, 0.0, -1.0)] {
            let result = loco.set_velocity(bad.0, bad.1, bad.2, bad.3).await;
            assert!(matches!(result, Err(G1Error::Argument { .. })), "{bad:?}: {result:?}");
        }
        assert_eq!(robot.model().requests, requests, "nothing was sent");
        loco.set_velocity(0.3, -0.1, 0.2, 2.0).await.unwrap();
        let sent = json(robot.model().velocities.last().unwrap());
        assert_eq!(sent, serde_json::json!({"velocity": [0.3, -0.1, 0.2], "duration": 2}));

        // A robot whose mode never lets go: the release gives up, typed.
        robot.model().releases_needed = u32::MAX;
        let stuck = g1.release().await.unwrap_err();
        assert!(
            matches!(&stuck, G1Error::LowLevel(unitree::UnitreeError::NotReleased { mode, attempts: 10 }) if mode == "ai"),
            "{stuck:?}"
        );
    });
}

/// The arm pose: elbows bent, the other arm and waist joints held at 0.
fn arm_pose() -> [JointCommand; ARM_JOINTS] {
    std::array::from_fn(|k| {
        let slot = unitree::g1::ARM_SDK_JOINTS[k];
        let q = if slot == slot::LEFT_ELBOW || slot == slot::RIGHT_ELBOW { 0.5 } else { 0.0 };
        JointCommand::hold(q, 60.0, 1.5)
    })
}

/// The weights of frames `from..`, checked to never move more than one step (0.5/s × 20 ms).
fn weights(robot: &Robot, from: usize) -> Vec<f32> {
    let weights: Vec<f32> =
        robot.received().arm_sdk[from..].iter().map(|c| c.motor_cmd[slot::ARM_SDK_WEIGHT].q.get()).collect();
    for pair in weights.windows(2) {
        assert!((pair[1] - pair[0]).abs() <= 0.01 + 1e-6, "the weight jumped: {pair:?}");
    }
    weights
}

async fn arm_refusals(arm: &ArmActions, loco: &Loco) {
    assert!(matches!(arm.execute_action(17).await, Err(G1Error::ArmFsm { action: 17 })), "FSM 4: no actions");
    loco.start().await.unwrap();
    assert!(matches!(arm.execute_action(1234).await, Err(G1Error::InvalidActionId { action: 1234 })));
    arm.execute_action(19).await.unwrap();
    assert!(matches!(arm.execute_action(17).await, Err(G1Error::ArmHolding { action: 17 })));
    arm.release_arm().await.unwrap();
    arm.execute_action(17).await.unwrap();
    assert!(arm.action_list().await.unwrap().contains("17"));
}

#[test]
fn arm_sdk_weight_ramps_up_and_out_never_jumping_and_arm_actions_are_refused_typed() {
    with_g1(|robot, g1| async move {
        robot.publish();
        assert!(g1.wait_state(WAIT, |_| true).await.is_some());
        arm_refusals(g1.arm(), g1.loco()).await;
        assert!(matches!(g1.set_arm_weight(1.0), Err(G1Error::NoArmTargets)));
        assert_eq!(refused(g1.set_arm_weight(1.5)), CommandError::ArmSdkWeight { value: 1.5 });
        let mut leg = arm_pose();
        leg[0].q_rad = 5.0; // beyond the left shoulder's pitch range
        assert!(matches!(refused(g1.set_arm_joints(&leg)), CommandError::OutOfRange { motor: 15, .. }));
        assert_eq!(g1.stats().arm_sdk_sent, 0, "nothing sent yet");

        // Blend in: refresh the targets until the robot sees weight 1.
        let pose = arm_pose();
        g1.set_arm_joints(&pose).unwrap();
        g1.set_arm_weight(1.0).unwrap();
        until_async(WAIT, "weight 1 on rt/arm_sdk", || {
            g1.set_arm_joints(&pose).unwrap();
            robot.received().arm_sdk.last().is_some_and(|c| c.motor_cmd[slot::ARM_SDK_WEIGHT].q.get() == 1.0)
        })
        .await;
        let at_one = *robot.received().arm_sdk.last().unwrap();
        assert_eq!(at_one.mode_machine, 5);
        assert_eq!(at_one.motor_cmd[slot::LEFT_ELBOW].q.get(), 0.5);
        assert_eq!((at_one.motor_cmd[slot::RIGHT_ELBOW].kp.get(), at_one.motor_cmd[12].kd.get()), (60.0, 1.5));
        assert!(at_one.motor_cmd[..12].iter().all(|m| *m == Default::default()), "legs untouched");
        let up = weights(&robot, 0);
        assert!(up[0] <= 0.01 + 1e-6 && up.len() >= 100, "from 0, in steps: {} frames", up.len());
        assert!(matches!(g1.arm().execute_action(17).await, Err(G1Error::ArmSdkOccupied { action: 17 })));

        // No refresh: stale after 500 ms, ramped out to 0, then idle.
        let from = robot.received().arm_sdk.len();
        until_async(WAIT, "ramped out", || {
            robot.received().arm_sdk.last().is_some_and(|c| c.motor_cmd[29].q.get() == 0.0)
        })
        .await;
        let down = weights(&robot, from - 1);
        assert!(down.len() > 100, "1 → 0 in steps of 0.01: {} frames", down.len());
        assert_eq!(g1.stats().arm_sdk_command_timeouts, 1);
        assert_eq!(g1.stats().arm_sdk_write_drops, 0);

        // Blend in again, then close: the weight ramps to 0 before the last frame.
        let from = robot.received().arm_sdk.len();
        g1.set_arm_joints(&pose).unwrap();
        until_async(WAIT, "weight 0.3 again", || {
            g1.set_arm_joints(&pose).unwrap();
            robot.received().arm_sdk.last().is_some_and(|c| c.motor_cmd[29].q.get() >= 0.3)
        })
        .await;
        tokio::task::spawn_blocking(move || g1.close()).await.unwrap();
        until_async(WAIT, "the last frame", || {
            robot.received().arm_sdk.last().is_some_and(|c| c.motor_cmd[29].q.get() == 0.0)
        })
        .await;
        let closing = weights(&robot, from);
        assert_eq!(*closing.last().unwrap(), 0.0);
        assert!(closing.iter().any(|&w| w >= 0.3) && closing.len() > 60, "up to 0.3 and down: {closing:?}");
        assert!(robot.received().lowcmd.is_empty(), "no LowCmd was ever set: no damping burst");
    });
}
