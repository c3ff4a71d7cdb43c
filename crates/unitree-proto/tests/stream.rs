//! The Go2 and G1 low-level command streams on a fake clock: the rate, the command timeout to damping,
//! refused commands, damping on demand, the missed-tick policy.

use core::time::Duration;

use robowire_core::schedule::Time;
use unitree_proto::go2::MotorCmd;
use unitree_proto::robot::{CommandError, Go2, MotorField, Robot};
use unitree_proto::stream::{CommandStream, StreamConfig, Transmit};
use unitree_proto::{F32, LowCmd};

const MS: Duration = Duration::from_millis(1);
const T0: Time = Time::from_nanos(3_000_000_000);

fn stand() -> LowCmd {
    let mut cmd = LowCmd::default();
    for (i, m) in cmd.motor_cmd.iter_mut().take(12).enumerate() {
        *m = MotorCmd::servo([0.0, 0.67, -1.3][i % 3], 0.0, 60.0, 5.0, 0.0);
    }
    cmd
}

/// Every command a perfect runner sends from `from` until `end`.
fn run<R: Robot>(stream: &mut CommandStream<R>, from: Time, end: Time) -> Vec<(Time, Transmit<R::Cmd>)> {
    let mut sent = Vec::new();
    let mut now = from;
    while let Some(deadline) = stream.poll_timeout() {
        now = now.max(deadline);
        if now >= end {
            break;
        }
        sent.extend(stream.poll_transmit(now).map(|t| (now, t)));
    }
    sent
}

fn kp(t: &Transmit<LowCmd>) -> f32 {
    t.command.motor_cmd[0].kp.get()
}

#[test]
fn five_hundred_hertz_from_the_first_command_then_damping_after_the_timeout() {
    let mut stream = CommandStream::<Go2>::new(T0, StreamConfig::default());
    assert!(run(&mut stream, T0, T0 + Duration::from_secs(1)).is_empty(), "silent before a command");
    let start = T0 + 5 * MS;
    stream.handle_command(start, stand()).unwrap();
    let sent = run(&mut stream, start, start + Duration::from_secs(1));
    assert_eq!(sent.len(), 500);
    assert!(sent.windows(2).all(|w| w[1].0.saturating_duration_since(w[0].0) == 2 * MS));
    // Fresh up to 100 ms after it was set (51 ticks: 0, 2, … 100 ms), damping after.
    let fresh = sent.iter().take_while(|(_, t)| t.fresh).count();
    assert_eq!(fresh, 51);
    assert!(sent[..fresh].iter().all(|(_, t)| kp(t) == 60.0));
    assert!(sent[fresh..].iter().all(|(_, t)| !t.fresh && kp(t) == 0.0 && t.command.motor_cmd[0].kd.get() == 1.0));
    let c = stream.counters();
    assert_eq!((c.sent, c.damping, c.command_timeouts), (500, 449, 1));
}

#[test]
fn a_refused_command_changes_nothing() {
    let mut stream = CommandStream::<Go2>::new(T0, StreamConfig::default());
    stream.handle_command(T0, stand()).unwrap();
    let mut bad = stand();
    bad.motor_cmd[5].q = F32::new(f32::INFINITY);
    assert!(matches!(
        stream.handle_command(T0 + MS, bad),
        Err(CommandError::NonFinite { motor: 5, field: MotorField::Q, .. })
    ));
    assert_eq!(stream.latched().map(|(at, c)| (*at, c.motor_cmd[5].q.get())), Some((T0, -1.3)));
    assert_eq!(stream.counters().refused, 1);
}

#[test]
fn damp_at_once_until_the_next_command() {
    let mut stream = CommandStream::<Go2>::new(T0, StreamConfig::default());
    stream.handle_command(T0, stand()).unwrap();
    run(&mut stream, T0, T0 + 10 * MS);
    stream.damp(T0 + 10 * MS);
    let damped = run(&mut stream, T0 + 10 * MS, T0 + 20 * MS);
    assert!(!damped.is_empty() && damped.iter().all(|(_, t)| !t.fresh && kp(t) == 0.0));
    assert_eq!(stream.counters().command_timeouts, 0, "a requested damping is no timeout");
    stream.handle_command(T0 + 20 * MS, stand()).unwrap();
    assert!(run(&mut stream, T0 + 20 * MS, T0 + 30 * MS).iter().all(|(_, t)| t.fresh));
    // Damping before any command: the grid starts there.
    let mut cold = CommandStream::<Go2>::new(T0, StreamConfig::default());
    cold.damp(T0);
    assert_eq!(cold.poll_transmit(T0).map(|t| t.fresh), Some(false));
}

#[test]
fn a_late_tick_is_sent_once_and_counted() {
    let mut stream = CommandStream::<Go2>::new(T0, StreamConfig::default());
    stream.handle_command(T0, stand()).unwrap();
    run(&mut stream, T0, T0 + MS); // the tick at 0
    let late = stream.poll_transmit(T0 + 11 * MS).unwrap(); // due at 2 ms
    assert_eq!((late.tick.skipped, late.tick.lateness), (4, 9 * MS));
    assert!(stream.poll_transmit(T0 + 11 * MS).is_none(), "no catch-up burst");
    assert_eq!(stream.counters().missed_ticks, 4);
    assert_eq!(stream.poll_timeout(), Some(T0 + 12 * MS));
}

#[test]
fn the_g1_stream_damps_a_stale_command_keeping_the_robots_mode_machine() {
    use unitree_proto::g1::{self, G1Variant};
    use unitree_proto::robot::Hg;

    let variant = G1Variant::Dof23;
    let zero = g1::hold(&[0.0; g1::JOINTS], 4, variant);
    assert_eq!(g1::check_low_cmd(&zero, Some(4), variant), Ok(()));
    let mut stream = CommandStream::<Hg>::new(T0, StreamConfig::default());
    stream.handle_command(T0, zero).unwrap();
    let sent = run(&mut stream, T0, T0 + 200 * MS);
    assert_eq!(sent.len(), 100, "500 Hz for 200 ms");
    let (fresh, damping): (Vec<_>, Vec<_>) = sent.iter().partition(|(_, t)| t.fresh);
    assert_eq!(fresh.len(), 51, "fresh for the 100 ms command timeout (both ends)");
    for (_, t) in &damping {
        let c = &t.command;
        assert_eq!(c.mode_machine, 4, "the robot ignores a LowCmd without its mode_machine");
        // The damping enables what the command enabled (the 23 joints), with kp 0 and kd.
        assert_eq!(g1::check_low_cmd(c, Some(4), variant), Ok(()));
        assert!(
            c.motor_cmd
                .iter()
                .enumerate()
                .all(|(slot, m)| (m.mode == 1) == variant.drives(slot) && m.kp.get() == 0.0 && m.q.get() == 0.0)
        );
        assert_eq!(c.motor_cmd[3].kd.get(), unitree_proto::robot::DAMPING_KD);
    }
    assert_eq!(stream.counters().command_timeouts, 1);
}
