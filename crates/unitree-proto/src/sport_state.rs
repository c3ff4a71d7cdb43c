//! The Go2's sport-mode state, `unitree_go::msg::dds_::SportModeState_` on `rt/sportmodestate`
//! (what Unitree's sport service publishes while it drives the robot: odometry, body height,
//! gait, foot forces, the planned path). No CRC.
//!
//! The struct image is not the CDR body: `mode` follows the IMU's `temperature` byte directly in
//! CDR (a nested struct adds no alignment) but after 3 bytes of C padding in the image, and XCDR2
//! puts a DHEADER in front of `path_point` (an array of structs). The field table is walked by
//! the CDR rules at compile time into copy plans ([`crate::plan`]), as for `LowState_`: the body
//! is 512 bytes in XCDR1 (3 block copies), 516 in XCDR2 (4 copies and the DHEADER).
//!
//! ```
//! use unitree_proto::sport_state::SportModeState;
//! use robowire_core::cdr::{CdrEncoding, CdrType};
//!
//! let mut state = SportModeState::default();
//! state.mode = 1;
//! state.body_height = 0.32.into();
//! state.velocity[0] = 0.5.into();
//! let mut body = [0u8; 516];
//! let n = state.encode_cdr_body(CdrEncoding::Xcdr2, &mut body).unwrap();
//! assert_eq!(n, 516);
//! let back = SportModeState::decode_body(CdrEncoding::Xcdr2, &body[..n]).unwrap();
//! assert_eq!((back.mode, back.body_height.get()), (1, 0.32));
//! // What a DDS writer sends: XCDR1, 512 bytes.
//! assert_eq!(state.encode_body(&mut body), Ok(512));
//! ```

use robowire_core::BufferTooSmall;
use robowire_core::cdr::{CdrEncoding, CdrType};
use zerocopy::little_endian::{F32, I16, I32, U32};
use zerocopy::{FromZeros, IntoBytes};

use crate::DecodeError;
use crate::go2::{IMU_STATE_LAYOUT, ImuState};
use crate::layout::{idl_struct, padding_count, padding_mask};
use crate::plan::{CdrPlan, cdr_plan};

/// The topic.
pub const SPORT_MODE_STATE_TOPIC: &str = "rt/sportmodestate";

idl_struct! {
    /// A time stamp, `unitree_go::msg::dds_::TimeSpec_`, 8 bytes.
    pub struct TimeSpec as "TimeSpec_" in TIME_SPEC_LAYOUT {
        /// Seconds.
        pub sec: I32 => scalar(I32),
        /// Nanoseconds within the second.
        pub nanosec: U32 => scalar(U32),
    }
}

idl_struct! {
    /// One point of the path the sport service plans, `unitree_go::msg::dds_::PathPoint_`, 28
    /// bytes.
    pub struct PathPoint as "PathPoint_" in PATH_POINT_LAYOUT {
        /// Time from the path's start, s.
        pub t_from_start: F32 => scalar(F32),
        /// Position x, m.
        pub x: F32 => scalar(F32),
        /// Position y, m.
        pub y: F32 => scalar(F32),
        /// Heading, rad.
        pub yaw: F32 => scalar(F32),
        /// Velocity x, m/s.
        pub vx: F32 => scalar(F32),
        /// Velocity y, m/s.
        pub vy: F32 => scalar(F32),
        /// Yaw rate, rad/s.
        pub vyaw: F32 => scalar(F32),
    }
}

/// Points in [`SportModeState::path_point`].
pub const PATH_POINT_COUNT: usize = 10;

