//! What every device's bridge shares: its namespace, frame ids, stamps, the rate cap, the
//! `cmd_vel` guard's options, and typed writers under ROS 2 names and QoS.

use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use robowire_core::cdr::CdrType;
use robowire_dds::Sample;
use robowire_record::{RecordLinks, Tap};
use ros2_proto::geometry::Twist;

use crate::graph::{NodeId, RosGraph};
use crate::guard::{CmdVelGuard, Verdict};
use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Participant, Reader, Writer};
use ros2_proto::builtin::{Header, Time};

/// How a device is bridged.
#[derive(Debug, Clone)]
pub(crate) struct NodeOptions {
    /// The device's namespace (`""` for the root, else `/ns`).
    pub namespace: String,
    /// `cmd_vel` moves the robot; without it the bridge only publishes.
    pub armed: bool,
    /// A `cmd_vel` older than this stops the robot.
    pub deadman: Duration,
    /// Publish at most this often per topic, Hz (`None`: the device's native rate).
    pub rate_cap_hz: Option<f64>,
    /// Where the topics' samples are recorded, each topic a link named after it.
    pub record: Option<RecordLinks>,
}

/// One device's node: topics in its namespace on the shared participant, each endpoint listed
/// under the node in the ROS graph.
pub(crate) struct Node<'a> {
    pub(crate) participant: &'a Participant,
    pub(crate) graph: &'a RosGraph,
    pub(crate) id: NodeId,
    pub(crate) options: NodeOptions,
}

impl Node<'_> {
    /// A writer of the ROS topic `name` in the namespace (recorded if the bridge records).
    pub(crate) fn writer<T: CdrType + 'static>(&self, name: &str, qos: Qos) -> Result<Writer<T>, DdsError> {
        let mut writer = self.participant.writer(&ros2_proto::topic(&self.options.namespace, name), qos)?;
        writer.set_tap(self.tap::<T>(name));
        self.listed_writer(writer)
    }

    /// A reader of the ROS topic `name` in the namespace (recorded if the bridge records).
    pub(crate) fn reader<T: CdrType + 'static>(&self, name: &str, qos: Qos) -> Result<Reader<T>, DdsError> {
        let mut reader = self.participant.reader(&ros2_proto::topic(&self.options.namespace, name), qos)?;
        reader.set_tap(self.tap::<T>(name));
        self.listed_reader(reader)
    }

    /// `writer`, listed under this node in the ROS graph.
    pub(crate) fn listed_writer<T: CdrType + 'static>(&self, writer: Writer<T>) -> Result<Writer<T>, DdsError> {
        self.graph.add_writer(self.id, writer.guid())?;
        Ok(writer)
    }

    /// `reader`, listed under this node in the ROS graph.
    pub(crate) fn listed_reader<T: CdrType + 'static>(&self, reader: Reader<T>) -> Result<Reader<T>, DdsError> {
        self.graph.add_reader(self.id, reader.guid())?;
        Ok(reader)
    }

    /// A tap for the ROS topic `name` in the namespace, named as ROS names it (`kmc/odom`), if
    /// the bridge records and the type is one ROS 2 tools can read from a capture.
    fn tap<T: CdrType>(&self, name: &str) -> Option<Tap> {
        let record = self.options.record.as_ref()?;
        let description = ros2_proto::description::of(T::TYPE_NAME)?;
        // The DDS topic is the ROS one behind `rt/`.
        let dds_topic = ros2_proto::topic(&self.options.namespace, name);
        Some(record.link(dds_topic.strip_prefix("rt/").unwrap_or(&dds_topic), description))
    }

    /// The frame id `name` in the namespace: `odom`, or `kmc0/odom`.
    pub(crate) fn frame(&self, name: &str) -> String {
        let ns = self.options.namespace.trim_matches('/');
        if ns.is_empty() { name.into() } else { format!("{ns}/{name}") }
    }

    /// A header at `stamp` in the frame `name`.
    pub(crate) fn header(&self, stamp: Time, name: &str) -> Header {
        Header { stamp, frame_id: self.frame(name) }
    }

    /// A rate limiter for one topic group.
    pub(crate) fn limiter(&self) -> RateLimiter {
        RateLimiter { period: self.options.rate_cap_hz.map(|hz| Duration::from_secs_f64(1.0 / hz)), last: None }
    }
}

