//! [`Reader`]: a topic's samples for one task, from a slot the background thread fills.

use std::marker::PhantomData;
use std::sync::Arc;
use std::task::{Context, Poll};

use robowire_core::cdr::CdrType;
use robowire_tap::{Direction, SampleOrigin, Tap};
use rtps_proto::EntityId;
use rtps_proto::participant::Sample as Arrived;

use crate::DdsError;
use crate::driver::Shared;
use crate::sample::{Counters, Sample, SampleIdentity, StatsHandle, TopicStats, decode};
use crate::slot::{Listen, ReaderSlot};

/// Reads `T` from one topic, asynchronously (any executor). Samples whose body does not decode
/// are counted and skipped. As DDS's keep-last history: of the samples that arrived since the last
/// `recv`, the newest `depth` (the QoS's) are kept, delivered oldest first; a keep-last-1 reader
/// gets the newest.
///
/// The participant's background thread puts each sample into this reader's slot and wakes the
/// task waiting in `recv` once; the task decodes it.
pub struct Reader<T: CdrType + 'static> {
    shared: Arc<Shared>,
    slot: Arc<ReaderSlot>,
    id: EntityId,
    guid: [u8; 16],
    topic: String,
    counters: Arc<Counters>,
    last_error: Option<String>,
    tap: Option<Tap>,
    decoded: PhantomData<fn() -> T>,
}

impl<T: CdrType + 'static> std::fmt::Debug for Reader<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Reader").field("topic", &self.topic).field("type", &T::TYPE_NAME).finish_non_exhaustive()
    }
}

impl<T: CdrType + 'static> Reader<T> {
    pub(crate) fn new(
        shared: Arc<Shared>,
        slot: Arc<ReaderSlot>,
        id: EntityId,
        guid: [u8; 16],
        topic: &str,
        counters: Arc<Counters>,
    ) -> Self {
        Self {
            shared,
            slot,
            id,
            guid,
            topic: topic.into(),
            counters,
            last_error: None,
            tap: None,
            decoded: PhantomData,
        }
    }

    /// Hands every sample this reader takes to `tap` as its payload (encapsulation header with
    /// its option bytes, body: decodable or not), with its writer's GUID and source timestamp.
    pub fn set_tap(&mut self, tap: Option<Tap>) {
        self.tap = tap;
    }

    /// The next sample that decodes.
    pub async fn recv(&mut self) -> Result<Sample<T>, DdsError> {
        let sample = std::future::poll_fn(|cx| self.poll_recv(cx)).await;
        Counters::bump(&self.counters.samples);
        Ok(sample)
    }

    fn poll_recv(&mut self, cx: &mut Context<'_>) -> Poll<Sample<T>> {
        loop {
            if let Some(arrived) = self.slot.pop() {
                if let Some(sample) = self.take(arrived) {
                    return Poll::Ready(sample);
                }
                continue;
            }
            // Looked again after the registration: a sample may have arrived in between.
            if self.slot.register(cx.waker()) {
                return Poll::Pending;
            }
        }
    }

    /// Hands every sample that decodes to `on_sample` on the participant's background thread, as it
    /// arrives (as a CycloneDDS listener): no task to wake, no hop. `on_sample` runs without the
    /// participant's lock and may write (to this participant too); it must not block, since the
    /// participant receives nothing else meanwhile. The reader lives until the [`Listener`] is
    /// dropped. Samples kept before the call are handed over at the next arrival.
    pub fn listen(mut self, mut on_sample: impl FnMut(Sample<T>) + Send + 'static) -> Listener
    where
        T: Send,
    {
        let slot = self.slot.clone();
        let listen: Listen = Box::new(move || {
            while let Some(arrived) = self.slot.pop() {
                if let Some(sample) = self.take(arrived) {
                    Counters::bump(&self.counters.samples);
                    on_sample(sample);
                }
            }
        });
        slot.install(listen);
        Listener { slot }
    }

    /// Decodes one arrived sample (counting a failure) and gives its buffer back.
    fn take(&mut self, arrived: Arrived) -> Option<Sample<T>> {
        let info = arrived.info;
        if let Some(tap) = &self.tap {
            let origin = SampleOrigin {
                writer: Some(info.writer.to_bytes()),
                source_unix_ns: info.source_timestamp.and_then(|t| t.to_unix_nanos()),
            };
            tap.record_parts(Direction::Received, &[&arrived.payload], origin);
        }
        let decoded = decode::<T>(&arrived.payload);
        let _ = self.shared.recycled.push(arrived.payload);
        match decoded {
            Ok(value) => Some(Sample {
                value,
                writer: info.writer.to_bytes(),
                sequence: info.sequence.0,
                related: info.related.map(SampleIdentity::of_rtps),
            }),
            Err(failure) => {
                let counter =
                    if failure.checksum { &self.counters.checksum_errors } else { &self.counters.decode_errors };
                Counters::bump(counter);
                self.last_error = Some(failure.reason);
                None
            }
        }
    }

    /// Its RTPS GUID in wire order (prefix 12 bytes, entity key 3, entity kind 1): the GID
    /// ROS 2 names it by.
    pub fn guid(&self) -> [u8; 16] {
        self.guid
    }

    /// Writers of this topic matched now.
    pub fn matched_writers(&self) -> usize {
        self.shared.lock().core.matched_writers(self.id).count()
    }

    /// Writers on this topic that cannot match this reader (another type, or QoS that do not
    /// match: a best-effort writer and this reliable reader, say), with the reason.
    pub fn incompatible_writers(&self) -> Vec<crate::Incompatible> {
        self.shared.lock().incompatible.get(&self.id).cloned().unwrap_or_default()
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

/// A reader whose samples a function takes on the participant's background thread
/// ([`Reader::listen`]); dropping it deletes the reader (not from within the function).
pub struct Listener {
    slot: Arc<ReaderSlot>,
}

impl std::fmt::Debug for Listener {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Listener").finish_non_exhaustive()
    }
}

impl Drop for Listener {
    fn drop(&mut self) {
        // The reader (inside the function) is dropped once the slot's lock is let go: its drop
        // takes the participant's lock.
        let listen = self.slot.uninstall();
        drop(listen);
    }
}

impl<T: CdrType + 'static> Drop for Reader<T> {
    /// The reader is deleted and its removal announced.
    fn drop(&mut self) {
        let now = robowire_rt::now();
        let mut st = self.shared.lock();
        st.readers.remove(&self.id);
        st.incompatible.remove(&self.id);
        st.core.delete_endpoint(now, self.id);
        self.shared.settle(&mut st, now);
    }
}
