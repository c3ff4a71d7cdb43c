//! Unitree golden vectors (`fixtures/unitree/vectors.json`), produced by Unitree's own SDK and
//! cyclonedds: struct image byte-exact both ways, CRC equal, CDR byte-exact both ways, JSON
//! fields equal. Vendor data: never rewritten.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;
use unitree_proto::{CdrEncoding, LowCmd, LowState, Message};

use super::{Outcome, to_json};
use crate::{hex_decode, hex_encode, workspace_root};

/// The Unitree vector file.
pub fn vectors_path() -> PathBuf {
    workspace_root().join("fixtures/unitree/vectors.json")
}

/// Loads the vector file.
pub fn load(path: &Path) -> anyhow::Result<Value> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
}

fn str_of<'a>(v: &'a Value, key: &str) -> anyhow::Result<&'a str> {
    v[key].as_str().with_context(|| format!("vector field {key:?} missing"))
}

/// Whether two JSON values say the same: the same keys and lengths, numbers equal as `f32`
/// (the vectors write each float's exact value, robowire its shortest text), strings equal.
pub(crate) fn same_fields(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same_fields(v, w)))
        }
        (Value::Array(x), Value::Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(v, w)| same_fields(v, w)),
        (Value::Number(x), Value::Number(y)) => match (x.as_f64(), y.as_f64()) {
            (Some(x), Some(y)) => x as f32 == y as f32 || x == y,
            _ => false,
        },
        (x, y) => x == y,
    }
}

/// A message vector: fields → image, image → fields, CRC.
fn check_message<M>(vector: &Value) -> anyhow::Result<Vec<String>>
where
    M: Message + PartialEq + core::fmt::Debug + Serialize + DeserializeOwned,
{
    let mut problems = Vec::new();
    let packed = hex_decode(str_of(vector, "packed_hex")?)?;
    let crc = vector["crc"].as_u64().context("crc")?;
    match serde_json::from_value::<M>(vector["fields"].clone()) {
        Ok(message) => {
            let image = message.sealed();
            if image.as_bytes() != packed.as_slice() {
                problems.push(format!("fields encode to {} …", &hex_encode(image.as_bytes())[..64]));
            }
            if u64::from(message.crc()) != crc {
                problems.push(format!("CRC 0x{:08x}, the vector says 0x{crc:08x}", message.crc()));
            }
        }
        Err(e) => problems.push(format!("fields do not convert: {e}")),
    }
    match M::decode_image(&packed) {
        Ok(decoded) => {
            if !same_fields(&to_json(&decoded)?, &vector["fields"]) {
                problems.push("the image decodes to other fields".into());
            }
        }
        Err(e) => problems.push(format!("the image does not decode: {}", e.without_message())),
    }
    Ok(problems)
}

/// A CDR vector: its source message encodes to the payload, and the payload decodes to it.
fn check_cdr<M>(vector: &Value, source: &Value) -> anyhow::Result<Vec<String>>
where
    M: Message + PartialEq + core::fmt::Debug + DeserializeOwned,
{
    let mut problems = Vec::new();
    let payload = hex_decode(str_of(vector, "cdr_hex")?)?;
    let encoding = CdrEncoding::from_header(payload.get(..4).context("short payload")?.try_into()?)
        .context("unknown encapsulation in vector")?;
    let message: M = serde_json::from_value(source["fields"].clone()).context("source fields")?;
    let mut out = vec![0u8; M::cdr_len(encoding)];
    message.encode_cdr(encoding, &mut out)?;
    if out != payload {
        problems.push(format!("encodes to {} bytes that differ", out.len()));
    }
    match M::decode_cdr(&payload) {
        Ok((decoded, found)) if decoded == message && found == encoding => {}
        Ok(_) => problems.push("decodes to another message".into()),
        Err(e) => problems.push(format!("does not decode: {}", e.without_message())),
    }
    if M::DDS_TYPE_NAME != str_of(vector, "dds_type_name")? || M::TOPIC != str_of(vector, "topic")? {
        problems.push("type name or topic differs".into());
    }
    Ok(problems)
}

/// Runs every Unitree vector.
pub fn check(path: &Path) -> anyhow::Result<Vec<Outcome>> {
    let vectors = load(path)?;
    let mut outcomes = Vec::new();
    let list = |key: &str| vectors[key].as_array().cloned().with_context(|| format!("{key} missing"));
    for vector in list("lowcmd")? {
        outcomes.push(Outcome::new(str_of(&vector, "name")?, check_message::<LowCmd>(&vector)?));
    }
    for vector in list("lowstate")? {
        outcomes.push(Outcome::new(str_of(&vector, "name")?, check_message::<LowState>(&vector)?));
    }
    let lowcmd = list("lowcmd")?;
    let lowstate = list("lowstate")?;
    for vector in list("cdr")? {
        let name = str_of(&vector, "name")?;
        let source_name = str_of(&vector, "source_vector")?;
        let find = |list: &[Value]| list.iter().find(|v| v["name"] == source_name).cloned();
        let problems = if let Some(source) = find(&lowcmd) {
            check_cdr::<LowCmd>(&vector, &source)?
        } else if let Some(source) = find(&lowstate) {
            check_cdr::<LowState>(&vector, &source)?
        } else {
            bail!("cdr vector {name}: no source vector {source_name}");
        };
        outcomes.push(Outcome::new(format!("cdr {name}"), problems));
    }
    for vector in list("crc_core")? {
        let words: Vec<u8> = vector["words_hex"]
            .as_array()
            .context("words_hex")?
            .iter()
            .map(|w| {
                let text = w.as_str().context("word")?.trim_start_matches("0x");
                Ok(u32::from_str_radix(text, 16)?.to_le_bytes())
            })
            .collect::<anyhow::Result<Vec<_>>>()?
            .concat();
        let expected = vector["crc"].as_u64().context("crc")?;
        let got = unitree_proto::crc::crc32_words(&words).map(u64::from);
        let problems =
            if got == Some(expected) { Vec::new() } else { vec![format!("CRC {got:?}, expected {expected:#010x}")] };
        outcomes.push(Outcome::new(format!("crc {}", str_of(&vector, "name")?), problems));
    }
    Ok(outcomes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_compare_as_f32() {
        let exact: Value = serde_json::from_str(r#"{"q":[0.4000000059604645,"NaN"],"mode":1}"#).unwrap();
        let shortest: Value = serde_json::from_str(r#"{"q":[0.4,"NaN"],"mode":1}"#).unwrap();
        assert!(same_fields(&exact, &shortest));
        let other: Value = serde_json::from_str(r#"{"q":[0.41,"NaN"],"mode":1}"#).unwrap();
        assert!(!same_fields(&exact, &other));
        let missing: Value = serde_json::from_str(r#"{"q":[0.4,"NaN"]}"#).unwrap();
        assert!(!same_fields(&exact, &missing));
    }

    /// Every vector of Unitree's SDK and cyclonedds, under `cargo test`.
    #[test]
    fn unitree_vectors_pass() {
        let outcomes = check(&vectors_path()).unwrap();
        assert_eq!(outcomes.len(), 11 + 10 + 8 + 4);
        for outcome in outcomes {
            assert!(outcome.problems.is_empty(), "{}: {:?}", outcome.name, outcome.problems);
        }
    }
}
