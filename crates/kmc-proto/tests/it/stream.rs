//! The command stream on a fake clock: rates, the command timeout, the stop burst, the
//! missed-tick policy, one-shot requests. Deterministic, microseconds of CPU.

use core::time::Duration;

use kmc_proto::stream::{CommandStream, Due, MAX_PENDING_REQUESTS, StreamConfig, Transmit};
use kmc_proto::{AfFrame, HostFrame, PcControl};
use robowire_core::schedule::Time;

const MS: Duration = Duration::from_millis(1);
const T0: Time = Time::from_nanos(7_000_000_000);

/// Runs the stream as a perfect runner would (waking exactly at each deadline) until `end`;
/// every frame with the time it went out.
fn run_until(stream: &mut CommandStream, end: Time) -> Vec<(Time, Transmit)> {
    let mut sent = Vec::new();
    let mut now = T0;
    while let Some(deadline) = stream.poll_timeout() {
        now = now.max(deadline);
        if now >= end {
            break;
        }
        while let Some(transmit) = stream.poll_transmit(now) {
            sent.push((now, transmit));
        }
    }
    sent
}

fn count(sent: &[(Time, Transmit)], due: impl Fn(&Due) -> bool) -> usize {
    sent.iter().filter(|(_, t)| due(&t.due)).count()
}

#[test]
fn the_vendors_rates_over_one_second() {
    let config = StreamConfig {
        battery_period: Some(kmc_proto::stream::BATTERY_POLL_PERIOD),
        all_state_period: Some(kmc_proto::stream::ALL_STATE_POLL_PERIOD),
        ..StreamConfig::default()
    };
    let mut stream = CommandStream::new(T0, config);
    let sent = run_until(&mut stream, T0 + Duration::from_secs(1));
    assert_eq!(count(&sent, |d| matches!(d, Due::Control { .. })), 100, "100 Hz");
    assert_eq!(count(&sent, |d| *d == Due::SpeedPoll), 50, "50 Hz");
    assert_eq!(count(&sent, |d| *d == Due::BatteryPoll), 1, "1 Hz");
    assert_eq!(count(&sent, |d| *d == Due::AllStatePoll { motor: 0 }), 10, "10 Hz, motor 0");
    assert_eq!(count(&sent, |d| *d == Due::AllStatePoll { motor: 1 }), 10, "10 Hz, motor 1");
    // Control frames exactly every 10 ms on the grid.
    let controls: Vec<Time> =
        sent.iter().filter(|(_, t)| matches!(t.due, Due::Control { .. })).map(|(at, _)| *at).collect();
    assert!(controls.windows(2).all(|w| w[1].saturating_duration_since(w[0]) == 10 * MS));
    // At one instant, in the vendor's order.
    let at_t0: Vec<Due> = sent.iter().filter(|(at, _)| *at == T0).map(|(_, t)| t.due).collect();
    assert!(matches!(at_t0[0], Due::Control { .. }));
    assert_eq!(
        at_t0[1..],
        [Due::SpeedPoll, Due::BatteryPoll, Due::AllStatePoll { motor: 0 }, Due::AllStatePoll { motor: 1 }]
    );
    let c = stream.counters();
    assert_eq!((c.control_frames, c.speed_requests, c.battery_requests, c.all_state_requests), (100, 50, 1, 20));
}

#[test]
fn a_command_older_than_the_timeout_becomes_a_stop() {
    let mut stream = CommandStream::new(T0, StreamConfig::default());
    let drive = PcControl { velocity_mps: 0.4, curvature_per_m: 0.0 };
    let mut sent = run_until(&mut stream, T0 + 5 * MS);
    stream.handle_command(T0 + 5 * MS, drive);
    sent.extend(run_until(&mut stream, T0 + 700 * MS));
    let controls: Vec<(Time, HostFrame)> =
        sent.iter().filter(|(_, t)| matches!(t.due, Due::Control { .. })).map(|(at, t)| (*at, t.frame)).collect();
    // Before the command: (0, 0); from 10 ms to 300 ms after it (t0 + 305 ms): the command;
    // from the first tick after that: (0, 0).
    for (at, frame) in &controls {
        let age = at.saturating_duration_since(T0 + 5 * MS);
        let expected = if *at >= T0 + 5 * MS && age <= 300 * MS { drive } else { PcControl::STOP };
        assert_eq!(*frame, HostFrame::PcControl(expected), "at t0 + {:?}", at.saturating_duration_since(T0));
    }
    let moving = controls.iter().filter(|(_, f)| *f == HostFrame::PcControl(drive)).count();
    assert_eq!(moving, 30, "t0 + 10 ms … t0 + 300 ms");
    let c = stream.counters();
    assert_eq!((c.command_timeouts, c.timeout_frames), (1, 70 - 30));
    // A refresh in time keeps it going.
    stream.handle_command(T0 + 700 * MS, drive);
    assert!(stream.is_command_fresh(T0 + 1000 * MS) && !stream.is_command_fresh(T0 + 1001 * MS));
    // A longer timeout (a bridge with its own deadman) takes effect at once.
    stream.set_command_timeout(500 * MS);
    assert!(stream.is_command_fresh(T0 + 1200 * MS) && !stream.is_command_fresh(T0 + 1201 * MS));
}

