// A Foxglove WebSocket client on the live server, as Foxglove is one: @foxglove/ws-protocol's
// FoxgloveClient over `ws`, subprotocol foxglove.sdk.v1. Run by the robowire-live tests.
//
// node client.js URL SECONDS: subscribes to every channel advertised; decodes `json` messages with
// JSON.parse and `cdr`/`omgidl` ones with Foxglove's IDL parser and CDR reader (the channel's
// schemaName the root type); after SECONDS prints on stdout
//   {"server": {serverInfo}, "status": [...], "channels": [{topic, encoding, schemaName,
//    schemaEncoding, count, errors, firstError?, first}]}
// where `first` is the first message decoded (arrays cut to their first 3 entries, int64 as
// decimal strings).
// node client.js URL SECONDS --stall: subscribes to every channel, then reads nothing from the
// socket for SECONDS; prints {"stalled": true}.
// node client.js URL 0 --malformed: three connections in turn, each sends one thing no Foxglove
// client sends (text `not json`, `{"op":"nope"}`, one 32 MiB binary frame) and waits up to 5 s for
// the server to close it; prints {"malformed": [{case, opened, closed, code, reason}]}.
"use strict";

const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parseIDL } = require("@foxglove/omgidl-parser");
const { MessageReader } = require("@foxglove/omgidl-serialization");
const WebSocket = require("ws");

const SUBPROTOCOL = "foxglove.sdk.v1";
const CLOSE_WAIT_MS = 5000;
const KEEP_ENTRIES = 3;

const [url, seconds, mode] = process.argv.slice(2);
if (!url || seconds === undefined || Number.isNaN(Number(seconds))) {
  console.error("usage: node client.js ws://HOST:PORT/ SECONDS [--stall | --malformed]");
  process.exit(2);
}

/** `value` as JSON can say it: arrays (typed ones too) cut to their first entries, bigints as strings. */
function plain(value) {
  if (typeof value === "bigint") return value.toString();
  if (ArrayBuffer.isView(value)) return Array.from(value.subarray(0, KEEP_ENTRIES), plain);
  if (Array.isArray(value)) return value.slice(0, KEEP_ENTRIES).map(plain);
  if (value !== null && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, plain(v)]));
  }
  return value;
}

/** A decoder of the channel's payloads; throws when there is none. */
function decoderOf(channel) {
  if (channel.encoding === "json") {
    const utf8 = new TextDecoder("utf-8", { fatal: true });
    return (bytes) => JSON.parse(utf8.decode(bytes));
  }
  if (channel.encoding === "cdr" && channel.schemaEncoding === "omgidl") {
    const reader = new MessageReader(channel.schemaName, parseIDL(channel.schema));
    return (bytes) => reader.readMessage(bytes);
  }
  throw new Error(`no decoder for encoding ${channel.encoding} (schema encoding ${channel.schemaEncoding})`);
}

/** A FoxgloveClient on a new connection; no connection at all exits 1. */
function connect() {
  const ws = new WebSocket(url, [SUBPROTOCOL]);
  let opened = false;
  ws.on("open", () => (opened = true));
  ws.on("error", (error) => {
    if (opened) return;
    console.error(`client.js: ${url}: ${error.message}`);
    process.exit(1);
  });
  return { ws, client: new FoxgloveClient({ ws }) };
}

function listen() {
  const { client } = connect();
  const result = { server: null, status: [], channels: [] };
  const bySubscription = new Map();
  client.on("serverInfo", (info) => (result.server = info));
  client.on("status", (status) => result.status.push(status));
  client.on("advertise", (channels) => {
    for (const channel of channels) {
      const entry = {
        topic: channel.topic,
        encoding: channel.encoding,
        schemaName: channel.schemaName,
        schemaEncoding: channel.schemaEncoding,
        count: 0,
        errors: 0,
        first: null,
      };
      result.channels.push(entry);
      let decode;
      try {
        decode = decoderOf(channel);
      } catch (error) {
        entry.firstError = `schema: ${error.message}`;
        decode = () => {
          throw error;
        };
      }
      bySubscription.set(client.subscribe(channel.id), { entry, decode });
    }
  });
  client.on("message", ({ subscriptionId, data }) => {
    const sub = bySubscription.get(subscriptionId);
    if (!sub) return;
    sub.entry.count++;
    try {
      const value = sub.decode(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
      if (sub.entry.first === null) sub.entry.first = plain(value);
    } catch (error) {
      sub.entry.errors++;
      sub.entry.firstError ??= String(error.message || error);
    }
  });
  client.on("close", (event) => (result.closed ??= { code: event.code, reason: String(event.reason || "") }));
  setTimeout(() => {
    process.stdout.write(JSON.stringify(result) + "\n");
    process.exit(0);
  }, Number(seconds) * 1000);
}

function stall() {
  const { ws, client } = connect();
  client.on("advertise", (channels) => {
    for (const channel of channels) client.subscribe(channel.id);
    // Reads nothing more: the server's writes fill the socket's buffers.
    ws._socket.pause();
  });
  setTimeout(() => {
    process.stdout.write(JSON.stringify({ stalled: true }) + "\n");
    process.exit(0);
  }, Number(seconds) * 1000);
}

/** One connection that sends `payload`: whether the server closed it within CLOSE_WAIT_MS. */
function malformedCase(name, payload) {
  return new Promise((resolve) => {
    const outcome = { case: name, opened: false, closed: false, code: null, reason: "" };
    const ws = new WebSocket(url, [SUBPROTOCOL]);
    let waited = false;
    const timer = setTimeout(() => {
      waited = true;
      resolve(outcome);
      ws.terminate();
    }, CLOSE_WAIT_MS);
    ws.on("open", () => {
      outcome.opened = true;
      ws.send(payload, { binary: typeof payload !== "string" }, () => {});
    });
    ws.on("error", (error) => waited || (outcome.error ??= error.message));
    ws.on("close", (code, reason) => {
      if (waited) return;
      clearTimeout(timer);
      Object.assign(outcome, { closed: outcome.opened, code, reason: reason.toString() });
      resolve(outcome);
    });
  });
}

async function malformed() {
  const cases = [
    ["bad json", "not json"],
    ["unknown op", JSON.stringify({ op: "nope" })],
    ["32 MiB binary", Buffer.alloc(32 << 20, 0x01)],
  ];
  const results = [];
  for (const [name, payload] of cases) results.push(await malformedCase(name, payload));
  process.stdout.write(JSON.stringify({ malformed: results }) + "\n");
  process.exit(0);
}

if (mode === "--stall") stall();
else if (mode === "--malformed") malformed();
else if (mode === undefined) listen();
else {
  console.error(`client.js: unknown option ${mode}`);
  process.exit(2);
}
