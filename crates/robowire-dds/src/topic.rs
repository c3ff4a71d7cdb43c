//! Typed writers and readers with their counters.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll};

use std::cell::RefCell;
use std::marker::PhantomData;

use robowire_core::cdr::CdrType;
use robowire_tap::{Direction, SLOT_BYTES, SampleOrigin, Tap};
use rustdds::no_key::{DataWriter, SimpleDataReader};
use rustdds::{DataWriterStatus, GUID, RTPSEntity, SequenceNumber, StatusEvented, Timestamp, WriteOptionsBuilder};

use crate::DdsError;
use crate::adapter::{CdrAdapter, Decoded, TakenPayload, TapDecoder};

/// An RTPS timestamp (seconds and 2^-32 fractions since the Unix epoch) as Unix ns.
fn unix_ns(timestamp: Timestamp) -> u64 {
    let ticks = timestamp.to_ticks();
    (ticks >> 32) * 1_000_000_000 + (((ticks & 0xffff_ffff) * 1_000_000_000) >> 32)
}

/// What a writer or reader has done.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TopicStats {
    /// Samples written, or received and decoded.
    pub samples: u64,
    /// Writes that failed.
    pub write_errors: u64,
    /// Samples a never-blocking writer dropped because its send window was full.
    pub dropped: u64,
    /// Received samples whose body did not decode (checksum failures not included).
    pub decode_errors: u64,
    /// Received samples whose integrity check (CRC) failed.
    pub checksum_errors: u64,
}

#[derive(Debug, Default)]
struct Counters {
    samples: AtomicU64,
    write_errors: AtomicU64,
    dropped: AtomicU64,
    decode_errors: AtomicU64,
    checksum_errors: AtomicU64,
}

impl Counters {
    fn bump(counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    fn get(&self) -> TopicStats {
        TopicStats {
            samples: self.samples.load(Ordering::Relaxed),
            write_errors: self.write_errors.load(Ordering::Relaxed),
            dropped: self.dropped.load(Ordering::Relaxed),
            decode_errors: self.decode_errors.load(Ordering::Relaxed),
            checksum_errors: self.checksum_errors.load(Ordering::Relaxed),
        }
    }
}

/// A handle on a writer's or reader's counters, usable from any thread.
#[derive(Debug, Clone)]
pub struct StatsHandle(Arc<Counters>);

impl StatsHandle {
    /// The counters now.
    pub fn get(&self) -> TopicStats {
        self.0.get()
    }
}

/// Why [`Writer::try_write`] did not publish a sample (counted; nothing allocated).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum WriteRefused {
    /// The send window was full (a reliable reader that does not acknowledge): dropped.
    #[error("the send window is full; the sample was dropped")]
    WindowFull,
    /// The middleware failed (its threads gone, the encoder refused).
    #[error("the middleware refused the sample")]
    Failed,
}

/// Writes `T` to one topic. Usable from any thread. With a reliable QoS, a `write` may wait up to
/// the QoS's blocking bound while a reader does not acknowledge; a stream thread uses
/// [`Qos::STREAM_WRITER`](crate::qos::Qos::STREAM_WRITER) and [`try_write`](Self::try_write),
/// which never waits.
pub struct Writer<T: CdrType + 'static> {
    inner: DataWriter<T, CdrAdapter<T>>,
    topic: String,
    counters: Arc<Counters>,
    /// Matched readers, from the last publication-matched status seen.
    matched: AtomicI64,
    /// The matched readers' GUIDs, from the publication-matched statuses seen (taken only by
    /// the `matched`/`reader_matched` queries, never by a write).
    matched_guids: Mutex<Vec<[u8; 16]>>,
    /// Where each sample written goes as its payload, with this writer's GUID.
    tap: Option<(Tap, [u8; 16])>,
}

impl<T: CdrType + 'static> std::fmt::Debug for Writer<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Writer").field("topic", &self.topic).field("type", &T::TYPE_NAME).finish_non_exhaustive()
    }
}

