//! The HG `BmsState_` codec against Unitree's own IDL class serialized by CycloneDDS' Python
//! binding (CPython 3.10, `robowire_fixtures::peers`; gated like every interop test): the same
//! bytes in each encoding the binding writes, and the same fields read back.

use std::path::Path;
use std::process::Command;

use robowire_core::cdr::{CdrEncoding, CdrType};
use serde_json::Value;
use unitree_proto::bms::HgBmsState;

fn hex(text: &str) -> Vec<u8> {
    (0..text.len()).step_by(2).map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap()).collect()
}

fn u64s(value: &Value) -> Vec<u64> {
    value.as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect()
}

#[test]
fn unitree_bms_state_serialized_by_cyclonedds_is_our_bytes() {
    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        return;
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/interop/hg_bms_state.py");
    let out = Command::new(python).arg(script).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let vendor: Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    let f = &vendor["fields"];

    let mut ours = HgBmsState::default();
    ours.version_high = 1;
    ours.version_low = 2;
    ours.fn_ = 3;
    ours.cell_vol = std::array::from_fn(|i| (3300 + i as u16).into());
    ours.bmsvoltage = [50000, 50001, 50002].map(Into::into);
    ours.current = (-2345).into();
    ours.soc = 87;
    ours.soh = 99;
    ours.temperature = std::array::from_fn(|i| (20 + i as i16).into());
    ours.cycle = 321.into();
    ours.manufacturer_date = 0x2405.into();
    ours.bmsstate = [1, 2, 3, 4, 5].map(Into::into);
    ours.reserve = [6, 7, 8].map(Into::into);
    assert_eq!(u64s(&f["cell_vol"]), ours.cell_vol.map(|v| u64::from(v.get())));

    let mut body = [0u8; 164];
    assert_eq!(ours.encode_body(&mut body), Ok(164));
    let mut checked = 0;
    for (key, encoding) in [("xcdr1", CdrEncoding::Xcdr1), ("xcdr2", CdrEncoding::Xcdr2)] {
        let Some(payload) = vendor[key].as_str().map(hex) else { continue };
        assert_eq!(payload[..4], encoding.header(), "{key}: the encapsulation header");
        assert_eq!(payload[4..], body, "{key}: Unitree's bytes are ours");
        assert_eq!(HgBmsState::decode_body(encoding, &payload[4..]).unwrap(), ours, "{key}");
        checked += 1;
    }
    assert!(checked >= 1, "no payload from the binding: {vendor}");
}
