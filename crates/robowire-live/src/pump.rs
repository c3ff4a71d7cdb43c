//! The live view's own thread: it empties the taps' ring, lets through at most one frame per
//! link, direction and length per period, and 16 per link and direction (counting every one;
//! frames of one message type mostly share a length, so a slow type is not starved by a fast one
//! on the same link), decodes those to JSON by their link's
//! description and logs them to the Foxglove channels, made on first use; a Unitree payload also
//! goes as the CDR it is, a robot's IMU attitude as a `foxglove.FrameTransform`, its bodies at
//! its joints' positions as `foxglove.FrameTransforms`.

use std::collections::HashSet;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use foxglove::{ChannelBuilder, Context, PartialMetadata, RawChannel, Schema};
use robowire_core::json::{JsonFrame, LinkDescription, Value};
use robowire_tap::{Direction, LinkRegistry, TapRing, TappedFrame};

use crate::messages::{self, Level};
use crate::relay::Viewers;
use crate::{LinkCount, LiveEvents, LiveStats, ViewerCount};

/// How long the thread sleeps when the ring is empty.
const POLL: Duration = Duration::from_millis(5);
/// How often `/robowire/live` says the counts.
const STATS_EVERY_NS: u64 = 1_000_000_000;
/// A link and direction that had this many frames in a second is a stream…
const STREAM_FRAMES_PER_S: u64 = 20;
/// …and one silent this long is said on the log (and again when frames come back).
const SILENT_AFTER_NS: u64 = 500_000_000;
/// Frame lengths whose last send is remembered per link and direction, at most (the oldest goes).
const LENGTHS: usize = 16;

