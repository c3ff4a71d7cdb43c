//! [`Writer`]: encodes a sample and sends its datagram on the caller's thread.

use std::cell::RefCell;
use std::marker::PhantomData;
use std::sync::Arc;
use std::sync::atomic::Ordering;

use robowire_core::cdr::CdrType;
use robowire_tap::{Direction, SampleOrigin, Tap};
use rtps_proto::endpoint::{WriteError, WriteOptions};
use rtps_proto::{EntityId, Timestamp};

use crate::DdsError;
use crate::driver::{Shared, State};
use crate::sample::{Counters, RawSample, SampleIdentity, StatsHandle, TopicStats, encode};

thread_local! {
    /// The payload of the sample being written: grown to the largest sample this thread wrote,
    /// then reused (no allocation per write).
    static PAYLOAD: RefCell<Vec<u8>> = const { RefCell::new(Vec::new()) };
}

/// Why [`Writer::try_write`] did not publish a sample (counted; nothing allocated).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum WriteRefused {
    /// The history was full of samples a reliable reader has not acknowledged (KEEP_ALL): dropped.
    #[error("the send window is full; the sample was dropped")]
    WindowFull,
    /// The sample could not be encoded or is larger than the participant's limit.
    #[error("the sample was refused")]
    Failed,
}

/// Writes `T` to one topic, from any thread. A write encodes the sample, hands it to the
/// participant and sends its datagram with one non-blocking `sendto` per destination on the
/// caller's thread: no hop, never a wait for a reader (a keep-last history replaces its oldest
/// sample; a full keep-all history refuses, counted).
pub struct Writer<T: CdrType + 'static> {
    shared: Arc<Shared>,
    id: EntityId,
    guid: [u8; 16],
    topic: String,
    counters: Arc<Counters>,
    tap: Option<Tap>,
    written: PhantomData<fn(T)>,
}

impl<T: CdrType + 'static> std::fmt::Debug for Writer<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Writer").field("topic", &self.topic).field("type", &T::TYPE_NAME).finish_non_exhaustive()
    }
}

/// Why a publish failed.
enum Refusal {
    Full,
    Failed(WriteError),
}

