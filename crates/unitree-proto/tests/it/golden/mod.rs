//! The golden Unitree vectors (`fixtures/unitree/vectors.json`), shared by the tests that read
//! them.

use serde_json::Value;

/// The parsed vectors file.
pub(crate) fn vectors() -> Value {
    serde_json::from_str(include_str!("../../../../../fixtures/unitree/vectors.json")).unwrap()
}

/// The vendor's fields of the `lowcmd` or `lowstate` vector named `name`.
pub(crate) fn source_fields(vectors: &Value, name: &str) -> Value {
    ["lowcmd", "lowstate"]
        .iter()
        .flat_map(|k| vectors[k].as_array().unwrap())
        .find(|v| v["name"] == name)
        .unwrap_or_else(|| panic!("no vector {name}"))["fields"]
        .clone()
}