/// One link and direction: what it got, and what the view keeps of it.
struct LinkState {
    count: LinkCount,
    /// When a frame of each length was last let through, newest last.
    last_sent_ns: Vec<(usize, u64)>,
    /// When any frame was last let through.
    last_any_sent_ns: Option<u64>,
    last_seen_ns: u64,
    /// The window's start (ns) and its frames so far: a second of them makes `streaming`.
    window: (u64, u64),
    streaming: bool,
    /// Said silent, not yet back.
    silent: bool,
    /// JSON channels by schema name.
    json: Vec<(&'static str, Arc<RawChannel>)>,
    /// Wire channels by schema name.
    wire: Vec<(&'static str, Arc<RawChannel>)>,
}

/// The thread's state.
pub(crate) struct Pump {
    pub(crate) ring: TapRing,
    pub(crate) registry: LinkRegistry,
    pub(crate) context: Arc<Context>,
    /// At most one frame per link and direction per this many ns.
    pub(crate) period_ns: u64,
    pub(crate) viewers: Arc<Viewers>,
    pub(crate) stats: Arc<Mutex<LiveStats>>,
    pub(crate) events: LiveEvents,
    /// By link number, then direction (sent, received).
    keys: Vec<[Option<LinkState>; 2]>,
    live: Option<Arc<RawChannel>>,
    /// Unix time minus the monotonic clock, ns.
    unix_offset_ns: i128,
}

impl Pump {
    pub(crate) fn new(
        ring: TapRing,
        registry: LinkRegistry,
        context: Arc<Context>,
        period_ns: u64,
        viewers: Arc<Viewers>,
        stats: Arc<Mutex<LiveStats>>,
        events: LiveEvents,
    ) -> Self {
        Self {
            ring,
            registry,
            context,
            period_ns,
            viewers,
            stats,
            events,
            keys: Vec::new(),
            live: None,
            unix_offset_ns: i128::from(messages::unix_now_ns()) - i128::from(robowire_rt::monotonic_ns()),
        }
    }

    /// Runs until `stop`, then empties the ring once more.
    pub(crate) fn run(mut self, stop: &AtomicBool) {
        let mut next_stats_ns = robowire_rt::monotonic_ns();
        loop {
            let stopping = stop.load(Ordering::Acquire);
            // At most a ring's worth at a time: the counts and silences are looked at between.
            let mut taken = 0;
            while taken < self.ring.slots()
                && let Some(frame) = self.ring.take()
            {
                self.frame(&frame);
                taken += 1;
            }
            let now = robowire_rt::monotonic_ns();
            self.say_silences(now);
            if now >= next_stats_ns || stopping {
                self.publish_stats();
                next_stats_ns = now + STATS_EVERY_NS;
            }
            if stopping && self.ring.waiting() == 0 {
                return;
            }
            if taken == 0 {
                std::thread::park_timeout(POLL);
            }
        }
    }

    fn frame(&mut self, frame: &TappedFrame) {
        let link = usize::from(frame.link);
        let Some((name, description)) = self.registry.lock().unwrap_or_else(PoisonError::into_inner).get(link).cloned()
        else {
            return;
        };
        if self.keys.len() <= link {
            self.keys.resize_with(link + 1, || [None, None]);
        }
        let slot = &mut self.keys[link][usize::from(frame.direction == Direction::Received)];
        let key = slot.get_or_insert_with(|| LinkState {
            count: LinkCount { topic: format!("/{name}/{}", frame.direction.name()), ..LinkCount::default() },
            last_sent_ns: Vec::with_capacity(LENGTHS),
            last_any_sent_ns: None,
            last_seen_ns: frame.monotonic_ns,
            window: (frame.monotonic_ns, 0),
            streaming: false,
            silent: false,
            json: Vec::new(),
            wire: Vec::new(),
        });
        key.count.seen += 1;
        let back_after_ns = key.silent.then(|| frame.monotonic_ns.saturating_sub(key.last_seen_ns));
        key.silent = false;
        key.last_seen_ns = frame.monotonic_ns;
        key.window.1 += 1;
        if frame.monotonic_ns.saturating_sub(key.window.0) >= 1_000_000_000 {
            key.streaming = key.window.1 >= STREAM_FRAMES_PER_S;
            key.window = (frame.monotonic_ns, 0);
        }
        if let Some(gap_ns) = back_after_ns {
            let message = format!("{}: frames again after {:.2} s", key.count.topic, gap_ns as f64 / 1e9);
            self.log(Level::Info, device(&name), &message);
        }
        let (period_ns, unix_offset_ns) = (self.period_ns, self.unix_offset_ns);
        let key = self.key(link, frame.direction);
        // At most LENGTHS times the rate per link and direction, whatever the lengths.
        if key.last_any_sent_ns.is_some_and(|last| frame.monotonic_ns.saturating_sub(last) < period_ns / LENGTHS as u64)
        {
            return;
        }
        let len = frame.bytes().len();
        let sent = key.last_sent_ns.iter().position(|(l, _)| *l == len);
        if let Some(at) = sent {
            if frame.monotonic_ns.saturating_sub(key.last_sent_ns[at].1) < period_ns {
                return;
            }
            key.last_sent_ns.remove(at);
        } else if key.last_sent_ns.len() == LENGTHS {
            key.last_sent_ns.remove(0);
        }
        key.last_sent_ns.push((len, frame.monotonic_ns));
        key.last_any_sent_ns = Some(frame.monotonic_ns);
        key.count.sent += 1;
        let log_time = u64::try_from(i128::from(frame.monotonic_ns) + unix_offset_ns).unwrap_or(0);
        let meta = PartialMetadata { log_time: Some(log_time) };
        let topic = key.count.topic.clone();
        match description.decode(frame.direction, frame.bytes()) {
            Ok(json) => {
                self.json(link, frame.direction, &topic, description, &json, meta);
                self.events.joints(device(&name), &json, meta);
                if !self.events.posed(device(&name))
                    && let Some(transform) = messages::frame_transform(&name, &json.value, log_time)
                {
                    self.transform(&transform, meta);
                }
            }
            Err(e) => {
                let key = self.key(link, frame.direction);
                key.count.undecodable += 1;
                if key.count.undecodable == 1 {
                    let message = format!("{topic}: a frame not decodable ({e}); later ones only counted");
                    self.log(Level::Warning, device(&name), &message);
                }
            }
        }
        if let Some(wire) = description.wire_schema(frame.direction, frame.bytes()) {
            let key = self.key(link, frame.direction);
            let channel = match key.wire.iter().find(|(n, _)| *n == wire.name) {
                Some((_, channel)) => Some(channel.clone()),
                None => {
                    let schema = Schema::new(wire.name, wire.schema_encoding, wire.text.as_bytes().to_vec());
                    let channel = self.channel(&topic, wire.encoding, schema);
                    let key = self.key(link, frame.direction);
                    if let Some(channel) = &channel {
                        key.wire.push((wire.name, channel.clone()));
                    }
                    channel
                }
            };
            if let Some(channel) = channel {
                channel.log_with_meta(frame.bytes(), meta);
            }
        }
    }

    /// Says once each stream that went silent.
    fn say_silences(&mut self, now_ns: u64) {
        let mut silent = Vec::new();
        for (link, keys) in self.keys.iter_mut().enumerate() {
            for key in keys.iter_mut().flatten() {
                if key.streaming && !key.silent && now_ns.saturating_sub(key.last_seen_ns) >= SILENT_AFTER_NS {
                    key.silent = true;
                    silent.push((link, key.count.topic.clone()));
                }
            }
        }
        for (link, topic) in silent {
            let name = self.registry.lock().unwrap_or_else(PoisonError::into_inner).get(link).map(|(n, _)| n.clone());
            let name = name.unwrap_or_default();
            let message = format!("{topic}: no frames for {:.1} s", SILENT_AFTER_NS as f64 / 1e9);
            self.log(Level::Warning, device(&name), &message);
        }
    }

    fn key(&mut self, link: usize, direction: Direction) -> &mut LinkState {
        self.keys[link][usize::from(direction == Direction::Received)]
            .as_mut()
            .unwrap_or_else(|| unreachable!("made before any use"))
    }

    fn json(
        &mut self,
        link: usize,
        direction: Direction,
        topic: &str,
        description: &'static dyn LinkDescription,
        json: &JsonFrame,
        meta: PartialMetadata,
    ) {
        let key = self.key(link, direction);
        let channel = match key.json.iter().find(|(n, _)| *n == json.schema) {
            Some((_, channel)) => Some(channel.clone()),
            None => {
                let schema_text = serde_json::to_vec(&description.schema(json)).unwrap_or_default();
                let schema = Schema::new(json.schema, "jsonschema", schema_text);
                let channel = self.channel(&format!("{topic}/{}", json.schema), "json", schema);
                if let Some(channel) = &channel {
                    self.key(link, direction).json.push((json.schema, channel.clone()));
                }
                channel
            }
        };
        if let (Some(channel), Ok(bytes)) = (channel, serde_json::to_vec(&json.value)) {
            channel.log_with_meta(&bytes, meta);
        }
    }

    fn transform(&mut self, transform: &Value, meta: PartialMetadata) {
        if let Ok(bytes) = serde_json::to_vec(transform) {
            self.events.transforms.log_with_meta(&bytes, meta);
        }
    }

    /// A channel on this server's context; `None` (and said on the log) if the SDK refuses it.
    fn channel(&self, topic: &str, encoding: &str, schema: Schema) -> Option<Arc<RawChannel>> {
        let built =
            ChannelBuilder::new(topic).context(&self.context).message_encoding(encoding).schema(schema).build_raw();
        match built {
            Ok(channel) => Some(channel),
            Err(e) => {
                self.log(Level::Error, "live", &format!("{topic}: no channel ({e})"));
                None
            }
        }
    }

    fn log(&self, level: Level, name: &str, message: &str) {
        self.events.log(level, name, message);
    }

    fn publish_stats(&mut self) {
        let stats = LiveStats {
            links: self.keys.iter().flatten().flatten().map(|key| key.count.clone()).collect(),
            viewers: self
                .viewers
                .connected()
                .into_iter()
                .map(|(addr, forwarded, dropped)| ViewerCount { addr, forwarded, dropped })
                .collect(),
            viewer_dropped_total: self.viewers.totals().1,
            ring_dropped: self.ring.counters().dropped(),
        };
        if self.live.is_none() {
            self.live = self.channel("/robowire/live", "json", messages::live_stats_schema());
        }
        if let Some(live) = &self.live {
            live.log(&serde_json::to_vec(&messages::live_stats_json(&stats)).unwrap_or_default());
        }
        *self.stats.lock().unwrap_or_else(PoisonError::into_inner) = stats;
    }
}

/// The device a link belongs to: the first part of its name.
fn device(link: &str) -> &str {
    link.split('/').next().unwrap_or(link)
}

/// The links registered so far, each by name, with its description's protocol.
pub(crate) fn registered(registry: &LinkRegistry) -> Vec<(String, &'static str)> {
    let links = registry.lock().unwrap_or_else(PoisonError::into_inner);
    let mut seen = HashSet::new();
    links
        .iter()
        .filter(|(name, _)| seen.insert(name.clone()))
        .map(|(name, description)| (name.clone(), description.protocol()))
        .collect()
}