impl<T: CdrType + 'static> Writer<T> {
    pub(crate) fn new(inner: DataWriter<T, CdrAdapter<T>>, topic: &str) -> Self {
        Self {
            inner,
            topic: topic.into(),
            counters: Arc::default(),
            matched: AtomicI64::new(0),
            matched_guids: Mutex::default(),
            tap: None,
        }
    }

    /// Hands every sample this writer publishes to `tap` as its payload (encapsulation header,
    /// body), with the writer's GUID and the source timestamp it is published with.
    pub fn set_tap(&mut self, tap: Option<Tap>) {
        let guid = self.guid();
        self.tap = tap.map(|tap| (tap, guid));
    }

    /// Publishes `sample` (with `related` as its related sample identity, if any), its payload
    /// first handed to the tap if there is one: the payload as rustdds will send it, encoded on
    /// the stack (no allocation), and the source timestamp given to rustdds so that the tap's and
    /// the wire's agree. The written sample's own identity.
    fn publish(
        &self,
        sample: T,
        related: Option<SampleIdentity>,
    ) -> Result<SampleIdentity, rustdds::dds::WriteError<T>> {
        let options = WriteOptionsBuilder::new().related_sample_identity_opt(related.map(SampleIdentity::to_rustdds));
        let Some((tap, guid)) = &self.tap else {
            return self.inner.write_with_options(sample, options.build()).map(SampleIdentity::of_rustdds);
        };
        let source = Timestamp::now();
        let mut payload = [0u8; SLOT_BYTES];
        let [a, b] = <CdrAdapter<T> as rustdds::no_key::SerializerAdapter<T>>::output_encoding().to_bytes();
        payload[..4].copy_from_slice(&[a, b, 0, 0]);
        let body = sample.encode_body(&mut payload[4..]).ok();
        let written = self.inner.write_with_options(sample, options.source_timestamp(source).build())?;
        let origin = SampleOrigin { writer: Some(*guid), source_unix_ns: Some(unix_ns(source)) };
        match body {
            Some(n) => tap.record_parts(Direction::Sent, &[&payload[..4 + n]], origin),
            None => tap.count_oversize(),
        }
        Ok(SampleIdentity::of_rustdds(written))
    }

    /// Encodes `sample` with its codec and publishes it.
    pub fn write(&self, sample: T) -> Result<(), DdsError> {
        self.write_with(sample, None).map(drop)
    }

    /// Publishes `sample` with `related` as its related sample identity (sent as inline QoS
    /// under both PID 0x0083 and eProsima's 0x800f): a reply naming the request it answers, as
    /// rmw_fastrtps' services do. The written sample's own identity (this writer's GUID, its
    /// sequence number): what an answer to it names.
    pub fn write_related(&self, sample: T, related: SampleIdentity) -> Result<SampleIdentity, DdsError> {
        self.write_with(sample, Some(related))
    }

    fn write_with(&self, sample: T, related: Option<SampleIdentity>) -> Result<SampleIdentity, DdsError> {
        match self.publish(sample, related) {
            Ok(written) => {
                Counters::bump(&self.counters.samples);
                Ok(written)
            }
            Err(e) => {
                Counters::bump(&self.counters.write_errors);
                Err(DdsError::Write { topic: self.topic.clone(), source: e.forget_data() })
            }
        }
    }

    /// Publishes `sample` without ever waiting (with [`Qos::STREAM_WRITER`](crate::qos::Qos::STREAM_WRITER)):
    /// a full send window drops it. No allocation on a refusal. For stream threads.
    pub fn try_write(&self, sample: T) -> Result<(), WriteRefused> {
        match self.publish(sample, None) {
            Ok(_) => {
                Counters::bump(&self.counters.samples);
                Ok(())
            }
            Err(rustdds::dds::WriteError::WouldBlock { .. }) => {
                Counters::bump(&self.counters.dropped);
                Err(WriteRefused::WindowFull)
            }
            Err(_) => {
                Counters::bump(&self.counters.write_errors);
                Err(WriteRefused::Failed)
            }
        }
    }

    /// Its RTPS GUID in wire order (prefix 12 bytes, entity key 3, entity kind 1): the GID
    /// ROS 2 names it by.
    pub fn guid(&self) -> [u8; 16] {
        self.inner.guid().to_bytes()
    }

    /// Whether every reliable reader matched has acknowledged every sample written so far;
    /// waits until they have (or the writer is gone): bring a timeout. Best effort: at once.
    pub async fn acknowledged(&self) -> Result<bool, DdsError> {
        self.inner
            .async_wait_for_acknowledgments()
            .await
            .map_err(|source| DdsError::Write { topic: self.topic.clone(), source })
    }

    /// Readers of this topic matched so far.
    pub fn matched_readers(&self) -> usize {
        self.take_statuses();
        usize::try_from(self.matched.load(Ordering::Relaxed)).unwrap_or(0)
    }

    /// Whether the reader whose GUID (wire order) is `reader` is matched now: a reply to it
    /// written before would be lost (volatile).
    pub fn reader_matched(&self, reader: [u8; 16]) -> bool {
        self.take_statuses();
        robowire_rt::lock(&self.matched_guids).contains(&reader)
    }

    /// The publication-matched statuses since the last look, into the count and the GUIDs.
    fn take_statuses(&self) {
        while let Some(status) = self.inner.try_recv_status() {
            if let DataWriterStatus::PublicationMatched { current, reader, .. } = status {
                self.matched.store(i64::from(current.count()), Ordering::Relaxed);
                let mut guids = robowire_rt::lock(&self.matched_guids);
                let reader = reader.to_bytes();
                guids.retain(|g| *g != reader);
                if current.count_change() > 0 {
                    guids.push(reader);
                }
            }
        }
    }

    /// The topic.
    pub fn topic(&self) -> &str {
        &self.topic
    }

    /// Counters.
    pub fn stats(&self) -> TopicStats {
        self.counters.get()
    }

    /// A handle on the counters.
    pub fn stats_handle(&self) -> StatsHandle {
        StatsHandle(self.counters.clone())
    }
}