#[test]
fn stop_sends_the_burst_at_once_and_then_nothing() {
    let mut stream = CommandStream::new(T0, StreamConfig { stop_burst: 3, ..StreamConfig::default() });
    stream.handle_command(T0, PcControl { velocity_mps: 1.0, curvature_per_m: 0.0 });
    run_until(&mut stream, T0 + 50 * MS);
    assert!(stream.request(AfFrame::battery_read(0)));
    stream.stop();
    assert!(!stream.request(AfFrame::battery_read(0)), "no requests once stopping");
    assert_eq!(stream.poll_timeout(), Some(Time::ZERO), "due at once");
    let now = T0 + 52 * MS; // between two ticks
    let burst: Vec<Transmit> = std::iter::from_fn(|| stream.poll_transmit(now)).collect();
    assert_eq!(burst.len(), 3, "{burst:?}");
    assert!(burst.iter().all(|t| t.frame == HostFrame::PcControl(PcControl::STOP) && t.due == Due::Stop));
    assert!(stream.is_finished());
    assert_eq!(stream.poll_timeout(), None);
    assert_eq!(stream.poll_transmit(now + Duration::from_secs(1)), None);
    assert_eq!(stream.counters().stop_frames, 3);
    // A burst of 0 is still one frame.
    let mut one = CommandStream::new(T0, StreamConfig { stop_burst: 0, ..StreamConfig::default() });
    one.stop();
    assert_eq!(std::iter::from_fn(|| one.poll_transmit(T0)).count(), 1);
}

#[test]
fn a_late_tick_is_sent_once_and_the_missed_slots_are_counted() {
    let mut stream = CommandStream::new(T0, StreamConfig::default());
    run_until(&mut stream, T0 + 25 * MS); // ticks at 0, 10, 20 ms
    // The runner wakes 55 ms after the 30 ms deadline.
    let late = T0 + 85 * MS;
    let burst: Vec<Transmit> = std::iter::from_fn(|| stream.poll_transmit(late)).collect();
    let controls: Vec<&Transmit> = burst.iter().filter(|t| matches!(t.due, Due::Control { .. })).collect();
    assert_eq!(controls.len(), 1, "one frame, no catch-up burst: {burst:?}");
    assert_eq!(controls[0].due, Due::Control { fresh: false, lateness: 55 * MS, skipped: 5 });
    assert_eq!(burst.iter().filter(|t| t.due == Due::SpeedPoll).count(), 1);
    assert_eq!(stream.counters().missed_ticks, 5);
    assert_eq!(stream.poll_timeout(), Some(T0 + 90 * MS), "back on the grid");
}

#[test]
fn one_shot_requests_go_out_at_once_and_a_full_queue_refuses() {
    let mut stream = CommandStream::new(T0, StreamConfig::default());
    run_until(&mut stream, T0 + 5 * MS);
    assert!(stream.request(AfFrame::all_state_read(1)));
    assert_eq!(stream.poll_timeout(), Some(Time::ZERO));
    let now = T0 + 6 * MS;
    let sent = stream.poll_transmit(now).unwrap();
    assert_eq!((sent.frame, sent.due), (HostFrame::Af(AfFrame::all_state_read(1)), Due::Request));
    assert_eq!(stream.poll_transmit(now), None, "nothing else due at 6 ms");
    for _ in 0..MAX_PENDING_REQUESTS {
        assert!(stream.request(AfFrame::battery_read(0)));
    }
    assert!(!stream.request(AfFrame::battery_read(0)));
    let c = stream.counters();
    assert_eq!((c.requests_refused, c.all_state_requests), (1, 1));
}

#[test]
fn restart_puts_every_grid_at_now() {
    let mut stream = CommandStream::new(T0, StreamConfig::default());
    run_until(&mut stream, T0 + 15 * MS);
    let back = T0 + Duration::from_secs(3) + 3 * MS;
    stream.restart(back);
    assert_eq!(stream.poll_timeout(), Some(back));
    let first = stream.poll_transmit(back).unwrap();
    assert!(matches!(first.due, Due::Control { skipped: 0, .. }), "no misses counted for the outage");
}
