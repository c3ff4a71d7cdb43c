//! The same client for an HG robot (G1, H1-2): its LowCmd type on `rt/lowcmd`, its checks, and
//! damping that keeps `mode_machine`, seen by a plain reader in another participant, where
//! loopback carries multicast (`robowire_dds::netns`). Nothing answers here (the G1 simulator
//! is `g1_dds.rs`'s), which is also the watchdog's case.

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use robowire_fixtures::wait::one_at_a_time;
use unitree::{Connection, Device, Hg, HgLowCmd, LowLevel, LowLevelOptions, UnitreeError};
use unitree_proto::Message;

const WAIT: Duration = Duration::from_secs(20);

#[test]
fn hg_commands_and_damping_keep_the_machine_mode() {
    // Alone, as when it was a binary of its own: its HG LowCmds on `rt/lowcmd` must not meet the
    // G1 simulator of `g1_dds` and `g1_follow` where `lo` already carries multicast.
    let _turn = one_at_a_time();
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let lo = ParticipantOptions::new(0, Some("lo"));
            let robot_end = Participant::new(lo.clone()).unwrap();
            let mut commands = robot_end.reader::<HgLowCmd>(HgLowCmd::TOPIC, Qos::READER).unwrap();
            let options = LowLevelOptions { participant: lo, ..LowLevelOptions::default() };
            let robot = LowLevel::<Hg>::open(options).unwrap();

            let mut cmd = HgLowCmd::default();
            cmd.mode_machine = 5;
            cmd.motor_cmd[0].mode = 1;
            cmd.motor_cmd[0].q = 0.3.into();
            cmd.motor_cmd[0].kp = 40.0.into();
            let mut nan = cmd;
            nan.motor_cmd[3].kd = f32::NAN.into();
            assert!(matches!(robot.set_command(nan), Err(UnitreeError::Command(_))));
            // Refresh the command until the robot's end sees it (discovery takes a moment), then
            // stop: once it is stale, damping with the machine mode kept.
            let seen = tokio::time::timeout(WAIT, async {
                loop {
                    robot.set_command(cmd).unwrap();
                    if let Ok(Ok(s)) = tokio::time::timeout(Duration::from_millis(10), commands.recv()).await
                        && s.value.motor_cmd[0].kp.get() == 40.0
                    {
                        return;
                    }
                }
            })
            .await;
            assert!(seen.is_ok(), "the HG command on rt/lowcmd");
            let damping = tokio::time::timeout(WAIT, async {
                loop {
                    let c = commands.recv().await.unwrap().value;
                    if c.motor_cmd[0].kp.get() == 0.0 {
                        return c;
                    }
                }
            })
            .await
            .expect("damping after the command went stale");
            assert_eq!(damping.mode_machine, 5);
            // The motors the command enabled (motor 0) damped; the others left disabled.
            let (enabled, rest) = damping.motor_cmd.split_at(1);
            assert!(enabled.iter().all(|m| m.kp.get() == 0.0 && m.kd.get() == 1.0 && m.mode == 1), "{enabled:?}");
            assert!(rest.iter().all(|m| *m == Default::default()), "{rest:?}");
            assert_eq!(robot.connection(), Connection::Waiting, "no HG robot answers");
        })
    });
}