/// A sample as received.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample<T> {
    /// The message.
    pub value: T,
    /// The GUID of the writer that sent it (tells two publishers on one topic apart).
    pub writer: [u8; 16],
    /// Its RTPS sequence number at that writer (from 1).
    pub sequence: i64,
    /// The related sample identity its writer sent with it (inline QoS PID 0x0083 or 0x800f),
    /// if any: for a request of rmw_fastrtps, where the reply goes.
    pub related: Option<SampleIdentity>,
}

/// A sample's identity: its writer's GUID and its sequence number there (DDS-RPC's
/// `SampleIdentity`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SampleIdentity {
    /// The writer's GUID in wire order (prefix 12 bytes, entity key 3, entity kind 1); all zero:
    /// unknown.
    pub writer: [u8; 16],
    /// The sequence number; [`SampleIdentity::SEQUENCE_UNKNOWN`]: unknown.
    pub sequence: i64,
}

impl SampleIdentity {
    /// RTPS's unknown sequence number (high −1, low 0), what rmw_fastrtps' clients send in
    /// their requests' related sample identity.
    pub const SEQUENCE_UNKNOWN: i64 = -1 << 32;

    /// Whether the writer GUID is known (not all zero).
    pub fn writer_known(&self) -> bool {
        self.writer != [0; 16]
    }

    fn to_rustdds(self) -> rustdds::rpc::SampleIdentity {
        rustdds::rpc::SampleIdentity {
            writer_guid: GUID::from_bytes(self.writer),
            sequence_number: SequenceNumber::from(self.sequence),
        }
    }

    fn of_rustdds(identity: rustdds::rpc::SampleIdentity) -> Self {
        Self { writer: identity.writer_guid.to_bytes(), sequence: identity.sequence_number.into() }
    }
}

/// Samples a reader takes between two drains of rustdds's notification socketpair.
const NOTIFICATIONS_DRAINED_EVERY: u32 = 64;

/// Reads `T` from one topic, asynchronously (any executor). Samples whose body does not decode
/// are counted and skipped. As DDS's keep-last history: of the samples that arrived since the last
/// `recv`, the newest `depth` (the QoS's) are kept, delivered oldest first; a keep-last-1 reader
/// gets the newest.
///
/// Served by the caller's task: `recv` takes from rustdds's topic cache itself and, when nothing
/// is there, parks on the waker rustdds's event loop wakes when a sample arrives (no task, no
/// channel in between).
pub struct Reader<T: CdrType + 'static> {
    inner: SimpleDataReader<Decoded<T>, CdrAdapter<T>>,
    /// Samples taken and not yet delivered, oldest first; at most `depth`.
    kept: VecDeque<Sample<T>>,
    depth: usize,
    /// Samples taken since rustdds's per-sample notification bytes were last drained.
    undrained: u32,
    topic: String,
    counters: Arc<Counters>,
    last_error: Option<String>,
    /// Where each sample taken goes as its payload, and the room it is copied into meanwhile.
    tap: Option<(Tap, RefCell<TakenPayload>)>,
}

impl<T: CdrType + 'static> std::fmt::Debug for Reader<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Reader").field("topic", &self.topic).field("type", &T::TYPE_NAME).finish_non_exhaustive()
    }
}