/// Now as a ROS time (wall clock, what ROS 2 nodes stamp with by default).
pub(crate) fn stamp_now() -> Time {
    let since = SystemTime::now().duration_since(UNIX_EPOCH).unwrap_or_default();
    Time::from_nanos(u64::try_from(since.as_nanos()).unwrap_or(u64::MAX))
}

/// Lets a publish through at most once per period.
#[derive(Debug)]
pub(crate) struct RateLimiter {
    period: Option<Duration>,
    last: Option<Instant>,
}

impl RateLimiter {
    /// Whether to publish at `now` (and if so, counts it as published).
    pub(crate) fn ready(&mut self, now: Instant) -> bool {
        let due = match (self.period, self.last) {
            (Some(period), Some(last)) => now.saturating_duration_since(last) >= period,
            _ => true,
        };
        if due {
            self.last = Some(now);
        }
        due
    }
}

/// A device's `cmd_vel`: the guard, its log, and what the device made of each twist.
pub(crate) struct CmdVel {
    pub(crate) guard: CmdVelGuard,
    log: LogLimiter,
    topic: String,
}

impl CmdVel {
    pub(crate) fn new(options: &NodeOptions) -> Self {
        Self {
            guard: CmdVelGuard::new(options.armed, options.deadman),
            log: LogLimiter::default(),
            topic: format!("{}/cmd_vel", options.namespace),
        }
    }

    /// A received twist: forward m/s, sideways m/s, yaw rate rad/s for the device, or `None`
    /// (unarmed, or not finite: counted, the latter logged). A new publisher is logged.
    pub(crate) fn receive(&mut self, now: Instant, sample: &Sample<Twist>) -> Option<(f32, f32, f32)> {
        let (verdict, second) = self.guard.on_twist(now, &sample.value, sample.writer);
        if let Some(count) = second {
            eprintln!("{}: {count} publishers now command this device; the latest twist wins", self.topic);
        }
        match verdict {
            Verdict::Drive { vx_mps, vy_mps, yaw_rate_radps } => Some((vx_mps, vy_mps, yaw_rate_radps)),
            Verdict::Invalid => {
                let topic = &self.topic;
                self.log.log(now, || format!("{topic} dropped: not finite {:?}", sample.value));
                None
            }
            Verdict::Unarmed => None,
        }
    }

    /// What the device made of the twist [`receive`](Self::receive) passed on; whether it took it.
    pub(crate) fn outcome<E: std::error::Error>(&mut self, now: Instant, result: Result<(), E>) -> bool {
        match result {
            Ok(()) => {
                self.guard.applied();
                true
            }
            Err(e) => {
                self.guard.refused();
                let topic = &self.topic;
                self.log.log(now, || format!("{topic} refused: {}", robowire_devices::error_chain(&e)));
                false
            }
        }
    }
}

/// Logs at most once per second per call site's limiter; the rest are counted in `suppressed`.
#[derive(Debug, Default)]
pub(crate) struct LogLimiter {
    last: Option<Instant>,
    suppressed: u64,
}

impl LogLimiter {
    pub(crate) fn log(&mut self, now: Instant, message: impl FnOnce() -> String) {
        if self.last.is_some_and(|last| now.saturating_duration_since(last) < Duration::from_secs(1)) {
            self.suppressed += 1;
            return;
        }
        let more = std::mem::take(&mut self.suppressed);
        let suffix = if more > 0 { format!(" ({more} more since the last report)") } else { String::new() };
        eprintln!("{}{suffix}", message());
        self.last = Some(now);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rate_cap_lets_one_through_per_period() {
        let mut limiter = RateLimiter { period: Some(Duration::from_millis(100)), last: None };
        let t0 = Instant::now();
        assert!(limiter.ready(t0));
        assert!(!limiter.ready(t0 + Duration::from_millis(99)));
        assert!(limiter.ready(t0 + Duration::from_millis(100)));
        let mut native = RateLimiter { period: None, last: None };
        assert!(native.ready(t0) && native.ready(t0));
    }
}