idl_struct! {
    /// Go2 sport-mode state, `unitree_go::msg::dds_::SportModeState_`, 516-byte struct image.
    /// Field meanings are Unitree's; units are given where Unitree's field names make them clear.
    pub struct SportModeState as "SportModeState_" in SPORT_MODE_STATE_LAYOUT {
        /// Time stamp.
        pub stamp: TimeSpec => nested(TIME_SPEC_LAYOUT),
        /// Unitree's error code.
        pub error_code: U32 => scalar(U32),
        /// IMU (the `IMUState_` of `LowState_`).
        pub imu_state: ImuState => nested(IMU_STATE_LAYOUT),
        /// Unitree's sport mode number.
        pub mode: u8 => scalar(U8),
        _pad0: [u8; 3] => pad,
        /// Unitree's progress of the motion under way.
        pub progress: F32 => scalar(F32),
        /// Unitree's gait number.
        pub gait_type: u8 => scalar(U8),
        _pad1: [u8; 3] => pad,
        /// Foot raise height, m.
        pub foot_raise_height: F32 => scalar(F32),
        /// Position (x, y, z), m.
        pub position: [F32; 3] => array(F32),
        /// Body height, m.
        pub body_height: F32 => scalar(F32),
        /// Velocity (x, y, z), m/s.
        pub velocity: [F32; 3] => array(F32),
        /// Yaw rate, rad/s.
        pub yaw_speed: F32 => scalar(F32),
        /// Unitree's obstacle ranges, four of them.
        pub range_obstacle: [F32; 4] => array(F32),
        /// Foot force, raw `int16`, one per foot.
        pub foot_force: [I16; 4] => array(I16),
        /// Foot positions relative to the body, (x, y, z) per foot, m.
        pub foot_position_body: [F32; 12] => array(F32),
        /// Foot velocities relative to the body, (x, y, z) per foot, m/s.
        pub foot_speed_body: [F32; 12] => array(F32),
        /// The planned path.
        pub path_point: [PathPoint; PATH_POINT_COUNT] => nested_array(PATH_POINT_LAYOUT),
    }
}

/// Image length, bytes.
const LEN: usize = size_of::<SportModeState>();
const MASK: [u8; LEN] = padding_mask::<LEN, { padding_count(&SPORT_MODE_STATE_LAYOUT) }>(&SPORT_MODE_STATE_LAYOUT);

const _: () = {
    use core::mem::offset_of;
    assert!(size_of::<TimeSpec>() == 8);
    assert!(size_of::<PathPoint>() == 28);
    assert!(LEN == 516);
    assert!(offset_of!(SportModeState, imu_state) == 12);
    assert!(offset_of!(SportModeState, mode) == 68);
    assert!(offset_of!(SportModeState, progress) == 72);
    assert!(offset_of!(SportModeState, gait_type) == 76);
    assert!(offset_of!(SportModeState, foot_raise_height) == 80);
    assert!(offset_of!(SportModeState, foot_force) == 132);
    assert!(offset_of!(SportModeState, path_point) == 236);
    assert!(SportModeState::XCDR1.body_len == 512);
    assert!(SportModeState::XCDR2.body_len == 516);
};

impl Default for SportModeState {
    /// Every field zero (the IDL default).
    fn default() -> Self {
        Self::new_zeroed()
    }
}

impl SportModeState {
    /// DDS type name on the wire.
    pub const DDS_TYPE_NAME: &'static str = "unitree_go::msg::dds_::SportModeState_";
    /// The XCDR1 copy plan (512-byte body).
    pub const XCDR1: CdrPlan = cdr_plan!(SPORT_MODE_STATE_LAYOUT, false);
    /// The XCDR2 copy plan (516-byte body: `path_point`'s DHEADER).
    pub const XCDR2: CdrPlan = cdr_plan!(SPORT_MODE_STATE_LAYOUT, true);

    /// The copy plan of `encoding`.
    pub const fn cdr_plan(encoding: CdrEncoding) -> &'static CdrPlan {
        match encoding {
            CdrEncoding::Xcdr1 => &Self::XCDR1,
            CdrEncoding::Xcdr2 => &Self::XCDR2,
        }
    }

    fn zero_padding(&mut self) {
        for (byte, mask) in self.as_mut_bytes().iter_mut().zip(MASK) {
            *byte &= mask;
        }
    }

    /// Writes the CDR body in `encoding` (no encapsulation header) into `out`; its length (512
    /// in XCDR1, 516 in XCDR2).
    pub fn encode_cdr_body(&self, encoding: CdrEncoding, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        let mut image = *self;
        image.zero_padding();
        Self::cdr_plan(encoding).encode_into(image.as_bytes(), out)
    }
}

impl CdrType for SportModeState {
    const TYPE_NAME: &'static str = Self::DDS_TYPE_NAME;
    type Error = DecodeError<()>;

    fn body_len(&self) -> usize {
        Self::XCDR1.body_len
    }

