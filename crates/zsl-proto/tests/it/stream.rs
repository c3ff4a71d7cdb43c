//! The client's command stream on a fake clock: immediate sends, the 2 ms refresh, the
//! per-datagram rules, the watchdog and reconnect, the halt, the missed-tick policy. Deterministic, no sockets.

use core::time::Duration;

use robowire_core::schedule::Time;
use zsl_proto::stream::{
    COMMAND_PERIOD, Cause, CommandStream, Connection, Event, Halted, HighLevelInterface, Interface, LowLevelInterface,
    WATCHDOG_TIMEOUT, Watchdog,
};
use zsl_proto::udp::{
    Action, ControlMode, HIGH_LEVEL_STATE_HEADER, HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState,
    MotorCommand,
};

const MS: Duration = Duration::from_millis(1);
const T0: Time = Time::from_nanos(42_000_000_000);

type High = CommandStream<HighLevelInterface>;

/// Every datagram a perfect runner sends until `end` (waking exactly at each deadline).
fn run<I: Interface>(stream: &mut CommandStream<I>, from: Time, end: Time) -> Vec<(Time, I::Command, Cause)> {
    let mut sent = Vec::new();
    let mut now = from;
    while let Some(deadline) = stream.poll_timeout() {
        now = now.max(deadline);
        if now >= end {
            break;
        }
        while let Some(t) = stream.poll_transmit(now) {
            sent.push((now, t.command, t.cause));
        }
    }
    sent
}

fn state(mode: u32) -> HighLevelState {
    HighLevelState { header: HIGH_LEVEL_STATE_HEADER, control_mode: mode.into(), ..HighLevelState::default() }
}

#[test]
fn the_idle_command_at_once_then_every_two_milliseconds() {
    let mut stream = High::new(T0, COMMAND_PERIOD);
    let sent = run(&mut stream, T0, T0 + Duration::from_secs(1));
    assert_eq!(sent[0], (T0, HighLevelCommand::default(), Cause::Call), "the idle command at once");
    let refreshes: Vec<Time> = sent.iter().filter(|s| matches!(s.2, Cause::Refresh(_))).map(|s| s.0).collect();
    assert_eq!(refreshes.len(), 499, "2, 4, … 998 ms");
    assert!(refreshes.windows(2).all(|w| w[1].saturating_duration_since(w[0]) == 2 * MS));
    assert_eq!(stream.counters().refreshes, 499);
}

#[test]
fn a_call_goes_out_at_once_and_the_grid_does_not_move() {
    let mut stream = High::new(T0, COMMAND_PERIOD);
    run(&mut stream, T0, T0 + 3 * MS); // idle, refresh at 2 ms
    stream.handle_call(HighLevelCommand::stand_up()).unwrap();
    assert_eq!(stream.poll_timeout(), Some(Time::ZERO), "due at once");
    let now = T0 + Duration::from_micros(3_100);
    let sent = stream.poll_transmit(now).unwrap();
    assert_eq!((sent.command, sent.cause), (HighLevelCommand::stand_up(), Cause::Call));
    assert_eq!(stream.poll_transmit(now), None, "once");
    assert_eq!(stream.poll_timeout(), Some(T0 + 4 * MS), "the refresh stays on its grid");
    let refresh = stream.poll_transmit(T0 + 4 * MS).unwrap();
    assert_eq!(refresh.command, HighLevelCommand::stand_up(), "the latched command is refreshed");
}

#[test]
fn a_trick_goes_out_in_exactly_six_datagrams() {
    let mut stream = High::new(T0, COMMAND_PERIOD);
    run(&mut stream, T0, T0 + MS);
    stream.handle_call(HighLevelCommand::jump()).unwrap();
    let sent = run(&mut stream, T0 + MS, T0 + 30 * MS);
    let actions: Vec<Action> = sent.iter().map(|s| s.1.action_code()).collect();
    assert_eq!(actions.iter().take_while(|a| **a == Action::Jump).count(), 6, "{actions:?}");
    assert!(actions[6..].iter().all(|a| *a == Action::None));
    assert!(sent.iter().all(|s| s.1.control_mode() == ControlMode::Action), "the mode stays");
}

