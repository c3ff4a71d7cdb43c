// Decodes CDR payloads with Foxglove's OMG IDL parser and CDR reader, as Foxglove does for an MCAP
// channel with message encoding `cdr` and schema encoding `omgidl`.
//
// stdin: JSON [{"schema": "a::b::C", "idl": "<IDL text>", "payload": "<hex, with the 4-byte
// encapsulation header>"}, ...]
// stdout: JSON [{"value": {...}, "decoded_bytes": n, "length": n} or {"error": "..."}, ...], one
// per input. int64 values are decimal strings, typed arrays plain arrays, non-finite floats the
// strings "NaN", "Infinity", "-Infinity", and -0 the string "-0" (JSON would drop its sign).
"use strict";

const { parseIDL } = require("@foxglove/omgidl-parser");
const { MessageReader } = require("@foxglove/omgidl-serialization");
const { CdrReader } = require("@foxglove/cdr");

function plain(value) {
  if (typeof value === "bigint") return value.toString();
  if (typeof value === "number" && (!Number.isFinite(value) || Object.is(value, -0))) {
    return Object.is(value, -0) ? "-0" : String(value);
  }
  if (ArrayBuffer.isView(value)) return Array.from(value, plain);
  if (Array.isArray(value)) return value.map(plain);
  if (value !== null && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, plain(v)]));
  }
  return value;
}

function decode({ schema, idl, payload }) {
  try {
    const reader = new MessageReader(schema, parseIDL(idl));
    const bytes = Uint8Array.from(Buffer.from(payload, "hex"));
    const value = reader.readMessage(bytes);
    // readMessage's own steps again, to learn how far the reader got.
    const cdr = new CdrReader(bytes);
    const options = { usesDelimiterHeader: cdr.usesDelimiterHeader, usesMemberHeader: cdr.usesMemberHeader };
    reader.readAggregatedType(reader.rootDefinition, cdr, options);
    return { value: plain(value), decoded_bytes: cdr.decodedBytes, length: bytes.length };
  } catch (error) {
    return { error: String(error && error.stack ? error.stack.split("\n")[0] : error) };
  }
}

const input = require("fs").readFileSync(0, "utf8");
process.stdout.write(JSON.stringify(JSON.parse(input).map(decode)));
