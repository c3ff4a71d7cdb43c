//! The simulated G1 driven from the wire, in a private network (`robowire_dds::netns`): its
//! motors taken only once released and only by LowCmds the robot accepts (CRC, `mode_machine`,
//! `mode` per motor), PR and AB on the ankles, `rt/arm_sdk` blended by its weight, the services
//! refusing motion after ReleaseMode, and the faults.

use std::time::Instant;

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions, Reader, Writer};
use robowire_sim::g1::{G1Fault, G1Sim, G1SimConfig, G1Snapshot, HOLDING_ACTIONS, JOINTS, STAND_POSE_RAD, SimClock};
use unitree_proto::api::{self, g1_arm, g1_loco, motion_switcher, status};
use unitree_proto::g1::{self, ARM_SDK_JOINTS, ARM_SDK_TOPIC, G1Variant, ModePr, slot};
use unitree_proto::{HgLowCmd, HgLowState, Message};

use crate::unitree_wire::{ServiceClient, Unsealed, WAIT};

/// The other end of the wire: Unitree's side.
struct Client {
    runtime: tokio::runtime::Runtime,
    lowcmd: Writer<HgLowCmd>,
    lowcmd_unsealed: Writer<Unsealed<HgLowCmd>>,
    arm_sdk: Writer<HgLowCmd>,
    arm_sdk_unsealed: Writer<Unsealed<HgLowCmd>>,
    states: Reader<HgLowState>,
    switcher: ServiceClient,
    loco: ServiceClient,
    arm: ServiceClient,
    next_id: i64,
    _participant: Participant,
}

impl Client {
    fn new() -> Self {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap();
        let rpc = |service| ServiceClient::new(&participant, service);
        let (switcher, loco, arm) = (rpc(motion_switcher::SERVICE), rpc(g1_loco::SERVICE), rpc(g1_arm::SERVICE));
        Self {
            lowcmd: participant.writer(HgLowCmd::TOPIC, Qos::WRITER).unwrap(),
            lowcmd_unsealed: participant.writer(HgLowCmd::TOPIC, Qos::WRITER).unwrap(),
            arm_sdk: participant.writer(ARM_SDK_TOPIC, Qos::WRITER).unwrap(),
            arm_sdk_unsealed: participant.writer(ARM_SDK_TOPIC, Qos::WRITER).unwrap(),
            states: participant.reader(HgLowState::TOPIC, Qos::READER).unwrap(),
            switcher,
            loco,
            arm,
            next_id: 1,
            runtime,
            _participant: participant,
        }
    }

    /// The next state the robot sends.
    fn state(&mut self) -> HgLowState {
        let states = &mut self.states;
        self.runtime.block_on(async {
            tokio::time::timeout(WAIT, states.recv()).await.expect("a LowState in time").unwrap().value
        })
    }

    /// Calls `api_id` of `service` (`motion_switcher`, `sport` or `arm`) with `parameter`: its
    /// code and data.
    fn call(&mut self, service: &str, api_id: i64, parameter: &str) -> (i32, String) {
        self.next_id += 1;
        self.call_as(self.next_id, service, api_id, parameter)
    }

    /// As [`call`](Self::call), under `id` (the last call's: the request written again).
    fn call_as(&mut self, id: i64, service: &str, api_id: i64, parameter: &str) -> (i32, String) {
        let client = match service {
            motion_switcher::SERVICE => &mut self.switcher,
            g1_loco::SERVICE => &mut self.loco,
            _ => &mut self.arm,
        };
        let answer = self.runtime.block_on(client.call(id, api_id, parameter));
        (answer.code, answer.data)
    }

    fn release(&mut self) {
        assert_eq!(self.call(motion_switcher::SERVICE, motion_switcher::RELEASE_MODE, "{}").0, status::OK);
        let (_, mode) = self.call(motion_switcher::SERVICE, motion_switcher::CHECK_MODE, "{}");
        assert_eq!(motion_switcher::mode_name(&mode), Some(""), "{mode}");
    }

    /// Sends what `command` gives once per state received, until `done` holds for the state
    /// and the simulator's snapshot.
    fn drive_until(
        &mut self,
        sim: &G1Sim,
        mut command: impl FnMut(&Self),
        mut done: impl FnMut(&HgLowState, &G1Snapshot) -> bool,
    ) -> (HgLowState, G1Snapshot) {
        let start = Instant::now();
        loop {
            command(self);
            let state = self.state();
            let snapshot = sim.snapshot();
            if done(&state, &snapshot) {
                return (state, snapshot);
            }
            assert!(start.elapsed() < WAIT, "not reached; last state {:?}\n{snapshot:?}", &state.motor_state[..6]);
        }
    }
}

