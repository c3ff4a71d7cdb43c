//! The `cmd_vel` guard, sans-IO on caller time: nothing moves until armed; NaN, infinities and
//! out-of-range twists are dropped and counted; a command older than the deadman time becomes
//! a stop; a second publisher is noticed.

use std::time::{Duration, Instant};

use ros2_proto::geometry::Twist;

/// What to do with a received twist.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// Command the device: forward m/s, sideways m/s, yaw rate rad/s.
    Drive {
        /// Forward velocity, m/s.
        vx_mps: f32,
        /// Sideways velocity, m/s.
        vy_mps: f32,
        /// Yaw rate, rad/s.
        yaw_rate_radps: f32,
    },
    /// Not armed: nothing is sent.
    Unarmed,
    /// Not finite, or not representable as f32: dropped.
    Invalid,
}

/// Counters of the guard.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct GuardCounters {
    /// Twists received.
    pub received: u64,
    /// Twists passed to the device.
    pub applied: u64,
    /// Twists dropped because the bridge is not armed.
    pub unarmed: u64,
    /// Twists dropped as NaN or infinite.
    pub invalid: u64,
    /// Twists the device refused: out of its range, or not now (a lying dog).
    pub refused: u64,
    /// Deadman stops (a command older than the deadman time).
    pub deadman_stops: u64,
    /// Publishers seen on `cmd_vel`.
    pub publishers: u64,
}

/// The guard of one device's `cmd_vel`.
#[derive(Debug)]
pub struct CmdVelGuard {
    armed: bool,
    deadman: Duration,
    /// When the last applied twist arrived; `None` once stopped.
    moving_since: Option<Instant>,
    writers: Vec<[u8; 16]>,
    counters: GuardCounters,
}

impl CmdVelGuard {
    /// A guard; `armed` false: the bridge only publishes.
    pub fn new(armed: bool, deadman: Duration) -> Self {
        Self { armed, deadman, moving_since: None, writers: Vec::new(), counters: GuardCounters::default() }
    }

    /// A twist from `writer` received at `now`. `Some(count)` in the second field when this
    /// writer is a new publisher beyond the first (two publishers now command the device).
    pub fn on_twist(&mut self, now: Instant, twist: &Twist, writer: [u8; 16]) -> (Verdict, Option<usize>) {
        self.counters.received += 1;
        let second_publisher = if self.writers.contains(&writer) {
            None
        } else {
            self.writers.push(writer);
            self.counters.publishers = self.writers.len() as u64;
            (self.writers.len() > 1).then_some(self.writers.len())
        };
        if !self.armed {
            self.counters.unarmed += 1;
            return (Verdict::Unarmed, second_publisher);
        }
        let to_f32 = |v: f64| {
            let f = v as f32;
            (v.is_finite() && f.is_finite()).then_some(f)
        };
        let (Some(vx_mps), Some(vy_mps), Some(yaw_rate_radps)) =
            (to_f32(twist.linear.x), to_f32(twist.linear.y), to_f32(twist.angular.z))
        else {
            self.counters.invalid += 1;
            return (Verdict::Invalid, second_publisher);
        };
        if [twist.linear.z, twist.angular.x, twist.angular.y].iter().any(|v| !v.is_finite()) {
            self.counters.invalid += 1;
            return (Verdict::Invalid, second_publisher);
        }
        self.moving_since = Some(now);
        (Verdict::Drive { vx_mps, vy_mps, yaw_rate_radps }, second_publisher)
    }

    /// The device refused the twist (out of its range, or not in this state): nothing moves.
    pub fn refused(&mut self) {
        self.counters.refused += 1;
        self.moving_since = None;
    }

    /// The device took an applied twist.
    pub fn applied(&mut self) {
        self.counters.applied += 1;
    }

    /// At `now`: `true` once when the last command has grown older than the deadman time (the
    /// caller stops the device).
    pub fn on_tick(&mut self, now: Instant) -> bool {
        match self.moving_since {
            Some(at) if now.saturating_duration_since(at) > self.deadman => {
                self.moving_since = None;
                self.counters.deadman_stops += 1;
                true
            }
            _ => false,
        }
    }

    /// When [`on_tick`](Self::on_tick) should next be called, if a command is live.
    pub fn deadline(&self) -> Option<Instant> {
        self.moving_since.map(|at| at + self.deadman)
    }

    /// The counters.
    pub fn counters(&self) -> GuardCounters {
        self.counters
    }
}

#[cfg(test)]
mod tests {
    use ros2_proto::geometry::Vector3;

    use super::*;

    fn twist(vx: f64, wz: f64) -> Twist {
        Twist { linear: Vector3 { x: vx, y: 0.0, z: 0.0 }, angular: Vector3 { x: 0.0, y: 0.0, z: wz } }
    }

    #[test]
    fn unarmed_moves_nothing() {
        let mut guard = CmdVelGuard::new(false, Duration::from_millis(500));
        let now = Instant::now();
        assert_eq!(guard.on_twist(now, &twist(0.5, 0.0), [1; 16]).0, Verdict::Unarmed);
        assert!(!guard.on_tick(now + Duration::from_secs(1)));
        assert_eq!(guard.counters().unarmed, 1);
    }

    #[test]
    fn a_stale_command_stops_once_on_the_fake_clock() {
        let mut guard = CmdVelGuard::new(true, Duration::from_millis(500));
        let t0 = Instant::now();
        let (verdict, _) = guard.on_twist(t0, &twist(0.5, 0.25), [1; 16]);
        assert_eq!(verdict, Verdict::Drive { vx_mps: 0.5, vy_mps: 0.0, yaw_rate_radps: 0.25 });
        assert_eq!(guard.deadline(), Some(t0 + Duration::from_millis(500)));
        assert!(!guard.on_tick(t0 + Duration::from_millis(500)));
        assert!(guard.on_tick(t0 + Duration::from_millis(501)));
        assert!(!guard.on_tick(t0 + Duration::from_millis(900)), "one stop per stale command");
        assert_eq!(guard.counters().deadman_stops, 1);
    }

    #[test]
    fn non_finite_and_overflowing_twists_are_dropped() {
        let mut guard = CmdVelGuard::new(true, Duration::from_millis(500));
        let now = Instant::now();
        for bad in [twist(f64::NAN, 0.0), twist(0.0, f64::INFINITY), twist(1e300, 0.0)] {
            assert_eq!(guard.on_twist(now, &bad, [1; 16]).0, Verdict::Invalid);
        }
        let mut tilted = twist(0.1, 0.0);
        tilted.angular.x = f64::NAN;
        assert_eq!(guard.on_twist(now, &tilted, [1; 16]).0, Verdict::Invalid);
        assert_eq!(guard.counters().invalid, 4);
        assert_eq!(guard.deadline(), None, "nothing live");
    }

    #[test]
    fn a_second_publisher_is_reported_once() {
        let mut guard = CmdVelGuard::new(true, Duration::from_millis(500));
        let now = Instant::now();
        assert_eq!(guard.on_twist(now, &twist(0.1, 0.0), [1; 16]).1, None);
        assert_eq!(guard.on_twist(now, &twist(0.1, 0.0), [2; 16]).1, Some(2));
        assert_eq!(guard.on_twist(now, &twist(0.1, 0.0), [2; 16]).1, None);
        assert_eq!(guard.counters().publishers, 2);
    }
}