/// A client as the facade runs one: the watchdog's disconnect is handed to the stream.
#[test]
fn the_watchdog_disconnects_the_stream_stops_the_motion_and_state_reconnects() {
    let mut stream = High::new(T0, COMMAND_PERIOD);
    let mut watchdog = Watchdog::new(T0, WATCHDOG_TIMEOUT);
    assert_eq!(watchdog.connection(), Connection::Waiting);
    assert_eq!(watchdog.feed(T0 + 5 * MS), Some(Event::Connected));
    stream.handle_state(&state(1));
    stream.handle_call(HighLevelCommand::move_velocity(0.5, 0.0, 0.3)).unwrap();
    run(&mut stream, T0, T0 + 100 * MS);
    let last_state = T0 + 100 * MS;
    assert_eq!(watchdog.feed(last_state), None);
    assert_eq!(watchdog.poll_timeout(), Some(last_state + Duration::from_secs(3)));
    assert_eq!(watchdog.poll_event(last_state + Duration::from_secs(3) - MS), None, "not yet");
    assert_eq!(watchdog.poll_event(last_state + Duration::from_secs(3)), Some(Event::Disconnected));
    assert_eq!(watchdog.poll_event(last_state + Duration::from_secs(4)), None, "once per silence");
    assert_eq!(watchdog.poll_timeout(), None);
    assert_eq!(watchdog.connection(), Connection::Disconnected);
    stream.handle_disconnect();
    let latched = *stream.latched();
    assert_eq!(latched.control_mode(), ControlMode::Move, "the mode stays");
    assert_eq!((latched.vx.get(), latched.yaw_rate.get()), (0.0, 0.0), "the motion became a stop");
    // The stop keeps streaming while disconnected.
    let after = run(&mut stream, last_state + Duration::from_secs(3), last_state + Duration::from_secs(3) + 10 * MS);
    assert!(after.iter().all(|s| s.1.vx.get() == 0.0) && !after.is_empty());
    // State returns: reconnected, and the stale motion never resumes.
    assert_eq!(watchdog.feed(last_state + Duration::from_secs(5)), Some(Event::Reconnected));
    stream.handle_state(&state(18));
    assert_eq!(stream.latched().vx.get(), 0.0);
    let c = watchdog.counters();
    assert_eq!((c.disconnects, c.reconnects), (1, 1));
}

#[test]
fn the_first_timeout_is_a_watchdog_period_after_start_and_an_empty_datagram_feeds_it() {
    let mut silent = Watchdog::new(T0, 300 * MS);
    assert_eq!(silent.poll_timeout(), Some(T0 + 300 * MS));
    assert_eq!(silent.poll_event(T0 + 300 * MS), Some(Event::Disconnected), "nothing ever arrived");
    let mut fed = Watchdog::new(T0, 300 * MS);
    assert_eq!(fed.feed(T0 + 200 * MS), Some(Event::Connected));
    assert_eq!(fed.poll_event(T0 + 300 * MS), None, "a datagram re-armed it");
    assert_eq!(fed.poll_event(T0 + 500 * MS), Some(Event::Disconnected));
}

#[test]
fn an_error_word_forces_passive_and_sdk_mismatch_halts_for_good() {
    let mut stream = High::new(T0, COMMAND_PERIOD);
    stream.handle_call(HighLevelCommand::move_velocity(0.5, 0.0, 0.0)).unwrap();
    let mut faulted = state(18);
    faulted.error_word = 0x3012.into();
    stream.handle_state(&faulted);
    let sent = stream.poll_transmit(T0).unwrap();
    assert_eq!(sent.command.control_mode(), ControlMode::Passive, "error word: mode 0");

    let mut mismatch = state(1);
    mismatch.sdk_mismatch = 1.into();
    stream.handle_state(&mismatch);
    assert_eq!(stream.poll_transmit(T0 + 2 * MS), None, "halted");
    assert!(stream.is_halted());
    assert_eq!(stream.poll_timeout(), None);
    assert_eq!(stream.handle_call(HighLevelCommand::stand_up()), Err(Halted));
    assert_eq!(stream.poll_transmit(T0 + Duration::from_secs(1)), None, "for good");
}

#[test]
fn late_refreshes_are_counted_not_caught_up() {
    let mut stream = High::new(T0, COMMAND_PERIOD);
    run(&mut stream, T0, T0 + MS);
    let late = T0 + 11 * MS; // due at 2 ms
    let sent = stream.poll_transmit(late).unwrap();
    assert!(matches!(sent.cause, Cause::Refresh(tick) if tick.skipped == 4 && tick.lateness == 9 * MS));
    assert_eq!(stream.poll_transmit(late), None, "one datagram");
    assert_eq!(stream.counters().missed_ticks, 4);
}

#[test]
fn low_level_watchdog_zeroes_velocity_targets_and_keeps_the_hold() {
    let mut stream = CommandStream::<LowLevelInterface>::new(T0, COMMAND_PERIOD);
    let mut motor = MotorCommand::pd_hold([[0.0; 4], [0.8; 4], [-1.5; 4]], [80.0; 3], [1.0; 3]);
    motor.qd_des[1] = [0.5.into(); 4];
    motor.tau_ff[2] = [2.0.into(); 4];
    stream.handle_call(LowLevelCommand::new(motor)).unwrap();
    stream.handle_state(&LowLevelState::default());
    stream.handle_disconnect();
    let held = stream.latched().motor;
    assert!(held.qd_des.iter().flatten().all(|v| v.get() == 0.0), "velocity targets zeroed");
    assert_eq!((held.q_des, held.kp, held.tau_ff), (motor.q_des, motor.kp, motor.tau_ff), "the hold stays");
}
