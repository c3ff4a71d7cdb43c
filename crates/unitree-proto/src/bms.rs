//! The HG robots' battery, `unitree_hg::msg::dds_::BmsState_` on `rt/lf/bmsstate` (the G1
//! publishes it beside `rt/lowstate`). No CRC. Every field is a primitive or an array of one,
//! aligned to its size in the struct image, so the image with its padding zeroed is the CDR body
//! in XCDR1 and XCDR2 alike (checked at compile time from the field table).
//!
//! ```
//! use unitree_proto::bms::HgBmsState;
//! use robowire_core::cdr::{CdrEncoding, CdrType};
//!
//! let mut bms = HgBmsState::default();
//! bms.soh = 99;
//! bms.soc = 87;
//! let mut body = [0u8; 164];
//! let n = bms.encode_body(&mut body).unwrap();
//! assert_eq!(HgBmsState::decode_body(CdrEncoding::Xcdr2, &body[..n]).unwrap().soc, 87);
//! ```

use robowire_core::BufferTooSmall;
use robowire_core::cdr::{CdrEncoding, CdrType};
use zerocopy::little_endian::{I16, I32, U16, U32};
use zerocopy::{FromZeros, IntoBytes};

use crate::DecodeError;
use crate::layout::{idl_struct, padding_count, padding_mask};
use crate::plan::plan_body_len;

/// The topic.
pub const BMS_TOPIC: &str = "rt/lf/bmsstate";

idl_struct! {
    /// HG battery state, `unitree_hg::msg::dds_::BmsState_`, 164 bytes. Field meanings are
    /// Unitree's (its IDL names them; its documents give no units beyond these).
    pub struct HgBmsState as "BmsState_" in HG_BMS_STATE_LAYOUT {
        /// Firmware version, major.
        pub version_high: u8 => scalar(U8),
        /// Firmware version, minor.
        pub version_low: u8 => scalar(U8),
        /// Function word (IDL `fn`).
        pub fn_: u8 => scalar(U8),
        _pad0: [u8; 1] => pad,
        /// Cell voltages, mV.
        pub cell_vol: [U16; 40] => array(U16),
        /// Pack voltages, mV.
        pub bmsvoltage: [U32; 3] => array(U32),
        /// Current, mA (negative: discharging).
        pub current: I32 => scalar(I32),
        /// State of charge, %.
        pub soc: u8 => scalar(U8),
        /// State of health, %.
        pub soh: u8 => scalar(U8),
        /// Temperatures, °C.
        pub temperature: [I16; 12] => array(I16),
        /// Charge cycles.
        pub cycle: U16 => scalar(U16),
        /// Manufacturing date word.
        pub manufacturer_date: U16 => scalar(U16),
        _pad1: [u8; 2] => pad,
        /// Status words.
        pub bmsstate: [U32; 5] => array(U32),
        /// Reserved.
        pub reserve: [U32; 3] => array(U32),
    }
}

/// Image length, bytes (also the CDR body's).
const LEN: usize = size_of::<HgBmsState>();
const MASK: [u8; LEN] = padding_mask::<LEN, { padding_count(&HG_BMS_STATE_LAYOUT) }>(&HG_BMS_STATE_LAYOUT);

// The image is the CDR body in both encodings: the field walk by the CDR rules lands every field
// where the C layout has it, with nothing after the last.
const _: () = {
    assert!(LEN == 164);
    assert!(plan_body_len(&HG_BMS_STATE_LAYOUT, false) == LEN);
    assert!(plan_body_len(&HG_BMS_STATE_LAYOUT, true) == LEN);
    assert!(core::mem::offset_of!(HgBmsState, cell_vol) == 4);
    assert!(core::mem::offset_of!(HgBmsState, current) == 96);
    assert!(core::mem::offset_of!(HgBmsState, temperature) == 102);
    assert!(core::mem::offset_of!(HgBmsState, bmsstate) == 132);
};

impl Default for HgBmsState {
    /// Every field zero.
    fn default() -> Self {
        Self::new_zeroed()
    }
}

impl HgBmsState {
    /// DDS type name on the wire.
    pub const DDS_TYPE_NAME: &'static str = "unitree_hg::msg::dds_::BmsState_";

    fn zero_padding(&mut self) {
        for (byte, mask) in self.as_mut_bytes().iter_mut().zip(MASK) {
            *byte &= mask;
        }
    }
}

impl CdrType for HgBmsState {
    const TYPE_NAME: &'static str = Self::DDS_TYPE_NAME;
    type Error = DecodeError<()>;

    fn body_len(&self) -> usize {
        LEN
    }

    /// The image with its padding zeroed.
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        let available = out.len();
        let dst = out.get_mut(..LEN).ok_or(BufferTooSmall { needed: LEN, available })?;
        let mut image = *self;
        image.zero_padding();
        dst.copy_from_slice(image.as_bytes());
        Ok(LEN)
    }

    /// Exactly 164 bytes in either encoding; alignment bytes are ignored (zeroed).
    fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, DecodeError<()>> {
        if body.len() != LEN {
            return Err(DecodeError::CdrLength { encoding, expected: LEN, found: body.len() });
        }
        let mut state = Self::new_zeroed();
        state.as_mut_bytes().copy_from_slice(body);
        state.zero_padding();
        Ok(state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_land_at_their_cdr_offsets_and_padding_is_zeroed() {
        let mut bms = HgBmsState::new_zeroed();
        bms.soc = 0x5a;
        bms.cycle = 0x1234.into();
        bms.current = (-2000).into();
        let mut body = [0xffu8; 170];
        assert_eq!(bms.encode_body(&mut body), Ok(164));
        assert_eq!((body[3], body[100], body[126], body[127]), (0, 0x5a, 0x34, 0x12));
        assert_eq!(i32::from_le_bytes(body[96..100].try_into().unwrap()), -2000);
        body[3] = 7; // an alignment byte as a writer may leave it
        let back = HgBmsState::decode_body(CdrEncoding::Xcdr1, &body[..164]).unwrap();
        assert_eq!(back, bms);
        assert!(matches!(
            HgBmsState::decode_body(CdrEncoding::Xcdr1, &body[..163]),
            Err(DecodeError::CdrLength { expected: 164, found: 163, .. })
        ));
        assert!(bms.encode_body(&mut [0u8; 10]).is_err());
    }
}
