//! The Go2 and G1 low-level command streams on a fake clock: the rate, the command timeout to damping,
//! refused commands, damping on demand, the missed-tick policy; motions stepped on the stream's
//! grid, replaced, damped, refused.

use core::time::Duration;

use robowire_core::schedule::Time;
use unitree_proto::go2::MotorCmd;
use unitree_proto::robot::{CommandError, Go2, MotorField, Robot};
use unitree_proto::stream::{CommandStream, Motion, MotionState, StreamConfig, Transmit, from_fn};
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
fn run<R: Robot, M: Motion<R::Cmd>>(
    stream: &mut CommandStream<R, M>,
    from: Time,
    end: Time,
) -> Vec<(Time, Transmit<R::Cmd>)> {
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

/// A thigh moving from 0.67 rad by 1 mrad per ms of the motion (its other joints at the stand
/// pose), for `duration`.
fn thigh_ramp(duration: Duration) -> impl Motion<LowCmd> + Clone {
    from_fn(duration, |elapsed: Duration| {
        let mut cmd = stand();
        cmd.motor_cmd[1].q = F32::new(0.67 + elapsed.as_micros() as f32 * 1e-6);
        cmd
    })
}

/// The thigh's target of a command, as the ms of the ramp it stands for.
fn ramp_ms(t: &Transmit<LowCmd>) -> i64 {
    ((t.command.motor_cmd[1].q.get() - 0.67) * 1000.0).round() as i64
}

#[test]
fn a_motion_is_stepped_on_the_streams_own_grid_then_held() {
    let mut stream = CommandStream::<Go2, _>::new(T0, StreamConfig::default());
    stream.handle_command(T0, stand()).unwrap();
    run(&mut stream, T0, T0 + 7 * MS); // ticks at 0, 2, 4, 6 ms
    // Handed over between two ticks: its first step is the next tick's, at elapsed 0.
    assert_eq!(stream.follow(T0 + 7 * MS, thigh_ramp(Duration::from_millis(9))).map(|(_, s)| s), None);
    assert_eq!(stream.motion().map(|(_, s)| s), Some(MotionState::Pending));
    let sent = run(&mut stream, T0 + 7 * MS, T0 + 1000 * MS);
    assert_eq!(sent.len(), 496, "500 Hz, the grid unchanged");
    assert_eq!(sent[0].0, T0 + 8 * MS);
    assert_eq!(stream.motion_began(), Some(T0 + 8 * MS));
    // One step per tick at 0, 2, 4, 6, 8 ms of the motion, then its end (9 ms), held.
    let steps: Vec<i64> = sent.iter().map(|(_, t)| ramp_ms(t)).collect();
    assert_eq!(steps[..6], [0, 2, 4, 6, 8, 9]);
    assert!(steps[6..].iter().all(|&ms| ms == 9), "held");
    // Never stale: the stream's own command, long after the command timeout.
    assert!(sent.iter().all(|(_, t)| t.fresh && kp(t) == 60.0));
    assert_eq!(stream.motion().map(|(_, s)| s), Some(MotionState::Reached));
    let c = stream.counters();
    assert_eq!((c.damping, c.command_timeouts, c.refused), (0, 0, 0));
}

#[test]
fn where_a_motion_is_while_it_moves() {
    let mut stream = CommandStream::<Go2, _>::new(T0, StreamConfig::default());
    // A motion before any command starts the grid where it was handed over.
    stream.follow(T0, thigh_ramp(Duration::from_millis(5)));
    assert_eq!(stream.poll_timeout(), Some(T0));
    let mut states = Vec::new();
    for ms in [0, 2, 4, 6] {
        let t = stream.poll_transmit(T0 + ms * MS).unwrap();
        states.push((ramp_ms(&t), stream.motion().unwrap().1));
    }
    let moving = |ms| MotionState::Moving { elapsed: ms * MS };
    assert_eq!(
        states,
        [(0, moving(0)), (2, moving(2)), (4, moving(4)), (5, MotionState::Reached)],
        "the end (5 ms) is the step of the first slot at or after it"
    );
}

#[test]
fn a_late_tick_steps_the_motion_at_the_latest_slot() {
    let mut stream = CommandStream::<Go2, _>::new(T0, StreamConfig::default());
    stream.follow(T0, thigh_ramp(Duration::from_secs(1)));
    run(&mut stream, T0, T0 + MS); // 0 ms
    let late = stream.poll_transmit(T0 + 11 * MS).unwrap(); // due at 2 ms; slots 4..10 passed
    assert_eq!(late.tick.skipped, 4);
    assert_eq!(ramp_ms(&late), 10, "the slot it is sent in, still on the grid");
    assert_eq!(ramp_ms(&stream.poll_transmit(T0 + 12 * MS).unwrap()), 12);
}

#[test]
fn a_command_or_a_motion_replaces_a_motion_and_damping_ends_it() {
    let mut stream = CommandStream::<Go2, _>::new(T0, StreamConfig::default());
    stream.follow(T0, thigh_ramp(Duration::from_secs(1)));
    run(&mut stream, T0, T0 + 10 * MS);
    // A newer motion: the previous one comes back, replaced; the new one starts at 0.
    let (_, was) = stream.follow(T0 + 10 * MS, thigh_ramp(Duration::from_secs(1))).unwrap();
    assert_eq!(was, MotionState::Replaced);
    let sent = run(&mut stream, T0 + 10 * MS, T0 + 14 * MS);
    assert_eq!(sent.iter().map(|(_, t)| ramp_ms(t)).collect::<Vec<_>>(), [0, 2]);
    // A command: latched from the next tick, stale 100 ms after it was set, as any command.
    stream.handle_command(T0 + 14 * MS, stand()).unwrap();
    assert_eq!(stream.motion().map(|(_, s)| s), Some(MotionState::Replaced));
    let sent = run(&mut stream, T0 + 14 * MS, T0 + 300 * MS);
    assert!(sent.iter().all(|(_, t)| ramp_ms(t) == 0 || !t.fresh));
    assert_eq!(sent.iter().filter(|(_, t)| t.fresh).count(), 51);
    assert_eq!(stream.counters().command_timeouts, 1);
    // Damping ends a motion, at once; the next motion starts again.
    stream.follow(T0 + 300 * MS, thigh_ramp(Duration::from_secs(1)));
    run(&mut stream, T0 + 300 * MS, T0 + 306 * MS);
    stream.damp(T0 + 306 * MS);
    assert_eq!(stream.motion().map(|(_, s)| s), Some(MotionState::Damped));
    let damped = run(&mut stream, T0 + 306 * MS, T0 + 400 * MS);
    assert!(damped.iter().all(|(_, t)| !t.fresh && kp(t) == 0.0));
    let (_, was) = stream.follow(T0 + 400 * MS, thigh_ramp(Duration::from_secs(1))).unwrap();
    assert_eq!(was, MotionState::Damped, "what became of it, kept");
    assert!(run(&mut stream, T0 + 400 * MS, T0 + 410 * MS).iter().all(|(_, t)| t.fresh));
}

#[test]
fn a_step_the_rules_refuse_ends_the_motion_in_damping() {
    let mut stream = CommandStream::<Go2, _>::new(T0, StreamConfig::default());
    // From 6 ms on the calf's target leaves its range.
    let reckless = from_fn(Duration::from_millis(50), |elapsed: Duration| {
        let mut cmd = stand();
        if elapsed >= 6 * MS {
            cmd.motor_cmd[2].q = F32::new(0.0);
        }
        cmd
    });
    stream.follow(T0, reckless);
    let sent = run(&mut stream, T0, T0 + 20 * MS);
    let fresh: Vec<bool> = sent.iter().map(|(_, t)| t.fresh).collect();
    assert_eq!(fresh, [true, true, true, false, false, false, false, false, false, false]);
    assert!(sent[3..].iter().all(|(_, t)| kp(t) == 0.0), "damping, never the refused step");
    assert!(matches!(
        stream.motion().map(|(_, s)| s),
        Some(MotionState::Refused(CommandError::OutOfRange { motor: 2, field: MotorField::Q, .. }))
    ));
    let c = stream.counters();
    assert_eq!((c.refused, c.command_timeouts), (1, 0));
}

#[test]
fn a_g1_motion_refused_damps_with_the_robots_mode_machine() {
    use unitree_proto::g1::{self, G1Variant};
    use unitree_proto::robot::Hg;

    let variant = G1Variant::Dof29;
    let mut stream = CommandStream::<Hg, _>::new(T0, StreamConfig::default());
    // The knee bends by 1 mrad per ms, and a NaN at 4 ms.
    stream.follow(
        T0,
        from_fn(Duration::from_secs(1), move |elapsed: Duration| {
            let mut q = [0.0; g1::JOINTS];
            q[g1::slot::LEFT_KNEE] = if elapsed == 4 * MS { f32::NAN } else { elapsed.as_micros() as f32 * 1e-6 };
            g1::hold(&q, 5, variant)
        }),
    );
    let sent = run(&mut stream, T0, T0 + 10 * MS);
    let knee: Vec<f32> = sent.iter().map(|(_, t)| t.command.motor_cmd[g1::slot::LEFT_KNEE].q.get()).collect();
    assert_eq!(knee[..2], [0.0, 0.002]);
    assert!(sent[2..].iter().all(|(_, t)| !t.fresh && t.command.mode_machine == 5));
    assert_eq!(g1::check_low_cmd(&sent[2].1.command, Some(5), variant), Ok(()));
}