impl<T: CdrType + 'static> Writer<T> {
    pub(crate) fn new(shared: Arc<Shared>, id: EntityId, guid: [u8; 16], topic: &str) -> Self {
        Self { shared, id, guid, topic: topic.into(), counters: Arc::default(), tap: None, written: PhantomData }
    }

    /// Hands every sample this writer publishes to `tap` as its payload (encapsulation header,
    /// body), with the writer's GUID and the source timestamp it is published with.
    pub fn set_tap(&mut self, tap: Option<Tap>) {
        self.tap = tap;
    }

    fn publish(&self, sample: &T, related: Option<SampleIdentity>) -> Result<SampleIdentity, Refusal> {
        PAYLOAD.with(|payload| {
            let mut payload = payload.borrow_mut();
            encode(sample, &mut payload).map_err(|_| Refusal::Failed(WriteError::BufferTooSmall))?;
            self.publish_payload(&payload, related)
        })
    }

    /// Publishes `payload` (encapsulation header, body) as it is.
    fn publish_payload(&self, payload: &[u8], related: Option<SampleIdentity>) -> Result<SampleIdentity, Refusal> {
        let unix_ns = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX));
        let options = WriteOptions {
            source_timestamp: Some(Timestamp::from_unix_nanos(unix_ns)),
            related: related.map(SampleIdentity::to_rtps),
            key_hash: None,
        };
        let now = robowire_rt::now();
        let written = {
            let mut st = self.shared.lock();
            let State { core, buf, .. } = &mut *st;
            let written = core.write(now, self.id, payload, &options, buf);
            if let Ok(w) = &written {
                // Counted before it can arrive anywhere: a reader never sees a sample the
                // writer's counters do not have yet.
                Counters::bump(&self.counters.samples);
                if let Some(t) = w.transmit {
                    let failed = self.shared.sockets.send(&buf[..t.len], t.destinations());
                    self.shared.send_failures.fetch_add(failed, Ordering::Relaxed);
                }
                // Fragments, a heartbeat's new deadline.
                self.shared.settle(&mut st, now);
            }
            written
        };
        let sequence = match written {
            Ok(w) => w.sequence,
            Err(WriteError::HistoryFull { .. }) => return Err(Refusal::Full),
            Err(e) => return Err(Refusal::Failed(e)),
        };
        if let Some(tap) = &self.tap {
            let origin = SampleOrigin { writer: Some(self.guid), source_unix_ns: Some(unix_ns) };
            tap.record_parts(Direction::Sent, &[payload], origin);
        }
        Ok(SampleIdentity { writer: self.guid, sequence: sequence.0 })
    }

    /// Encodes `sample` with its codec and publishes it.
    pub fn write(&self, sample: T) -> Result<(), DdsError> {
        self.write_with(&sample, None).map(drop)
    }

    /// Publishes `sample` with `related` as its related sample identity (sent as inline QoS
    /// under both PID 0x0083 and eProsima's 0x800f): a reply naming the request it answers, as
    /// rmw_fastrtps' services do. The written sample's own identity (this writer's GUID, its
    /// sequence number): what an answer to it names.
    pub fn write_related(&self, sample: T, related: SampleIdentity) -> Result<SampleIdentity, DdsError> {
        self.write_with(&sample, Some(related))
    }

    fn write_with(&self, sample: &T, related: Option<SampleIdentity>) -> Result<SampleIdentity, DdsError> {
        match self.publish(sample, related) {
            Ok(written) => Ok(written),
            Err(refusal) => {
                Counters::bump(&self.counters.write_errors);
                let source = match refusal {
                    Refusal::Full => WriteError::HistoryFull { depth: 0 },
                    Refusal::Failed(e) => e,
                };
                Err(DdsError::Write { topic: self.topic.clone(), source })
            }
        }
    }

    /// Publishes `sample`, never waiting: a full keep-all history drops it. No allocation. For
    /// stream threads.
    pub fn try_write(&self, sample: T) -> Result<(), WriteRefused> {
        self.refused(self.publish(&sample, None))
    }

    fn refused(&self, published: Result<SampleIdentity, Refusal>) -> Result<(), WriteRefused> {
        match published {
            Ok(_) => Ok(()),
            Err(Refusal::Full) => {
                Counters::bump(&self.counters.dropped);
                Err(WriteRefused::WindowFull)
            }
            Err(Refusal::Failed(_)) => {
                Counters::bump(&self.counters.write_errors);
                Err(WriteRefused::Failed)
            }
        }
    }

    /// Its RTPS GUID in wire order (prefix 12 bytes, entity key 3, entity kind 1): the GID
    /// ROS 2 names it by.
    pub fn guid(&self) -> [u8; 16] {
        self.guid
    }

    /// Whether every reliable reader matched has acknowledged every sample written so far;
    /// waits until they have: bring a timeout. Best effort: at once.
    pub async fn acknowledged(&self) -> Result<bool, DdsError> {
        struct Waiting<'a>(&'a Shared);
        impl Drop for Waiting<'_> {
            fn drop(&mut self) {
                self.0.ack_waiters.fetch_sub(1, Ordering::Relaxed);
            }
        }
        self.shared.ack_waiters.fetch_add(1, Ordering::Relaxed);
        let _waiting = Waiting(&self.shared);
        loop {
            let notified = self.shared.acknowledgements.notified();
            let mut notified = std::pin::pin!(notified);
            notified.as_mut().enable();
            if self.shared.lock().core.writer_acknowledged(self.id) != Some(false) {
                return Ok(true);
            }
            notified.await;
        }
    }

    /// Readers of this topic matched now.
    pub fn matched_readers(&self) -> usize {
        self.shared.lock().core.matched_readers(self.id).count()
    }

    /// Whether the reader whose GUID (wire order) is `reader` is matched now: a reply to it
    /// written before would be lost (volatile).
    pub fn reader_matched(&self, reader: [u8; 16]) -> bool {
        self.shared.lock().core.matched_readers(self.id).any(|g| g.to_bytes() == reader)
    }

    /// Readers on this topic that cannot match this writer (another type, or QoS that do not
    /// match), with the reason.
    pub fn incompatible_readers(&self) -> Vec<crate::Incompatible> {
        self.shared.lock().incompatible.get(&self.id).cloned().unwrap_or_default()
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

impl Writer<RawSample> {
    /// Publishes a recorded payload (encapsulation header with its option bytes, body) byte for
    /// byte, never waiting, as [`try_write`](Self::try_write): what `replay --as-device` sends.
    pub fn try_write_payload(&self, payload: &[u8]) -> Result<(), WriteRefused> {
        self.refused(self.publish_payload(payload, None))
    }
}

impl<T: CdrType + 'static> Drop for Writer<T> {
    /// The writer is deleted and its removal announced.
    fn drop(&mut self) {
        let now = robowire_rt::now();
        let mut st = self.shared.lock();
        st.incompatible.remove(&self.id);
        st.core.delete_endpoint(now, self.id);
        self.shared.settle(&mut st, now);
    }
}
