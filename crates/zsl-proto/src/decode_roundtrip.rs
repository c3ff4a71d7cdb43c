//! Decode round trips, the property the fuzz target (`fuzz/`) and xtask's seed replay check
//! (feature `fuzzing`: internal, not public API).
//!
//! Every ZSL-1 decoder runs on the same bytes. It panics (what a fuzzer reports) if a decoder
//! panics, if anything decoded does not re-encode to exactly those bytes, or if lenient decoding
//! does not overwrite exactly the prefix it was given.

use crate::udp::{DatagramError, HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState};

/// All ZSL-1 datagram decoders on `data`.
pub fn datagram_decode(data: &[u8]) {
    if let Ok((command, model)) = HighLevelCommand::decode(data) {
        assert_eq!(&command.encode(model)[..], data);
    }
    if let Ok((command, model)) = LowLevelCommand::decode(data) {
        assert_eq!(&command.encode(model)[..], data);
    }
    if let Ok(state) = HighLevelState::decode_strict(data) {
        assert_eq!(&state.encode()[..], data);
    }
    if let Ok(state) = LowLevelState::decode_strict(data) {
        assert_eq!(&state.encode()[..], data);
    }
    let mut high = HighLevelState::default();
    let before = high.encode();
    match high.update_lenient(data) {
        Ok(update) => {
            let after = high.encode();
            assert_eq!(&after[..data.len()], data);
            assert_eq!(&after[data.len()..], &before[data.len()..], "lenient decoding touched bytes it was not given");
            assert_eq!((update.len, update.short), (data.len(), data.len() < HighLevelState::LEN));
        }
        Err(e) => assert_eq!(e, DatagramError::TooLong { max: HighLevelState::LEN, found: data.len() }),
    }
    let mut low = LowLevelState::default();
    match low.update_lenient(data) {
        Ok(update) => {
            assert_eq!(&low.encode()[..data.len()], data);
            assert_eq!(update.header_ok, low.has_motor_data());
        }
        Err(e) => assert_eq!(e, DatagramError::TooLong { max: LowLevelState::LEN, found: data.len() }),
    }
}
