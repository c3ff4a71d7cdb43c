//! `G1::follow` against the simulated G1 over real DDS, where loopback carries multicast
//! (`robowire_dds::netns`): a motion the G1's rules refuse before anything is sent, one whose
//! middle they refuse on the stream (ended in damping, with the robot's `mode_machine`), and one
//! to the zero posture the robot reaches. Conditions are awaited with a generous timeout;
//! nothing here measures time.

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_fixtures::wait::{one_at_a_time, until_async};
use robowire_sim::g1::{G1Sim, G1SimConfig};
use unitree::UnitreeError;
use unitree::g1::{
    CommandError, Device, G1, G1Error, G1Options, JOINT_LIMITS, JOINTS, MotionState, ParticipantOptions, from_fn, hold,
    slot,
};

/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);

#[test]
fn a_g1_motion_is_checked_before_and_while_it_is_followed() {
    let _turn = one_at_a_time();
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let lo = ParticipantOptions::new(0, Some("lo"));
            let sim = G1Sim::spawn(G1SimConfig { participant: lo.clone(), ..G1SimConfig::default() }).unwrap();
            let mut options = G1Options::default();
            options.low_level.participant = lo;
            let robot = G1::open(options).unwrap();
            let first = robot.wait_state(WAIT, |_| true).await.expect("rt/lowstate");
            let (mode_machine, variant) = (first.mode_machine, robot.variant().unwrap());
            robot.release().await.unwrap();

            // Another robot's mode_machine: refused here, nothing sent.
            let elsewhere = from_fn(Duration::from_secs(1), move |_| hold(&[0.0; JOINTS], mode_machine + 1, variant));
            let refused = robot.follow(elsewhere);
            assert!(matches!(refused, Err(G1Error::Command(CommandError::ModeMachine { .. }))), "{refused:?}");
            assert_eq!(robot.stats().low_level.commands_sent, 0);

            // A knee past its range in the middle (the ends are fine): refused on the stream, damping.
            let knee_max = JOINT_LIMITS[slot::LEFT_KNEE].q_max;
            let reckless = from_fn(Duration::from_millis(200), move |elapsed| {
                let mut q = [0.0; JOINTS];
                if (50..150).contains(&elapsed.as_millis()) {
                    q[slot::LEFT_KNEE] = knee_max + 0.5;
                }
                hold(&q, mode_machine, variant)
            });
            let end = tokio::time::timeout(WAIT, robot.follow(reckless).unwrap().wait()).await.unwrap();
            assert!(
                matches!(
                    end,
                    Err(UnitreeError::MotionEnded(MotionState::Refused(CommandError::OutOfRange {
                        motor: slot::LEFT_KNEE,
                        ..
                    })))
                ),
                "{end:?}"
            );
            until_async(WAIT, "damping", || robot.stats().low_level.damping_sent > 0).await;

            // To the zero posture, stepped by the stream; reached and held.
            let from = robot.joint_positions().unwrap();
            let to_zero = from_fn(Duration::from_millis(500), move |elapsed| {
                let left = 1.0 - (elapsed.as_secs_f32() / 0.5).min(1.0);
                hold(&from.map(|q| q * left), mode_machine, variant)
            });
            let following = robot.follow(to_zero).unwrap();
            tokio::time::timeout(WAIT, following.wait()).await.unwrap().unwrap();
            until_async(WAIT, "the zero posture", || sim.snapshot().joints_rad.iter().all(|q| q.abs() < 0.02)).await;
            let lowcmd = sim.snapshot().lowcmd;
            assert_eq!((lowcmd.bad_mode_machine, lowcmd.disabled_motors, lowcmd.bad_crc), (0, 0, 0), "{lowcmd:?}");
            assert!(robot.stats().low_level.commands_sent > 0);
            robot.close();
        })
    });
}
