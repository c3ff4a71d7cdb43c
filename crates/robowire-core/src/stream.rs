//! Incremental decoding of unframed byte streams (UARTs).

/// What a stream decoder has seen so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DecoderCounters {
    /// Frames accepted.
    pub frames: u64,
    /// Bytes dropped while searching for a frame start, including the first byte of every
    /// rejected candidate.
    pub skipped_bytes: u64,
    /// Candidates that started with a valid frame ID but failed a plausibility check.
    pub rejected_candidates: u64,
}

/// The result of one [`StreamDecoder::decode`] call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[must_use]
pub struct DecodeStep<F> {
    /// Leading bytes of the input the decoder is done with: skipped bytes plus the frame, if
    /// any. The caller drops them; they are never shown to the decoder again.
    pub consumed: usize,
    /// The frame that ended at `consumed`, or `None` when the rest of the input is the start of
    /// a candidate that needs more bytes (or the input is exhausted).
    pub frame: Option<F>,
}

impl<F> DecodeStep<F> {
    /// A frame was found; `consumed` counts the skipped bytes before it and the frame itself.
    #[inline]
    pub fn frame(consumed: usize, frame: F) -> Self {
        Self { consumed, frame: Some(frame) }
    }

    /// No frame yet: `consumed` leading bytes were skipped, the rest must be shown again with
    /// more bytes appended.
    #[inline]
    pub fn need_more(consumed: usize) -> Self {
        Self { consumed, frame: None }
    }
}

/// A sans-IO decoder for a stream protocol without framing (tokio-modbus RTU style).
///
/// # Contract
///
/// `decode(input)` returns a [`DecodeStep`] with `consumed <= input.len()`.
/// - With a frame: `input[..consumed]` is skipped bytes followed by the frame.
/// - Without: `input[consumed..]` is shorter than [`MAX_FRAME_LEN`](Self::MAX_FRAME_LEN) and is
///   a plausible prefix of a frame; the caller shows it again with more bytes appended.
///   Partial input is never rejected for being partial, only for content that is already wrong.
///
/// Bytes are counted in [`DecoderCounters`] exactly once, when they are consumed, so calling
/// again with the same pending prefix never double-counts. `decode` never panics, whatever the
/// input.
pub trait StreamDecoder {
    /// What the decoder yields.
    type Frame;
    /// Longest frame in bytes. A buffer at least this long always makes progress.
    const MAX_FRAME_LEN: usize;
    /// Looks for the next frame at the start of `input`.
    fn decode(&mut self, input: &[u8]) -> DecodeStep<Self::Frame>;
    /// Counters since the decoder was made.
    fn counters(&self) -> DecoderCounters;
}

/// The bytes one decoding step consumed ([`FrameBuffer::next_frame_seen`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Consumed<'a> {
    /// Bytes skipped while searching (noise, rejected candidates' first bytes).
    pub skipped: &'a [u8],
    /// The frame's bytes; empty when the step found none.
    pub frame: &'a [u8],
}

/// A fixed-capacity byte buffer in front of a [`StreamDecoder`]: push bytes, pop frames.
///
/// Transports read straight into [`spare_mut`](Self::spare_mut) and [`commit`](Self::commit)
/// what arrived; there is no copy and no allocation. `N` must be at least the decoder's
/// [`MAX_FRAME_LEN`](StreamDecoder::MAX_FRAME_LEN) (checked at compile time).
#[derive(Debug, Clone)]
pub struct FrameBuffer<D, const N: usize> {
    decoder: D,
    buf: [u8; N],
    start: usize,
    end: usize,
}

impl<D: StreamDecoder, const N: usize> FrameBuffer<D, N> {
    /// An empty buffer in front of `decoder`.
    pub fn new(decoder: D) -> Self {
        const {
            assert!(N >= D::MAX_FRAME_LEN, "FrameBuffer capacity below the decoder's MAX_FRAME_LEN");
            assert!(N > 0);
        }
        Self { decoder, buf: [0; N], start: 0, end: 0 }
    }

    /// Free space at the end of the buffer, after moving pending bytes to the front if needed.
    /// Empty only when `N` bytes are pending, which a conforming decoder never leaves.
    pub fn spare_mut(&mut self) -> &mut [u8] {
        if self.end == N && self.start > 0 {
            self.buf.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
        }
        &mut self.buf[self.end..]
    }

    /// Marks `n` bytes written into [`spare_mut`](Self::spare_mut) as received.
    /// `n` larger than the spare space is clamped.
    pub fn commit(&mut self, n: usize) {
        self.end = (self.end + n).min(N);
    }

    /// Copies as much of `bytes` as fits and returns how many bytes were taken.
    pub fn push(&mut self, bytes: &[u8]) -> usize {
        let spare = self.spare_mut();
        let n = bytes.len().min(spare.len());
        spare[..n].copy_from_slice(&bytes[..n]);
        self.commit(n);
        n
    }

    /// The next complete frame among the pending bytes, if there is one.
    pub fn next_frame(&mut self) -> Option<D::Frame> {
        if self.start == self.end {
            return None;
        }
        let step = self.decoder.decode(&self.buf[self.start..self.end]);
        self.start = (self.start + step.consumed).min(self.end);
        if self.start == self.end {
            self.start = 0;
            self.end = 0;
        }
        step.frame
    }