    /// The body in XCDR1 (512 bytes).
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        self.encode_cdr_body(CdrEncoding::Xcdr1, out)
    }

    /// Exactly 512 bytes in XCDR1, 516 in XCDR2 (whose `path_point` DHEADER must say 280);
    /// alignment bytes are ignored.
    fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, DecodeError<()>> {
        let mut state = Self::new_zeroed();
        Self::cdr_plan(encoding).decode_from(encoding, body, state.as_mut_bytes())?;
        // Alignment bytes of the body landed on the image's padding.
        state.zero_padding();
        Ok(state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{ArrayHeader, CopyRun};

    #[test]
    fn the_plans_move_mode_by_three_bytes_and_put_a_dheader_before_the_path() {
        assert_eq!(
            SportModeState::XCDR1.runs,
            [
                CopyRun { body: 0, image: 0, len: 65 },
                CopyRun { body: 65, image: 68, len: 1 },
                CopyRun { body: 68, image: 72, len: 444 }
            ]
        );
        assert!(SportModeState::XCDR1.headers.is_empty());
        assert_eq!(
            SportModeState::XCDR2.runs,
            [
                CopyRun { body: 0, image: 0, len: 65 },
                CopyRun { body: 65, image: 68, len: 1 },
                CopyRun { body: 68, image: 72, len: 164 },
                CopyRun { body: 236, image: 236, len: 280 }
            ]
        );
        assert_eq!(SportModeState::XCDR2.headers, [ArrayHeader { at: 232, len: 280, field: "path_point" }]);
    }

    #[test]
    fn fields_land_at_their_cdr_offsets_and_padding_is_zeroed() {
        let mut state = SportModeState::new_zeroed();
        state.imu_state.temperature = 0x41;
        state.mode = 0x5a;
        state.gait_type = 0x3c;
        state.foot_force[3] = (-2).into();
        state.path_point[9].vyaw = 1.5.into();
        state._pad0 = [0xee; 3]; // as a decoder's caller could never make it, but the encoder must not care
        let mut body = [0xffu8; 520];
        assert_eq!(state.encode_cdr_body(CdrEncoding::Xcdr1, &mut body), Ok(512));
        assert_eq!(body[64..69], [0x41, 0x5a, 0, 0, 0]);
        assert_eq!(body[72..76], [0x3c, 0, 0, 0]);
        assert_eq!(body[134..136], (-2i16).to_le_bytes());
        assert_eq!(body[508..512], 1.5f32.to_le_bytes());
        body[66] = 7; // an alignment byte as a writer may leave it
        let mut expected = state;
        expected._pad0 = [0; 3];
        assert_eq!(SportModeState::decode_body(CdrEncoding::Xcdr1, &body[..512]), Ok(expected));

        assert_eq!(state.encode_cdr_body(CdrEncoding::Xcdr2, &mut body), Ok(516));
        assert_eq!(body[232..236], 280u32.to_le_bytes());
        assert_eq!(body[512..516], 1.5f32.to_le_bytes());
        assert_eq!(SportModeState::decode_body(CdrEncoding::Xcdr2, &body[..516]), Ok(expected));
    }

    #[test]
    fn typed_errors() {
        let state = SportModeState::default();
        let mut body = [0u8; 516];
        let n = state.encode_cdr_body(CdrEncoding::Xcdr2, &mut body).unwrap();
        assert_eq!(
            SportModeState::decode_body(CdrEncoding::Xcdr2, &body[..n - 1]),
            Err(DecodeError::CdrLength { encoding: CdrEncoding::Xcdr2, expected: 516, found: 515 })
        );
        // A 516-byte body read as XCDR1, and a 512-byte one as XCDR2: wrong lengths, not misreads.
        assert_eq!(
            SportModeState::decode_body(CdrEncoding::Xcdr1, &body),
            Err(DecodeError::CdrLength { encoding: CdrEncoding::Xcdr1, expected: 512, found: 516 })
        );
        assert_eq!(
            SportModeState::decode_body(CdrEncoding::Xcdr2, &body[..512]),
            Err(DecodeError::CdrLength { encoding: CdrEncoding::Xcdr2, expected: 516, found: 512 })
        );
        body[233] = 2; // 280 is 0x118
        assert_eq!(
            SportModeState::decode_body(CdrEncoding::Xcdr2, &body),
            Err(DecodeError::ArrayHeader { field: "path_point", expected: 280, found: 280 + 256 })
        );
        assert_eq!(
            state.encode_cdr_body(CdrEncoding::Xcdr1, &mut [0u8; 511]),
            Err(BufferTooSmall { needed: 512, available: 511 })
        );
        assert_eq!(state.encode_body(&mut [0u8; 0]), Err(BufferTooSmall { needed: 512, available: 0 }));
    }
}