impl<T: CdrType + 'static> Reader<T> {
    pub(crate) fn new(inner: SimpleDataReader<Decoded<T>, CdrAdapter<T>>, topic: &str, depth: usize) -> Self {
        let depth = depth.max(1);
        Self {
            inner,
            kept: VecDeque::with_capacity(depth),
            depth,
            undrained: 0,
            topic: topic.into(),
            counters: Arc::default(),
            last_error: None,
            tap: None,
        }
    }

    /// Hands every sample this reader takes to `tap` as its payload (encapsulation header, body:
    /// decodable or not), with its writer's GUID and source timestamp. The header's two option
    /// bytes are recorded as zero (rustdds does not hand them over).
    pub fn set_tap(&mut self, tap: Option<Tap>) {
        self.tap = tap.map(|tap| (tap, RefCell::new(TakenPayload::new())));
    }

    /// The next sample that decodes.
    pub async fn recv(&mut self) -> Result<Sample<T>, DdsError> {
        let sample = std::future::poll_fn(|cx| self.poll_recv(cx)).await;
        Counters::bump(&self.counters.samples);
        Ok(sample)
    }

    /// The next kept sample; else, `cx`'s waker handed to rustdds (it wakes it once, when a
    /// sample arrives) and one more look, so that a sample that arrived in between is not missed.
    fn poll_recv(&mut self, cx: &mut Context<'_>) -> Poll<Sample<T>> {
        self.take_arrived();
        if let Some(sample) = self.kept.pop_front() {
            return Poll::Ready(sample);
        }
        self.inner.set_waker(Some(cx.waker().clone()));
        self.take_arrived();
        self.kept.pop_front().map_or(Poll::Pending, Poll::Ready)
    }

    /// Takes every sample that arrived into `kept`, the oldest dropped beyond `depth`; counts the
    /// ones that do not decode.
    fn take_arrived(&mut self) {
        // rustdds also writes a byte to a socketpair (for a mio poll, unused here) per sample:
        // emptied now and then, so that it does not stay full.
        if self.undrained >= NOTIFICATIONS_DRAINED_EVERY {
            self.inner.drain_read_notifications();
            self.undrained = 0;
        }
        loop {
            let taken = match &self.tap {
                None => self.inner.try_take_one(),
                Some((tap, payload)) => {
                    let taken = self.inner.try_take_one_with(TapDecoder::<T> { taken: payload, decoder: PhantomData });
                    if let Ok(Some(change)) = &taken {
                        let origin = SampleOrigin {
                            writer: Some(change.writer_guid.to_bytes()),
                            source_unix_ns: change.write_options.source_timestamp().map(unix_ns),
                        };
                        let payload = payload.borrow();
                        if payload.oversize {
                            tap.count_oversize();
                        } else {
                            tap.record_parts(Direction::Received, &[&payload.header, &payload.body], origin);
                        }
                    }
                    taken
                }
            };
            self.undrained += u32::from(!matches!(taken, Ok(None)));
            match taken {
                Ok(None) => return,
                Ok(Some(change)) => match change.sample {
                    Ok(value) => {
                        if self.kept.len() == self.depth {
                            self.kept.pop_front();
                        }
                        self.kept.push_back(Sample {
                            value,
                            writer: change.writer_guid.to_bytes(),
                            sequence: change.sequence_number.into(),
                            related: change.write_options.related_sample_identity().map(SampleIdentity::of_rustdds),
                        });
                    }
                    Err(failure) => {
                        let counter = if failure.checksum {
                            &self.counters.checksum_errors
                        } else {
                            &self.counters.decode_errors
                        };
                        Counters::bump(counter);
                        self.last_error = Some(failure.reason);
                    }
                },
                // A read error of the library (a sample it could not take): counted, next.
                Err(e) => {
                    Counters::bump(&self.counters.decode_errors);
                    self.last_error = Some(e.to_string());
                }
            }
        }
    }

    /// Its RTPS GUID in wire order (prefix 12 bytes, entity key 3, entity kind 1): the GID
    /// ROS 2 names it by.
    pub fn guid(&self) -> [u8; 16] {
        self.inner.guid().to_bytes()
    }

    /// Why the last rejected sample was rejected (the codec's words).
    pub fn last_error(&self) -> Option<&str> {
        self.last_error.as_deref()
    }

    /// The topic.
    pub fn topic(&self) -> &str {
        &self.topic
    }

    /// Counters.
    pub fn stats(&self) -> TopicStats {
        self.counters.get()
    }

    /// A handle on the counters.
    pub fn stats_handle(&self) -> StatsHandle {
        StatsHandle(self.counters.clone())
    }
}

/// A sample of a type robowire has no codec for: its representation and its CDR body.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawSample {
    /// The representation the writer used.
    pub encoding: robowire_core::cdr::CdrEncoding,
    /// The body (after the 4-byte encapsulation header).
    pub body: Vec<u8>,
}

impl CdrType for RawSample {
    /// Not used: a raw reader's topic takes the type name it is given.
    const TYPE_NAME: &'static str = "";
    type Error = core::convert::Infallible;
    fn body_len(&self) -> usize {
        self.body.len()
    }
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, robowire_core::BufferTooSmall> {
        let (needed, available) = (self.body.len(), out.len());
        out.get_mut(..needed).ok_or(robowire_core::BufferTooSmall { needed, available })?.copy_from_slice(&self.body);
        Ok(needed)
    }
    fn decode_body(encoding: robowire_core::cdr::CdrEncoding, body: &[u8]) -> Result<Self, Self::Error> {
        Ok(Self { encoding, body: body.to_vec() })
    }
}