fn sim(variant: G1Variant) -> G1Sim {
    let config = G1SimConfig { participant: ParticipantOptions::new(0, Some("lo")), ..G1SimConfig::new(variant) };
    G1Sim::spawn(config).expect("simulator")
}

fn near(a: f32, b: f32) -> bool {
    (a - b).abs() < 0.02
}

fn q(state: &HgLowState, slot: usize) -> f32 {
    state.motor_state[slot].q.get()
}

/// Unitree's example gains holding `pose`, with the robot's `mode_machine`.
fn hold(pose: &[f32; JOINTS]) -> HgLowCmd {
    g1::hold(pose, 5, G1Variant::Dof29)
}

#[test]
fn lowcmds_drive_the_motors_only_once_released_and_as_the_robot_checks_them() {
    with_loopback_multicast(|| {
        let sim = sim(G1Variant::Dof29);
        let mut c = Client::new();
        let state = c.state();
        assert_eq!((state.mode_machine, state.mode_pr), (5, 0));
        assert!((0..JOINTS).all(|s| q(&state, s) == STAND_POSE_RAD[s]), "standing: {:?}", state.motor_state);
        assert_eq!(state.crc.get(), state.computed_crc(), "sealed by the encoder");
        let zero = hold(&[0.0; JOINTS]);

        // Owned by the robot's controller: ignored, counted, said once.
        c.drive_until(&sim, |c| c.lowcmd.write(zero).unwrap(), |_, s| s.lowcmd.ignored_mode > 2);
        assert!((0..JOINTS).all(|s| q(&c.state(), s) == STAND_POSE_RAD[s]));
        let log = sim.take_log().join("\n");
        assert!(log.contains("booted standing") && log.contains("LowCmd ignored: sport mode \"ai\""), "{log}");

        c.release();
        let log = sim.take_log().join("\n");
        assert!(log.contains("ReleaseMode: sport mode \"ai\" released"), "{log}");
        // A wrong mode_machine and a wrong CRC: counted, never applied.
        let mut wrong_machine = zero;
        wrong_machine.mode_machine = 0;
        c.drive_until(&sim, |c| c.lowcmd.write(wrong_machine).unwrap(), |_, s| s.lowcmd.bad_mode_machine > 2);
        c.drive_until(&sim, |c| c.lowcmd_unsealed.write(Unsealed(zero)).unwrap(), |_, s| s.lowcmd.bad_crc > 2);
        let (state, snapshot) = c.drive_until(&sim, |_| {}, |_, _| true);
        assert!((0..JOINTS).all(|s| q(&state, s) == STAND_POSE_RAD[s]), "nothing moved");
        assert_eq!(snapshot.lowcmd.accepted, 0);
        assert!(sim.take_log().join("\n").contains("mode_machine 0 is not the robot's 5"));

        // A mode-0 motor with a target: counted, no torque; the frame's other motors move.
        let mut knee_off = zero;
        knee_off.motor_cmd[slot::LEFT_KNEE].mode = 0;
        let (state, snapshot) = c.drive_until(
            &sim,
            |c| c.lowcmd.write(knee_off).unwrap(),
            |state, _| (0..JOINTS).all(|s| s == slot::LEFT_KNEE || q(state, s).abs() < 0.01),
        );
        assert_eq!(q(&state, slot::LEFT_KNEE), STAND_POSE_RAD[slot::LEFT_KNEE], "mode 0: no torque");
        assert!(snapshot.lowcmd.disabled_motors > 0 && snapshot.lowcmd.accepted > 0, "{:?}", snapshot.lowcmd);

        // PR: the slots are the ankle's pitch and roll.
        let mut pose = [0.0; JOINTS];
        (pose[slot::LEFT_ANKLE_PITCH], pose[slot::LEFT_ANKLE_ROLL]) = (0.3, 0.1);
        let pr = hold(&pose);
        c.drive_until(
            &sim,
            |c| c.lowcmd.write(pr).unwrap(),
            |state, _| state.mode_pr == 0 && near(q(state, 4), 0.3) && near(q(state, 5), 0.1),
        );
        // AB: the slots are the A (roll slot) and B (pitch slot) motors; the state says so.
        let (a, b) = g1::pr_to_ab(-0.2, 0.15);
        let mut ab = hold(&[0.0; JOINTS]);
        ab.mode_pr = ModePr::Ab as u8;
        (ab.motor_cmd[slot::LEFT_ANKLE_ROLL].q, ab.motor_cmd[slot::LEFT_ANKLE_PITCH].q) = (a.into(), b.into());
        let (_, snapshot) = c.drive_until(
            &sim,
            |c| c.lowcmd.write(ab).unwrap(),
            |state, _| state.mode_pr == 1 && near(q(state, 5), a) && near(q(state, 4), b),
        );
        assert!(near(snapshot.joints_rad[4], -0.2) && near(snapshot.joints_rad[5], 0.15), "{:?}", snapshot.joints_rad);
        assert_eq!(snapshot.lowcmd.malformed, 0);
    });
}

