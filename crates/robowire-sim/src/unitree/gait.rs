//! The robot's own locomotion, when the simulator is given one (`--walk`): the sport/loco
//! service says whether it runs and at what velocity ([`GaitAsk`]), and an onboard controller
//! (a walking policy in the simulator's process) reads the robot's state and drives its motors
//! through an [`Onboard`] port, as the robot's controller does beside the DDS clients.

use std::fmt;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};

use robowire_core::schedule::Time;

use super::BasePose;

/// What the robot's service asks of its locomotion now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaitRequest {
    /// The locomotion runs (a standing or walking mode owns the motors); off: the onboard
    /// controller drives nothing and the robot's own behaviour holds (damping, lying).
    pub on: bool,
    /// vx m/s, vy m/s, yaw rate rad/s in the body frame; zero once the last `Move` expired.
    pub velocity: [f32; 3],
    /// How many times the locomotion was switched on: a new count is a new start (stand up
    /// first).
    pub starts: u32,
}

/// What the services thread asks of the locomotion, lock-free for any reader.
#[derive(Debug, Default)]
pub(crate) struct GaitAsk {
    on: AtomicBool,
    starts: AtomicU32,
    velocity: [AtomicU32; 3],
    /// Until when the velocity holds, ns on robowire's clock.
    until_ns: AtomicU64,
}

impl GaitAsk {
    /// Switches the locomotion on or off (a start counted when it turns on); off forgets the
    /// velocity.
    pub(crate) fn set_on(&self, on: bool) {
        if on && !self.on.swap(true, Ordering::AcqRel) {
            self.starts.fetch_add(1, Ordering::AcqRel);
        }
        if !on {
            self.on.store(false, Ordering::Release);
            self.until_ns.store(0, Ordering::Release);
        }
    }

    /// Asks `velocity` until `until`.
    pub(crate) fn set_velocity(&self, velocity: [f32; 3], until: Time) {
        for (slot, v) in self.velocity.iter().zip(velocity) {
            slot.store(v.to_bits(), Ordering::Relaxed);
        }
        self.until_ns.store(until.as_nanos(), Ordering::Release);
    }

    /// The request at `now`.
    pub(crate) fn request(&self, now: Time) -> GaitRequest {
        let held = now.as_nanos() < self.until_ns.load(Ordering::Acquire);
        GaitRequest {
            on: self.on.load(Ordering::Acquire),
            velocity: match held {
                true => self.velocity.each_ref().map(|v| f32::from_bits(v.load(Ordering::Relaxed))),
                false => [0.0; 3],
            },
            starts: self.starts.load(Ordering::Acquire),
        }
    }
}

/// What a simulated robot gives its onboard controller.
pub(crate) trait Port<S, C>: Send + Sync {
    /// The state the stream sent last, and when.
    fn state(&self) -> Option<(Time, S)>;
    /// The base as the stream last stepped it (physics only).
    fn base(&self) -> Option<BasePose>;
    /// Hands `command` (arrived at `now`) to the stream as the robot's own controller's.
    fn drive(&self, command: &C, now: Time);
    /// What the service asks.
    fn ask(&self) -> &GaitAsk;
}

/// The port of a simulated robot's own controller: its latest state, its base, the service's
/// request, and the motors while the request is on. A command it drives takes the place of the
/// robot's controller's (every motor with `mode` 1), held as a `rt/lowcmd` one is
/// ([`super::COMMAND_HOLD_S`]); `rt/lowcmd` and the other clients' rules stay as they are.
pub struct Onboard<S, C> {
    port: Arc<dyn Port<S, C>>,
}

impl<S, C> fmt::Debug for Onboard<S, C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Onboard").finish_non_exhaustive()
    }
}

impl<S, C> Clone for Onboard<S, C> {
    fn clone(&self) -> Self {
        Self { port: self.port.clone() }
    }
}

impl<S, C> Onboard<S, C> {
    pub(crate) fn new(port: Arc<dyn Port<S, C>>) -> Self {
        Self { port }
    }

    /// The LowState the robot sent last (its CRC as sent) and when.
    pub fn state(&self) -> Option<(Time, S)> {
        self.port.state()
    }

    /// The base's velocity in the world, m/s (physics only).
    pub fn base_velocity_world_mps(&self) -> Option<[f32; 3]> {
        self.port.base().map(|pose| pose.velocity_mps)
    }

    /// What the robot's service asks now.
    pub fn request(&self) -> GaitRequest {
        self.port.ask().request(robowire_rt::now())
    }

    /// Drives the motors with `command` while the request is on (ignored otherwise).
    pub fn drive(&self, command: &C) {
        if self.port.ask().request(robowire_rt::now()).on {
            self.port.drive(command, robowire_rt::now());
        }
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;

    #[test]
    fn a_velocity_holds_until_its_deadline_and_each_switch_on_is_a_start() {
        let ask = GaitAsk::default();
        let t0 = Time::from_nanos(1_000_000_000);
        assert_eq!(ask.request(t0), GaitRequest { on: false, velocity: [0.0; 3], starts: 0 });
        ask.set_on(true);
        ask.set_on(true);
        ask.set_velocity([0.5, 0.0, 0.2], t0 + Duration::from_secs(1));
        assert_eq!(ask.request(t0).velocity, [0.5, 0.0, 0.2]);
        assert_eq!(ask.request(t0 + Duration::from_secs(1)).velocity, [0.0; 3]);
        assert_eq!(ask.request(t0).starts, 1);
        ask.set_on(false);
        assert_eq!(ask.request(t0), GaitRequest { on: false, velocity: [0.0; 3], starts: 1 });
        ask.set_on(true);
        assert_eq!(ask.request(t0).starts, 2);
    }
}
