//! The JSON schema of a decoded message, from its structure: every field with its type, nested
//! objects and arrays described the same way. What Foxglove needs to list and plot the fields.

use serde_json::{Map, Value, json};

/// The schema of values shaped like `value`, titled `title`.
pub(crate) fn schema_of(title: &str, value: &Value) -> Value {
    let mut schema = describe(value);
    if let Value::Object(map) = &mut schema {
        map.insert("$schema".into(), json!("https://json-schema.org/draft/2020-12/schema"));
        map.insert("title".into(), json!(title));
    }
    schema
}

fn describe(value: &Value) -> Value {
    match value {
        Value::Null => json!({ "type": "null" }),
        Value::Bool(_) => json!({ "type": "boolean" }),
        Value::Number(n) if n.is_f64() => json!({ "type": "number" }),
        Value::Number(_) => json!({ "type": "integer" }),
        Value::String(_) => json!({ "type": "string" }),
        Value::Array(items) => match items.first() {
            Some(first) => json!({ "type": "array", "items": describe(first) }),
            None => json!({ "type": "array" }),
        },
        Value::Object(fields) => {
            let properties: Map<String, Value> = fields.iter().map(|(k, v)| (k.clone(), describe(v))).collect();
            json!({ "type": "object", "properties": properties })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_nested_objects_and_arrays_are_described() {
        let schema = schema_of("t", &json!({"mode": 18, "vx": 0.5, "legs": [[0.1, 0.2]], "ok": true, "name": "x"}));
        assert_eq!(schema["title"], "t");
        assert_eq!(schema["properties"]["mode"]["type"], "integer");
        assert_eq!(schema["properties"]["vx"]["type"], "number");
        assert_eq!(schema["properties"]["legs"]["items"]["items"]["type"], "number");
        assert_eq!(schema["properties"]["ok"]["type"], "boolean");
        assert_eq!(schema["properties"]["name"]["type"], "string");
    }
}
