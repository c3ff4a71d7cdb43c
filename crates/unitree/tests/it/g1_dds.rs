//! The G1 client against the simulated G1 (`robowire_sim::g1::G1Sim`) over real DDS, where
//! loopback carries multicast (`robowire_dds::netns`): the robot's `mode_machine` before any
//! command, the release loop, the locomotion and arm services' typed refusals, `rt/arm_sdk`'s
//! weight ramp, the battery. What the client puts on `rt/lowcmd` and `rt/arm_sdk` is read field
//! for field by a plain reader beside the robot ([`Wire`]); what the robot made of it, from the
//! simulator. Conditions are awaited with a generous timeout; nothing here measures time (the
//! arm stream's timing is its fake-clock tests).

use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Listener, Participant, ParticipantOptions};
use robowire_fixtures::wait::{one_at_a_time, until_async};
use robowire_sim::g1::{G1Fault, G1Sim, G1SimConfig, STAND_POSE_RAD, battery};
use unitree::g1::{
    ARM_JOINTS, ArmActions, CommandError, Device, G1, G1Error, G1Options, G1Variant, HgLowCmd, JOINT_LIMITS, JOINTS,
    JointCommand, Loco,
};
use unitree_proto::Message;
use unitree_proto::api::g1_loco;
use unitree_proto::g1::{ARM_SDK_TOPIC, slot};

use crate::common::{WAIT, pattern};

/// Every `rt/lowcmd` and `rt/arm_sdk` frame on the wire, in order.
#[derive(Debug, Default)]
struct Received {
    lowcmd: Vec<HgLowCmd>,
    arm_sdk: Vec<HgLowCmd>,
}

/// A reader that loses nothing on loopback.
const KEEP_ALL: Qos = Qos { reliable: true, max_blocking_ms: 0, depth: 1024, transient_local: false };

/// Readers of `rt/lowcmd` and `rt/arm_sdk` beside the robot, in a participant of their own: what
/// the client sent, as it arrived.
struct Wire {
    received: Arc<Mutex<Received>>,
    _listeners: [Listener; 2],
    _participant: Participant,
}

impl Wire {
    /// The readers, once matched with the open client's writers (a frame sent before is not
    /// seen).
    async fn beside_client() -> Self {
        let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap();
        let lowcmd = participant.reader::<HgLowCmd>(HgLowCmd::TOPIC, KEEP_ALL).unwrap();
        let arm_sdk = participant.reader::<HgLowCmd>(ARM_SDK_TOPIC, KEEP_ALL).unwrap();
        until_async(WAIT, "the client's rt/lowcmd and rt/arm_sdk writers matched", || {
            lowcmd.matched_writers() > 0 && arm_sdk.matched_writers() > 0
        })
        .await;
        let received = Arc::new(Mutex::new(Received::default()));
        let into = received.clone();
        let lowcmd = lowcmd.listen(move |s| robowire_rt::lock(&into).lowcmd.push(s.value));
        let into = received.clone();
        let arm_sdk = arm_sdk.listen(move |s| robowire_rt::lock(&into).arm_sdk.push(s.value));
        Self { received, _listeners: [lowcmd, arm_sdk], _participant: participant }
    }

    fn received(&self) -> MutexGuard<'_, Received> {
        robowire_rt::lock(&self.received)
    }
}

/// The simulated 29-dof G1 on `lo` (mode_machine 5), standing under its own controller.
fn g1_sim() -> G1Sim {
    let config = G1SimConfig { participant: ParticipantOptions::new(0, Some("lo")), ..G1SimConfig::default() };
    G1Sim::spawn(config).expect("simulator")
}

/// `scenario` with an open client and the wire beside it, in a fresh namespace; the scenario
/// starts the robot.
fn with_client<F>(scenario: impl FnOnce(G1, Wire) -> F + Send)
where
    F: Future<Output = ()>,
{
    let _turn = one_at_a_time();
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let client = G1::open(G1Options::on(Some("lo"), 0)).expect("client");
            let wire = Wire::beside_client().await;
            scenario(client, wire).await;
        })
    });
}

/// Turns from a command to damping on `rt/lowcmd` (motor 0's `kp` from non-zero to 0).
fn damping_onsets(frames: &[HgLowCmd]) -> usize {
    frames.windows(2).filter(|p| p[0].motor_cmd[0].kp.get() != 0.0 && p[1].motor_cmd[0].kp.get() == 0.0).count()
}

fn refused(result: Result<(), G1Error>) -> CommandError {
    match result {
        Err(G1Error::Command(e)) => e,
        other => panic!("not a command refusal: {other:?}"),
    }
}