    /// As [`next_frame`](Self::next_frame), showing `seen` the bytes the step consumed: the ones
    /// skipped before a frame (or without one), then the frame's own, either possibly empty. For a
    /// tap that records the frames as they were on the line and the noise between them.
    pub fn next_frame_seen(&mut self, seen: impl FnOnce(Consumed<'_>)) -> Option<D::Frame> {
        if self.start == self.end {
            return None;
        }
        let skipped_before = self.decoder.counters().skipped_bytes;
        let step = self.decoder.decode(&self.buf[self.start..self.end]);
        let consumed = step.consumed.min(self.end - self.start);
        let skipped = usize::try_from(self.decoder.counters().skipped_bytes.saturating_sub(skipped_before))
            .map_or(consumed, |n| n.min(consumed));
        let bytes = &self.buf[self.start..self.start + consumed];
        let frame_len = if step.frame.is_some() { consumed - skipped } else { 0 };
        if consumed > 0 {
            seen(Consumed { skipped: &bytes[..consumed - frame_len], frame: &bytes[consumed - frame_len..] });
        }
        self.start += consumed;
        if self.start == self.end {
            self.start = 0;
            self.end = 0;
        }
        step.frame
    }

    /// Feeds all of `bytes`, calling `on_frame` for every frame completed on the way.
    pub fn push_all(&mut self, bytes: &[u8], on_frame: impl FnMut(D::Frame)) {
        self.push_all_by(bytes, Self::next_frame, on_frame);
    }

    /// As [`push_all`](Self::push_all), showing `seen` the bytes each step consumed
    /// ([`next_frame_seen`](Self::next_frame_seen)).
    pub fn push_all_seen(&mut self, bytes: &[u8], mut seen: impl FnMut(Consumed<'_>), on_frame: impl FnMut(D::Frame)) {
        self.push_all_by(bytes, |rx| rx.next_frame_seen(&mut seen), on_frame);
    }

    fn push_all_by(
        &mut self,
        mut bytes: &[u8],
        mut next_frame: impl FnMut(&mut Self) -> Option<D::Frame>,
        mut on_frame: impl FnMut(D::Frame),
    ) {
        loop {
            let taken = self.push(bytes);
            bytes = &bytes[taken..];
            let mut progressed = taken > 0;
            while let Some(frame) = next_frame(self) {
                on_frame(frame);
                progressed = true;
            }
            if bytes.is_empty() {
                return;
            }
            if !progressed && self.pending().len() == N {
                // Only a decoder that breaks its contract gets here: drop the oldest byte
                // rather than spin.
                self.start += 1;
            }
        }
    }

    /// Bytes received but not yet consumed: the start of an incomplete candidate.
    pub fn pending(&self) -> &[u8] {
        &self.buf[self.start..self.end]
    }

    /// Drops the pending bytes (after a reconnect, say). They are not counted as skipped.
    pub fn clear(&mut self) {
        self.start = 0;
        self.end = 0;
    }

    /// The decoder's counters.
    pub fn counters(&self) -> DecoderCounters {
        self.decoder.counters()
    }

    /// The decoder.
    pub fn decoder(&self) -> &D {
        &self.decoder
    }

    /// The decoder, mutably (to change its configuration).
    pub fn decoder_mut(&mut self) -> &mut D {
        &mut self.decoder
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames are `[0x55, len, payload...]` with len ≤ 3; anything else is skipped.
    #[derive(Default)]
    struct Lv {
        counters: DecoderCounters,
    }

    impl StreamDecoder for Lv {
        type Frame = (usize, [u8; 3]);
        const MAX_FRAME_LEN: usize = 5;
        fn decode(&mut self, input: &[u8]) -> DecodeStep<Self::Frame> {
            let mut i = 0;
            while i < input.len() {
                if input[i] != 0x55 {
                    i += 1;
                    continue;
                }
                let Some(&len) = input.get(i + 1) else { break };
                if len > 3 {
                    self.counters.rejected_candidates += 1;
                    i += 1;
                    continue;
                }
                let len = usize::from(len);
                let Some(payload) = input.get(i + 2..i + 2 + len) else { break };
                let mut out = [0; 3];
                out[..len].copy_from_slice(payload);
                self.counters.skipped_bytes += i as u64;
                self.counters.frames += 1;
                return DecodeStep::frame(i + 2 + len, (len, out));
            }
            self.counters.skipped_bytes += i as u64;
            DecodeStep::need_more(i)
        }
        fn counters(&self) -> DecoderCounters {
            self.counters
        }
    }

    #[test]
    fn frames_split_across_pushes_and_compaction() {
        let stream = [0x55, 2, 9, 8, 0x00, 0x55, 9, 0x55, 0, 0x55, 3, 1, 2, 3];
        for chunk in 1..stream.len() {
            let mut fb: FrameBuffer<Lv, 5> = FrameBuffer::new(Lv::default());
            let mut frames = [(0, [0; 3]); 3];
            let mut n = 0;
            for part in stream.chunks(chunk) {
                fb.push_all(part, |f| {
                    frames[n] = f;
                    n += 1;
                });
            }
            assert_eq!(n, 3, "chunk size {chunk}");
            assert_eq!(frames, [(2, [9, 8, 0]), (0, [0; 3]), (3, [1, 2, 3])]);
            let c = fb.counters();
            // 0x00, and the 0x55 of the rejected candidate.
            assert_eq!((c.frames, c.skipped_bytes, c.rejected_candidates), (3, 3, 1));
            assert!(fb.pending().is_empty());
        }
    }

    #[test]
    fn pending_prefix_is_kept_and_not_counted() {
        let mut fb: FrameBuffer<Lv, 8> = FrameBuffer::new(Lv::default());
        assert_eq!(fb.push(&[0x01, 0x55, 3, 1]), 4);
        assert_eq!(fb.next_frame(), None);
        assert_eq!(fb.next_frame(), None);
        assert_eq!(fb.pending(), &[0x55, 3, 1]);
        assert_eq!(fb.counters().skipped_bytes, 1);
        fb.clear();
        assert!(fb.pending().is_empty());
    }
}
