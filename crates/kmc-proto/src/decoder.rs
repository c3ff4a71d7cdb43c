//! The incremental stream decoders of spec §6.2 (host side) and §6.3 (device side).

use robowire_core::{DecodeStep, DecoderCounters, StreamDecoder};

use crate::af::Scan;
use crate::{ChassisFrame, DEFAULT_MAX_SPEED_MPS, DecodeError, HostFrame, MAX_FRAME_LEN};

/// The search loop both decoders share: skip non-ID bytes, judge candidates, resync by one byte.
fn decode_with<F>(
    input: &[u8],
    counters: &mut DecoderCounters,
    last_rejection: &mut Option<DecodeError>,
    is_frame_id: fn(u8) -> bool,
    scan: impl Fn(&[u8]) -> Scan<F>,
) -> DecodeStep<F> {
    let mut i = 0;
    while i < input.len() {
        if !is_frame_id(input[i]) {
            i += 1;
            continue;
        }
        match scan(&input[i..]) {
            Scan::Frame(frame, len) => {
                counters.skipped_bytes += i as u64;
                counters.frames += 1;
                return DecodeStep::frame(i + len, frame);
            }
            Scan::Incomplete => break,
            Scan::Reject(e) => {
                counters.rejected_candidates += 1;
                *last_rejection = Some(e);
                i += 1;
            }
        }
    }
    counters.skipped_bytes += i as u64;
    DecodeStep::need_more(i)
}

/// A speed plausibility bound that is not finite and positive.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("a speed bound must be finite and positive, got {bound_mps} m/s")]
pub struct InvalidSpeedBound {
    /// The bound given.
    pub bound_mps: f32,
}

/// Host-side decoder (spec §6.2): finds [`ChassisFrame`]s in the bytes the chassis sends.
///
/// ```
/// use kmc_proto::{ChassisFrame, ChassisFrameDecoder};
/// use robowire_core::FrameBuffer;
///
/// let mut rx: FrameBuffer<ChassisFrameDecoder, 256> = FrameBuffer::new(ChassisFrameDecoder::new());
/// // Noise, then a speed response split in two reads.
/// rx.push_all(&[0x00, 0xb3, 0x00], |_| unreachable!());
/// let mut frames = Vec::new();
/// rx.push_all(&[0x00, 0xa0, 0x3f], |f| frames.push(f));
/// assert!(matches!(frames[..], [ChassisFrame::VehicleSpeed(s)] if s.speed_mps == 1.25));
/// assert_eq!(rx.counters().skipped_bytes, 1);
/// ```
#[derive(Debug, Clone)]
pub struct ChassisFrameDecoder {
    max_speed_mps: f32,
    counters: DecoderCounters,
    last_rejection: Option<DecodeError>,
}

impl Default for ChassisFrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl ChassisFrameDecoder {
    /// A decoder with the default speed bound, [`DEFAULT_MAX_SPEED_MPS`].
    pub fn new() -> Self {
        Self { max_speed_mps: DEFAULT_MAX_SPEED_MPS, counters: DecoderCounters::default(), last_rejection: None }
    }

    /// Sets the plausibility bound: a `0xB3` response with |speed| at or above it is rejected.
    /// The bound must be finite and positive.
    ///
    /// ```
    /// # use kmc_proto::ChassisFrameDecoder;
    /// assert_eq!(ChassisFrameDecoder::new().with_max_speed_mps(5.0).unwrap().max_speed_mps(), 5.0);
    /// assert!(ChassisFrameDecoder::new().with_max_speed_mps(f32::NAN).is_err());
    /// ```
    pub fn with_max_speed_mps(mut self, bound_mps: f32) -> Result<Self, InvalidSpeedBound> {
        if !(bound_mps.is_finite() && bound_mps > 0.0) {
            return Err(InvalidSpeedBound { bound_mps });
        }
        self.max_speed_mps = bound_mps;
        Ok(self)
    }

    /// The speed bound in force, m/s.
    pub fn max_speed_mps(&self) -> f32 {
        self.max_speed_mps
    }

    /// Why the most recent candidate was rejected.
    pub fn last_rejection(&self) -> Option<DecodeError> {
        self.last_rejection
    }
}

impl StreamDecoder for ChassisFrameDecoder {
    type Frame = ChassisFrame;
    const MAX_FRAME_LEN: usize = MAX_FRAME_LEN;

    fn decode(&mut self, input: &[u8]) -> DecodeStep<ChassisFrame> {
        let bound = self.max_speed_mps;
        decode_with(input, &mut self.counters, &mut self.last_rejection, ChassisFrame::is_frame_id, |c| {
            ChassisFrame::scan(c, bound)
        })
    }

    fn counters(&self) -> DecoderCounters {
        self.counters
    }
}

/// Device-side decoder (spec §6.3): finds [`HostFrame`]s in the bytes the host sends.
/// Used by the chassis simulator; any stray `0xB3` is a speed request.
#[derive(Debug, Clone, Default)]
pub struct HostFrameDecoder {
    counters: DecoderCounters,
    last_rejection: Option<DecodeError>,
}

impl HostFrameDecoder {
    /// A new decoder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Why the most recent candidate was rejected.
    pub fn last_rejection(&self) -> Option<DecodeError> {
        self.last_rejection
    }
}

impl StreamDecoder for HostFrameDecoder {
    type Frame = HostFrame;
    const MAX_FRAME_LEN: usize = MAX_FRAME_LEN;

    fn decode(&mut self, input: &[u8]) -> DecodeStep<HostFrame> {
        decode_with(input, &mut self.counters, &mut self.last_rejection, HostFrame::is_frame_id, HostFrame::scan)
    }

    fn counters(&self) -> DecoderCounters {
        self.counters
    }
}