#[test]
fn commands_wait_for_the_robots_mode_machine_and_damping_keeps_it() {
    with_client(|g1, wire| async move {
        // No robot yet, no LowState: nothing may be sent, not even damping.
        assert_eq!(refused(g1.set_joints(&pattern())), CommandError::NoModeMachine);
        assert_eq!(refused(g1.hold(&[0.0; JOINTS])), CommandError::NoModeMachine);
        assert_eq!(refused(g1.damp()), CommandError::NoModeMachine);
        assert_eq!(refused(g1.set_arm_joints(&[JointCommand::default(); ARM_JOINTS])), CommandError::NoModeMachine);
        assert_eq!((g1.mode_machine(), g1.variant()), (None, None));
        assert_eq!(g1.stats().low_level.commands_sent, 0);
        assert_eq!(g1.battery(), None);

        let sim = g1_sim();
        assert!(g1.wait_state(WAIT, |_| true).await.is_some(), "rt/lowstate");
        assert_eq!((g1.mode_machine(), g1.variant()), (Some(5), Some(G1Variant::Dof29)));
        let q = g1.joint_positions().unwrap();
        assert!(q.iter().zip(STAND_POSE_RAD).all(|(q, stand)| (q - stand).abs() < 1e-6), "standing: {q:?}");
        // rt/lf/bmsstate beside it: the latest, and its topic's counters.
        until_async(WAIT, "rt/lf/bmsstate", || g1.battery().is_some()).await;
        let state = g1.battery_handle().latest().unwrap();
        assert_eq!((state.soc, state.current.get()), (battery::FULL_SOC_PERCENT, battery::CURRENT_MA));
        let cells = state.cell_vol.map(|v| v.get());
        assert!(cells[..battery::CELLS].iter().all(|&mv| mv == cells[0] && mv > 3_600), "{cells:?}");
        assert_eq!(cells[battery::CELLS], 0, "a 13-cell pack");
        let bmsstate = g1.stats().bmsstate;
        assert!(bmsstate.samples > 0 && bmsstate.decode_errors == 0, "{bmsstate:?}");

        // Damping before any command: the robot's mode_machine, its 29 joints. The robot's
        // controller owns the motors: the robot ignores it, and counts it.
        g1.damp().unwrap();
        until_async(WAIT, "damping on rt/lowcmd", || !wire.received().lowcmd.is_empty()).await;
        let damping = wire.received().lowcmd[0];
        assert_eq!((damping.mode_machine, damping.mode_pr), (5, 0));
        for (i, m) in damping.motor_cmd.iter().enumerate() {
            let on = i < JOINTS;
            assert_eq!((m.mode, m.kp.get(), m.kd.get()), (u8::from(on), 0.0, if on { 1.0 } else { 0.0 }), "slot {i}");
        }
        // The stream counts a frame once it is sent: maybe after the wire has it.
        until_async(WAIT, "damping counted", || g1.stats().low_level.damping_sent > 0).await;
        until_async(WAIT, "damping ignored by the robot", || sim.snapshot().lowcmd.ignored_mode > 0).await;

        // Released, the robot takes the client's LowCmds: its mode_machine is right.
        assert_eq!(g1.release().await.unwrap(), 1);
        let accepted = sim.snapshot().lowcmd.accepted;
        // A command: field for field as set, with the robot's mode_machine.
        let joints = pattern();
        until_async(WAIT, "the pattern on rt/lowcmd, taken by the robot", || {
            g1.set_joints(&joints).unwrap();
            wire.received().lowcmd.last().is_some_and(|c| c.motor_cmd[0].kp.get() == 40.0)
                && sim.snapshot().lowcmd.accepted > accepted
        })
        .await;
        let robot = sim.snapshot().lowcmd;
        assert_eq!((robot.bad_mode_machine, robot.bad_crc, robot.disabled_motors), (0, 0, 0), "{robot:?}");
        let sent = *wire.received().lowcmd.last().unwrap();
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
        let before = wire.received().lowcmd.len();
        until_async(WAIT, "damping after the command went stale", || {
            wire.received().lowcmd[before..].iter().any(|c| c.motor_cmd[0].kp.get() == 0.0)
        })
        .await;
        let stale = wire.received().lowcmd.iter().rev().find(|c| c.motor_cmd[0].kp.get() == 0.0).copied().unwrap();
        assert_eq!(stale.mode_machine, 5);
        assert!(stale.motor_cmd[..JOINTS].iter().all(|m| m.mode == 1 && m.kd.get() == 1.0));
        // Each timeout is one turn from the command to damping on the wire: this one, and one
        // more for every time this test's own refreshing stalled 100 ms (a loaded machine).
        let onsets = damping_onsets(&wire.received().lowcmd) as u64;
        assert!(onsets >= 1);
        until_async(WAIT, "each timeout counted", || g1.stats().low_level.command_timeouts == onsets).await;
        assert_eq!(sim.snapshot().lowcmd.bad_mode_machine, 0);

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
    with_client(|g1, _wire| async move {
        let sim = g1_sim();
        // The robot's mode lets go at the second ReleaseMode.
        sim.inject(G1Fault::ModeHeld { releases: 1 });
        assert_eq!(g1.mode().await.unwrap(), "ai");
        assert_eq!(g1.release().await.unwrap(), 2, "ReleaseMode until CheckMode reports no mode");
        assert_eq!(g1.mode().await.unwrap(), "");
        assert_eq!(sim.snapshot().mode, "");
        assert_eq!(g1.release().await.unwrap(), 0, "nothing left to release");

        let loco: &Loco = g1.loco();
        let off = loco.fsm_id().await.unwrap_err();
        assert!(matches!(off, G1Error::LocoStateUnavailable { api_id: g1_loco::GET_FSM_ID }), "{off:?}");
        assert!(off.to_string().contains("select_mode"), "the error says what to do: {off}");
        g1.select_mode("ai").await.unwrap();
        assert_eq!(loco.fsm_id().await.unwrap(), 500, "the walking controller has the motors again");
        loco.stand_up().await.unwrap();
        assert_eq!(loco.fsm_id().await.unwrap(), 4);
        loco.start().await.unwrap();
        assert_eq!(loco.fsm_id().await.unwrap(), 500);
        assert_eq!(sim.snapshot().fsm_id, 500);
        assert!(matches!(loco.set_fsm(12345).await, Err(G1Error::InvalidFsmId { fsm: 12345 })));
        assert!(matches!(loco.set_arm_task(7).await, Err(G1Error::InvalidTaskId { task: 7 })));
        loco.set_arm_task(0).await.unwrap();
        assert_eq!(loco.stand_height().await.unwrap(), 0.75);

        let requests = sim.snapshot().stream.requests;
        for bad in [(f32::NAN, 0.0, 0.0, 1.0), (0.0, 0.0, 5.0, 1.0), (0.0, 0.0, 0.0, -1.0)] {
            let result = loco.set_velocity(bad.0, bad.1, bad.2, bad.3).await;
            assert!(matches!(result, Err(G1Error::Argument { .. })), "{bad:?}: {result:?}");
        }
        assert_eq!(sim.snapshot().stream.requests, requests, "nothing was sent");
        let _ = sim.take_log();
        loco.set_velocity(0.3, -0.1, 0.2, 2.0).await.unwrap();
        let log = sim.take_log().join("\n");
        assert!(log.contains("loco SetVelocity [0.3, -0.1, 0.2] for 2 s"), "as set, f32 for f32: {log}");

        // A robot whose mode never lets go: the release gives up, typed.
        sim.inject(G1Fault::ModeHeld { releases: u32::MAX });
        let stuck = g1.release().await.unwrap_err();
        assert!(
            matches!(&stuck, G1Error::LowLevel(unitree::UnitreeError::NotReleased { mode, attempts: 10 }) if mode == "ai"),
            "{stuck:?}"
        );
        sim.clear_faults();
        assert_eq!(g1.release().await.unwrap(), 1);
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

/// Turns of the `rt/arm_sdk` weight from rising or holding to falling: a ramp-out starting.
fn ramp_outs(weights: &[f32]) -> usize {
    let falling: Vec<bool> = weights.windows(2).map(|p| p[1] < p[0]).collect();
    (0..falling.len()).filter(|&i| falling[i] && (i == 0 || !falling[i - 1])).count()
}

/// The weights of frames `from..`, checked to never move more than one step (0.5/s × 20 ms).
fn weights(wire: &Wire, from: usize) -> Vec<f32> {
    let weights: Vec<f32> =
        wire.received().arm_sdk[from..].iter().map(|c| c.motor_cmd[slot::ARM_SDK_WEIGHT].q.get()).collect();
    for pair in weights.windows(2) {
        assert!((pair[1] - pair[0]).abs() <= 0.01 + 1e-6, "the weight jumped: {pair:?}");
    }
    weights
}

async fn arm_refusals(arm: &ArmActions, loco: &Loco) {
    loco.stand_up().await.unwrap();
    assert!(matches!(arm.execute_action(17).await, Err(G1Error::ArmFsm { action: 17 })), "FSM 4: no actions");
    loco.start().await.unwrap();
    assert!(matches!(arm.execute_action(1234).await, Err(G1Error::InvalidActionId { action: 1234 })));
    arm.execute_action(19).await.unwrap(); // a hug holds its pose
    assert!(matches!(arm.execute_action(17).await, Err(G1Error::ArmHolding { action: 17 })));
    arm.release_arm().await.unwrap();
    arm.execute_action(17).await.unwrap();
    assert!(arm.action_list().await.unwrap().contains(r#""id":17"#));
}

/// `call`'s outcome, the arm targets refreshed every 20 ms meanwhile (they go stale in 500 ms).
async fn refreshing<T>(g1: &G1, pose: &[JointCommand; ARM_JOINTS], call: impl Future<Output = T>) -> T {
    let mut call = std::pin::pin!(call);
    let mut every = tokio::time::interval(Duration::from_millis(20));
    loop {
        tokio::select! {
            outcome = &mut call => return outcome,
            _ = every.tick() => g1.set_arm_joints(pose).unwrap(),
        }
    }
}

#[test]
fn arm_sdk_weight_ramps_up_and_out_never_jumping_and_arm_actions_are_refused_typed() {
    with_client(|g1, wire| async move {
        let sim = g1_sim();
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
        until_async(WAIT, "weight 1 on rt/arm_sdk, blended in by the robot", || {
            g1.set_arm_joints(&pose).unwrap();
            wire.received().arm_sdk.last().is_some_and(|c| c.motor_cmd[slot::ARM_SDK_WEIGHT].q.get() == 1.0)
                && sim.snapshot().arm_sdk.weight == 1.0
        })
        .await;
        let at_one = *wire.received().arm_sdk.last().unwrap();
        assert_eq!(at_one.mode_machine, 5);
        assert_eq!(at_one.motor_cmd[slot::LEFT_ELBOW].q.get(), 0.5);
        assert_eq!((at_one.motor_cmd[slot::RIGHT_ELBOW].kp.get(), at_one.motor_cmd[12].kd.get()), (60.0, 1.5));
        assert!(at_one.motor_cmd[..12].iter().all(|m| *m == Default::default()), "legs untouched");
        let up = weights(&wire, 0);
        assert!(up[0] <= 0.01 + 1e-6 && up.len() >= 100, "from 0, in steps: {} frames", up.len());
        let occupied = refreshing(&g1, &pose, g1.arm().execute_action(17)).await;
        assert!(matches!(occupied, Err(G1Error::ArmSdkOccupied { action: 17 })), "{occupied:?}");

        // No refresh: stale after 500 ms, ramped out to 0, then idle.
        let from = wire.received().arm_sdk.len();
        until_async(WAIT, "ramped out", || {
            wire.received().arm_sdk.last().is_some_and(|c| c.motor_cmd[slot::ARM_SDK_WEIGHT].q.get() == 0.0)
        })
        .await;
        let down = weights(&wire, from - 1);
        assert!(down.len() > 100, "1 → 0 in steps of 0.01: {} frames", down.len());
        assert_eq!(*down.last().unwrap(), 0.0);
        // Each timeout is one ramp-out on the wire: this one, and one more for every time this
        // test's own refreshing stalled 500 ms (a loaded machine).
        let ramp_outs = ramp_outs(&weights(&wire, 0));
        assert!(ramp_outs >= 1);
        assert_eq!(g1.stats().arm_sdk_command_timeouts, ramp_outs as u64);
        assert_eq!(g1.stats().arm_sdk_write_drops, 0);
        // At weight 0 the robot's controller has the arms again: actions run.
        until_async(WAIT, "the robot at weight 0", || sim.snapshot().arm_sdk.weight == 0.0).await;
        g1.arm().execute_action(17).await.unwrap();

        // Blend in again, then close: the weight ramps to 0 before the last frame.
        let from = wire.received().arm_sdk.len();
        g1.set_arm_joints(&pose).unwrap();
        until_async(WAIT, "weight 0.3 again", || {
            g1.set_arm_joints(&pose).unwrap();
            wire.received().arm_sdk.last().is_some_and(|c| c.motor_cmd[slot::ARM_SDK_WEIGHT].q.get() >= 0.3)
        })
        .await;
        tokio::task::spawn_blocking(move || g1.close()).await.unwrap();
        until_async(WAIT, "the last frame", || {
            wire.received().arm_sdk.last().is_some_and(|c| c.motor_cmd[slot::ARM_SDK_WEIGHT].q.get() == 0.0)
        })
        .await;
        let closing = weights(&wire, from);
        assert_eq!(*closing.last().unwrap(), 0.0);
        assert!(closing.iter().any(|&w| w >= 0.3) && closing.len() > 60, "up to 0.3 and down: {closing:?}");
        assert!(wire.received().lowcmd.is_empty(), "no LowCmd was ever set: no damping burst");
        assert_eq!(sim.snapshot().lowcmd.accepted + sim.snapshot().lowcmd.ignored_mode, 0);
        until_async(WAIT, "the robot at weight 0 again", || sim.snapshot().arm_sdk.weight == 0.0).await;
    });
}