#[test]
fn arm_sdk_blends_by_its_weight_while_the_controller_owns_the_motors() {
    with_loopback_multicast(|| {
        let sim = sim(G1Variant::Dof29);
        let mut c = Client::new();
        let arm = |weight: f32, elbow: f32| {
            // As Unitree's arm examples send it: modes and mode_machine 0.
            let mut cmd = HgLowCmd::default();
            for &j in &ARM_SDK_JOINTS {
                cmd.motor_cmd[j].kp = 60.0.into();
                cmd.motor_cmd[j].kd = 1.5.into();
            }
            cmd.motor_cmd[slot::LEFT_ELBOW].q = elbow.into();
            cmd.motor_cmd[slot::ARM_SDK_WEIGHT].q = weight.into();
            cmd
        };
        let (half, full) = (arm(0.5, 1.0), arm(1.0, 1.0));
        // Half: the controller (elbow 0, kp 50) and arm_sdk (1.0, kp 60) blended half and half.
        c.drive_until(
            &sim,
            |c| c.arm_sdk.write(half).unwrap(),
            |state, s| near(q(state, slot::LEFT_ELBOW), 0.5) && s.arm_sdk.weight == 0.5,
        );
        let (state, snapshot) =
            c.drive_until(&sim, |c| c.arm_sdk.write(full).unwrap(), |state, _| near(q(state, slot::LEFT_ELBOW), 1.0));
        assert_eq!(q(&state, slot::LEFT_KNEE), STAND_POSE_RAD[slot::LEFT_KNEE], "the legs stay the controller's");
        assert_eq!(snapshot.arm_sdk.unsealed, 0);
        // Unsealed frames (Unitree's C++ example sends them so): taken, counted.
        c.drive_until(&sim, |c| c.arm_sdk_unsealed.write(Unsealed(full)).unwrap(), |_, s| s.arm_sdk.unsealed > 2);
        // Silent: the weight decays and the controller takes the arm back.
        let mut last = 1.0;
        c.drive_until(
            &sim,
            |_| {},
            |state, s| {
                assert!(s.arm_sdk.weight <= last, "never up without a frame");
                last = s.arm_sdk.weight;
                s.arm_sdk.weight == 0.0 && q(state, slot::LEFT_ELBOW).abs() < 0.01
            },
        );

        // Released: arm_sdk is ignored; SelectMode gives the motors back to the controller.
        c.release();
        c.drive_until(&sim, |c| c.arm_sdk.write(full).unwrap(), |_, s| s.arm_sdk.ignored_released > 2);
        assert_eq!(sim.snapshot().arm_sdk.weight, 0.0);
        assert!(sim.take_log().join("\n").contains("rt/arm_sdk ignored: no mode owns the motors"));
        assert_eq!(c.call(motion_switcher::SERVICE, motion_switcher::SELECT_MODE, r#"{"name":"ai"}"#).0, status::OK);
        c.drive_until(
            &sim,
            |c| c.arm_sdk.write(half).unwrap(),
            |state, s| s.mode == "ai" && near(q(state, slot::LEFT_ELBOW), 0.5),
        );
    });
}

#[test]
fn the_services_refuse_motion_after_release_and_accept_it_after_select() {
    with_loopback_multicast(|| {
        let sim = sim(G1Variant::Dof29);
        let mut c = Client::new();
        let (loco, arm, switcher) = (g1_loco::SERVICE, g1_arm::SERVICE, motion_switcher::SERVICE);
        assert_eq!(c.call(switcher, api::API_VERSION_ID, "{}"), (status::OK, "1.0.0.1".into()));
        assert_eq!(c.call(loco, api::API_VERSION_ID, "{}"), (status::OK, "1.0.0.0".into()));
        assert_eq!(c.call(arm, api::API_VERSION_ID, "{}"), (status::OK, "1.0.0.14".into()));
        assert_eq!(c.call(loco, g1_loco::GET_FSM_ID, "{}"), (status::OK, r#"{"data":500}"#.into()));
        let walk = r#"{"velocity":[0.3,0.0,0.2],"duration":1.0}"#;
        assert_eq!(c.call(loco, g1_loco::SET_VELOCITY, walk).0, status::OK);
        assert_eq!(c.call(loco, g1_loco::SET_VELOCITY, r#"{"velocity":[0.3]}"#).0, status::SERVER_API_PARAMETER);
        assert_eq!(c.call(loco, g1_loco::SET_VELOCITY, "not json").0, status::SERVER_API_PARAMETER);
        assert_eq!(c.call(loco, g1_loco::SET_FSM_ID, r#"{"data":12345}"#).0, g1_loco::error::INVALID_FSM_ID);
        assert_eq!(c.call(loco, g1_loco::SET_STAND_HEIGHT, r#"{"data":0.6}"#).0, status::OK);
        assert_eq!(c.call(loco, g1_loco::GET_STAND_HEIGHT, "{}"), (status::OK, r#"{"data":0.6}"#.into()));
        assert_eq!(c.call(arm, g1_arm::EXECUTE_ACTION, r#"{"data":26}"#).0, status::OK);
        assert_eq!(c.call(arm, g1_arm::EXECUTE_ACTION, r#"{"action_id":99}"#).0, status::OK);
        assert_eq!(c.call(arm, g1_arm::EXECUTE_ACTION, r#"{"data":5}"#).0, g1_arm::error::INVALID_ACTION_ID);
        let (code, list) = c.call(arm, g1_arm::GET_ACTION_LIST, "{}");
        assert!(code == status::OK && list.contains(r#""name":"high wave""#), "{list}");

        c.release();
        assert_eq!(c.call(loco, g1_loco::SET_VELOCITY, walk).0, g1_loco::error::LOCO_STATE_UNAVAILABLE);
        assert_eq!(c.call(loco, g1_loco::GET_FSM_ID, "{}").0, g1_loco::error::LOCO_STATE_UNAVAILABLE);
        assert_eq!(c.call(arm, g1_arm::EXECUTE_ACTION, r#"{"data":99}"#).0, g1_arm::error::INVALID_FSM_ID);
        assert_eq!(c.call(switcher, motion_switcher::SELECT_MODE, "{}").0, status::SERVER_API_PARAMETER);
        assert_eq!(c.call(switcher, motion_switcher::SELECT_MODE, r#"{"name":"ai"}"#).0, status::OK);
        assert_eq!(c.call(loco, g1_loco::SET_VELOCITY, walk).0, status::OK);
        assert_eq!(c.call(loco, g1_loco::SET_FSM_ID, r#"{"data":1}"#).0, status::OK);
        assert_eq!(c.call(arm, g1_arm::EXECUTE_ACTION, r#"{"data":99}"#).0, g1_arm::error::INVALID_FSM_ID, "damping");
        let snapshot = sim.snapshot();
        assert_eq!((snapshot.mode.as_str(), snapshot.fsm_id), ("ai", 1));
        assert!(snapshot.stream.requests >= 20, "{}", snapshot.stream.requests);
        let log = sim.take_log().join("\n");
        assert!(log.contains("arm action 26 (high wave)") && log.contains("loco SetFsmId 1"), "{log}");
    });
}

#[test]
fn faults_silence_a_motor_and_flip_bits_on_the_wire() {
    with_loopback_multicast(|| {
        let sim = sim(G1Variant::Dof29);
        let mut c = Client::new();
        c.state();
        sim.inject(G1Fault::MotorFault { motor: 3 });
        let (state, _) = c.drive_until(&sim, |_| {}, |state, _| state.motor_state[3].mode == 0);
        assert_eq!(state.motor_state[3].motorstate.get(), 1);
        sim.inject(G1Fault::BitFlips { every: 2 });
        let caught = |c: &Client| c.states.stats().checksum_errors;
        let start = Instant::now();
        while caught(&c) < 5 {
            c.state();
            assert!(start.elapsed() < WAIT, "no corrupted state caught");
        }
        assert!(sim.snapshot().stream.corrupted_states >= 5);
        sim.inject(G1Fault::Silence);
        let (sent, ran) = (sim.snapshot().stream.lowstate.samples, sim.snapshot().stream.state_lateness.count);
        let start = Instant::now();
        while sim.snapshot().stream.state_lateness.count < ran + 50 {
            assert!(start.elapsed() < WAIT, "the stream stalled");
            std::thread::yield_now();
        }
        assert_eq!(sim.snapshot().stream.lowstate.samples, sent, "silent for 50 ticks");
        sim.clear_faults();
        let (state, snapshot) = c.drive_until(&sim, |_| {}, |state, _| state.motor_state[3].mode == 1);
        assert!(snapshot.stream.lowstate.samples > sent);
        assert_eq!(state.crc.get(), state.computed_crc());
        let log = sim.take_log().join("\n");
        assert!(log.contains("fault injected: Silence") && log.contains("faults cleared"), "{log}");
    });
}

#[test]
fn a_23_dof_g1_reports_mode_machine_4_and_drives_only_its_joints() {
    with_loopback_multicast(|| {
        let sim = sim(G1Variant::Dof23);
        let mut c = Client::new();
        let state = c.state();
        assert_eq!(state.mode_machine, 4);
        for s in [13, 14, 20, 21, 27, 28] {
            assert_eq!((state.motor_state[s].mode, q(&state, s)), (0, 0.0), "slot {s} drives nothing");
        }
        c.release();
        // Unitree's 29-joint command with the 23-dof robot's mode_machine: its joints follow, the
        // others drive nothing.
        let mut all = g1::hold(&[0.3; JOINTS], 4, G1Variant::Dof29);
        all.motor_cmd[slot::LEFT_ANKLE_ROLL].q = 0.0.into();
        all.motor_cmd[slot::RIGHT_ANKLE_ROLL].q = 0.0.into();
        let (state, _) = c.drive_until(&sim, |c| c.lowcmd.write(all).unwrap(), |state, _| near(q(state, 19), 0.3));
        assert_eq!(q(&state, 20), 0.0);
        let mut wrong = all;
        wrong.mode_machine = 5;
        c.drive_until(&sim, |c| c.lowcmd.write(wrong).unwrap(), |_, s| s.lowcmd.bad_mode_machine > 0);
    });
}

#[test]
fn a_mode_that_withstands_release_mode_is_named_until_it_lets_go() {
    with_loopback_multicast(|| {
        let sim = sim(G1Variant::Dof29);
        let mut c = Client::new();
        let switcher = motion_switcher::SERVICE;
        let mode = |c: &mut Client| {
            let (_, data) = c.call(switcher, motion_switcher::CHECK_MODE, "{}");
            motion_switcher::mode_name(&data).unwrap().to_owned()
        };
        // The next two ReleaseModes are answered and let nothing go; the third does.
        sim.inject(G1Fault::ModeHeld { releases: 2 });
        for _ in 0..2 {
            assert_eq!(c.call(switcher, motion_switcher::RELEASE_MODE, "{}").0, status::OK);
            assert_eq!(mode(&mut c), "ai");
        }
        assert_eq!(sim.snapshot().mode, "ai");
        assert_eq!(c.call(g1_loco::SERVICE, g1_loco::GET_FSM_ID, "{}").0, status::OK, "still the controller's");
        c.release();
        let log = sim.take_log().join("\n");
        assert!(log.contains("fault injected: ModeHeld { releases: 2 }"), "{log}");
        assert_eq!(log.matches("does not let go").count(), 2, "{log}");

        // A ReleaseMode written again (its answer lost: the same id) is answered again, acted
        // on once.
        assert_eq!(c.call(switcher, motion_switcher::SELECT_MODE, r#"{"name":"ai"}"#).0, status::OK);
        sim.inject(G1Fault::ModeHeld { releases: 1 });
        let requests = sim.snapshot().stream.requests;
        assert_eq!(c.call(switcher, motion_switcher::RELEASE_MODE, "{}").0, status::OK);
        assert_eq!(c.call_as(c.next_id, switcher, motion_switcher::RELEASE_MODE, "{}").0, status::OK);
        assert_eq!(sim.snapshot().stream.requests, requests + 1);
        assert_eq!(mode(&mut c), "ai");
        c.release();
        // A client that does not number its calls (id 0, as Unitree's ROS 2 examples): each one
        // is acted on.
        let requests = sim.snapshot().stream.requests;
        for _ in 0..2 {
            assert_eq!(c.call_as(0, switcher, motion_switcher::CHECK_MODE, "{}").0, status::OK);
        }
        assert!(sim.snapshot().stream.requests >= requests + 2);

        // Never: until the fault is cleared.
        assert_eq!(c.call(switcher, motion_switcher::SELECT_MODE, r#"{"name":"ai"}"#).0, status::OK);
        sim.inject(G1Fault::ModeHeld { releases: u32::MAX });
        for _ in 0..12 {
            assert_eq!(c.call(switcher, motion_switcher::RELEASE_MODE, "{}").0, status::OK);
        }
        assert_eq!(mode(&mut c), "ai");
        sim.clear_faults();
        c.release();
        assert_eq!(sim.snapshot().mode, "");
    });
}

#[test]
fn arm_actions_wait_for_a_held_pose_and_for_rt_arm_sdk() {
    with_loopback_multicast(|| {
        // Lock-step: the arm_sdk weight stays where it is while the services are called.
        let config = G1SimConfig {
            participant: ParticipantOptions::new(0, Some("lo")),
            clock: SimClock::LockStep,
            ..G1SimConfig::new(G1Variant::Dof29)
        };
        let sim = G1Sim::spawn(config).expect("simulator");
        let mut c = Client::new();
        let (arm, execute) = (g1_arm::SERVICE, g1_arm::EXECUTE_ACTION);
        let action = |c: &mut Client, id: i64| c.call(arm, execute, &format!(r#"{{"data":{id}}}"#)).0;
        assert!(HOLDING_ACTIONS.contains(&19) && !HOLDING_ACTIONS.contains(&17));

        // A hug holds its pose: only the release (99) or the hug again until then.
        assert_eq!(action(&mut c, 19), status::OK);
        assert_eq!(action(&mut c, 17), g1_arm::error::HOLDING);
        assert_eq!(action(&mut c, 5), g1_arm::error::INVALID_ACTION_ID);
        assert_eq!(action(&mut c, 19), status::OK);
        assert_eq!(action(&mut c, 17), g1_arm::error::HOLDING);
        assert_eq!(action(&mut c, g1_arm::RELEASE_ARM), status::OK);
        assert_eq!(action(&mut c, 17), status::OK);
        assert_eq!(action(&mut c, 26), status::OK, "a clap and a wave hold nothing");
        // A held pose is let go with the motors.
        assert_eq!(action(&mut c, 27), status::OK);
        c.release();
        assert_eq!(c.call(motion_switcher::SERVICE, motion_switcher::SELECT_MODE, r#"{"name":"ai"}"#).0, status::OK);
        assert_eq!(action(&mut c, 17), status::OK);

        // rt/arm_sdk blended in (its weight above 0): no action runs.
        let with_weight = |weight: f32| {
            let mut frame = HgLowCmd::default();
            frame.motor_cmd[slot::ARM_SDK_WEIGHT].q = weight.into();
            frame
        };
        let weighted = |c: &Client, weight: f32, done: fn(f32) -> bool| {
            let start = Instant::now();
            while !done(sim.snapshot().arm_sdk.weight) {
                c.arm_sdk.write(with_weight(weight)).unwrap();
                sim.advance(std::time::Duration::from_millis(2)).unwrap();
                assert!(start.elapsed() < WAIT, "rt/arm_sdk at {weight} not taken: {:?}", sim.snapshot().arm_sdk);
            }
        };
        weighted(&c, 0.2, |w| w == 0.2);
        assert_eq!(action(&mut c, 17), g1_arm::error::ARM_SDK_OCCUPIED);
        assert_eq!(action(&mut c, 5), g1_arm::error::ARM_SDK_OCCUPIED);
        // At weight 0 the controller has the arms again.
        weighted(&c, 0.0, |w| w == 0.0);
        assert_eq!(action(&mut c, 17), status::OK);
        assert!(sim.snapshot().arm_sdk.accepted > 0);
    });
}
