//! Checks shared by the fuzz target (`fuzz/`) and the seed-replay test. Not stable API.
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

/// The vendor call a fixture's `api` text names: `HighLevel.move(0.5, -0.25, 1.5)` gives
/// `("move", [0.5, -0.25, 1.5, 0.0], 3)`; `nan` is NaN. `None` if the text names no call.
pub fn vendor_call(api: &str) -> Option<(&str, [f32; 4], usize)> {
    let call = api.split_once("HighLevel.").map(|(_, c)| c).or_else(|| api.split_once("LowLevel.").map(|(_, c)| c))?;
    let (name, rest) = call.split_once('(')?;
    let (inside, _) = rest.split_once(')')?;
    let mut args = [0.0f32; 4];
    let mut n = 0;
    if name != "sendMotorCmd" {
        for arg in inside.split(',').map(str::trim).filter(|a| !a.is_empty()) {
            *args.get_mut(n)? = if arg == "nan" { f32::NAN } else { arg.parse().ok()? };
            n += 1;
        }
    }
    Some((name, args, n))
}

/// The motor command of a fixture's `sendMotorCmd` call, built from the call's description.
pub fn fixture_motor_command(api: &str) -> Option<crate::udp::MotorCommand> {
    use zerocopy::little_endian::F32;
    if api.contains("demo-like stand pose") {
        return Some(crate::udp::MotorCommand::pd_hold([[0.0; 4], [0.8; 4], [-1.5; 4]], [80.0; 3], [1.0; 3]));
    }
    if !api.contains("field k>=3 leg j = 10*(k+1)+j+0.5") {
        return None;
    }
    // Field k, leg j: positions 0.10 + 0.01 j, 1.00 + 0.01 j, -(1.00 + 0.01 j); the rest 10 (k + 1) + j + 0.5.
    let value = |k: usize, j: usize| -> f32 {
        match k {
            0 => [0.10, 0.11, 0.12, 0.13][j],
            1 => [1.00, 1.01, 1.02, 1.03][j],
            2 => [-1.00, -1.01, -1.02, -1.03][j],
            _ => 10.0 * (k as f32 + 1.0) + j as f32 + 0.5,
        }
    };
    let arrays = |base: usize| -> [[F32; 4]; 3] {
        core::array::from_fn(|i| core::array::from_fn(|j| F32::new(value(base + i, j))))
    };
    Some(crate::udp::MotorCommand {
        q_des: arrays(0),
        qd_des: arrays(3),
        kp: arrays(6),
        kd: arrays(9),
        tau_ff: arrays(12),
    })
}
