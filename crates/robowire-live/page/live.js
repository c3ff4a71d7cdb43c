// robowire live: per device, the newest state, plots of the series /plots.json names, log entries
// and counts, from the Foxglove WebSocket server (subprotocol foxglove.sdk.v1) on this page's
// host:port. Plots by uPlot 1.6.32 (MIT, see uPlot.LICENSE), vendored from npm's `uplot`.
"use strict";

const WINDOW_S = 10; // each plot's rolling window
const REDRAW_MS = 100;
const STATE_MS = 250; // state tables' refresh period
const RECONNECT_MS = 1000;
const PLOTS_TRIES = 5; // /plots.json fetches for a link advertised but not listed
const LOG_KEEP = 50; // log entries kept per device
const STATE_FIELDS = 12; // top-level fields shown per state table
const PLOT_HEIGHT_PX = 200;
const PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf"];
const LEVELS = { 1: "debug", 2: "info", 3: "warning", 4: "error", 5: "fatal" };
const LEVEL_COLORS = { 1: "#888", 2: "#888", 3: "#e90", 4: "#e33", 5: "#e33" };
const LINK_TOPIC = /^\/(.+)\/(sent|received)(?:\/([^/]+))?$/; // /{link}/{direction}[/{schema}]

const utf8 = new TextDecoder();
const stepped = uPlot.paths.stepped({ align: 1, extend: true }); // a held command, to the right edge
const devices = new Map(); // name → device
const links = new Set(); // links of /plots.json already built
// `/{link}/{schema}` → [{plot, cols: [{index, tokens, range}]}]. Without the direction: a
// simulator records its side of the link (its LowState sent, not received), and a message type
// names one side.
const sinks = new Map();
const channels = new Map(); // channel id → advertised channel
const subscribed = new Map(); // subscription id → channel
const subscribedChannels = new Set();
const otherLog = []; // log entries of names with no device section
const seenRates = new Map(); // topic → {seen, at_ms} of the previous stats
let ws = null;
let nextSubscription = 0;
let plotsFetch = null;
let serverName = "";
const askedLinks = new Map(); // advertised link missing from /plots.json → times asked again

window.robowireLive = { connected: false, devices: [], points: {} };

/** An element: `h("td", {class: "num"}, "3")`. */
function h(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  e.append(...children);
  return e;
}

/** The value at an RFC 6901 pointer's unescaped tokens. */
function at(value, tokens) {
  for (const t of tokens) {
    if (value === null || typeof value !== "object") return undefined;
    value = value[t];
  }
  return value;
}

function tokens(pointer) {
  return pointer.split("/").slice(1).map((t) => t.replace(/~1/g, "/").replace(/~0/g, "~"));
}

function deviceOf(link) {
  return link.split("/")[0];
}

function clock(t_s) {
  const d = new Date(t_s * 1000);
  return d.toLocaleTimeString([], { hour12: false }) + "." + String(d.getMilliseconds()).padStart(3, "0");
}

function short(v) {
  if (typeof v === "number") return Number.isInteger(v) ? String(v) : String(Number(v.toPrecision(4)));
  if (Array.isArray(v)) return "[" + v.map(short).join(", ") + "]";
  return String(v);
}

/** The device section named `name`, made on first use. */
function device(name) {
  let d = devices.get(name);
  if (d) return d;
  const logList = h("ol", { class: "log" });
  const stateBox = h("div", { class: "state muted" }, "no message yet");
  const counts = h("tbody");
  const last = h("span", { class: "last muted" });
  const plotsBox = h("div", { class: "plots" });
  const root = h(
    "section",
    { class: "device", "data-device": name },
    h("header", {}, h("h2", {}, name), last),
    h(
      "div",
      { class: "columns" },
      h("div", {}, h("h3", {}, "Latest state"), stateBox),
      h("div", {}, h("h3", {}, "Connection and faults"), logList),
      h(
        "div",
        {},
        h("h3", {}, "Channels"),
        h("table", {}, h("thead", {}, h("tr", {}, ...["topic", "seen", "sent", "undecodable", "seen/s"].map((t) => h("th", {}, t)))), counts),
      ),
    ),
    plotsBox,
  );
  d = { name, root, logList, stateBox, counts, last, plotsBox, plots: [], log: [], states: new Map() };
  const sections = [...document.querySelectorAll("section.device")];
  const after = sections.find((s) => s.dataset.device > name);
  document.getElementById("devices").insertBefore(root, after || null);
  devices.set(name, d);
  for (let i = otherLog.length - 1; i >= 0; i--) {
    if (otherLog[i].name === name) d.log.unshift(...otherLog.splice(i, 1));
  }
  renderLog(d);
  renderOtherLog();
  return d;
}

/** Plots for each panel of a /plots.json link, fed by the JSON topics its series name. */
function addLink({ link, panels }) {
  if (links.has(link)) return;
  links.add(link);
  const d = device(deviceOf(link));
  for (const panel of panels) {
    const series = [];
    let color = 0;
    panel.series.forEach((s, i) => {
      const topic = `/${link}/${s.direction}/${s.schema}`;
      series.push({ ...s, topic, color: PALETTE[color % PALETTE.length] });
      // A held target and the value after it share a color.
      const pairs = s.held && panel.series[i + 1] && !panel.series[i + 1].held;
      if (!pairs) color++;
    });
    const chart = h("div", { class: "chart" }, h("div", { class: "waiting muted" }, `${link} · ${panel.title}: waiting for data`));
    const root = h("div", {
      class: "plot",
      "data-topic-series": series.map((s) => `${s.topic}#${s.pointer}`).join(" "),
      "data-points": "0",
    }, chart);
    d.plotsBox.append(root);
    const plot = { device: d, title: `${link} · ${panel.title}`, panel, series, root, chart, xs: [], ys: series.map(() => []), added: 0, dirty: false, uplot: null };
    d.plots.push(plot);
    const byTopic = new Map();
    series.forEach((s, index) => {
      const key = sinkKey(s.topic);
      if (!byTopic.has(key)) byTopic.set(key, []);
      byTopic.get(key).push({ index, tokens: tokens(s.pointer), range: s.range || [-Infinity, Infinity] });
    });
    for (const [topic, cols] of byTopic) {
      if (!sinks.has(topic)) sinks.set(topic, []);
      sinks.get(topic).push({ plot, cols });
    }
  }
}

/** One row of `plot` at `t_s`, kept in time order: the values of `cols`, `undefined` (a point
 * the line passes over) elsewhere. */
function addRow(plot, t_s, cols, values) {
  const { xs, ys } = plot;
  let i = xs.length;
  while (i > 0 && xs[i - 1] > t_s) i--;
  xs.splice(i, 0, t_s);
  for (const y of ys) y.splice(i, 0, undefined);
  cols.forEach((c, k) => {
    ys[c.index][i] = values[k];
    if (values[k] !== undefined) plot.added++;
  });
  plot.dirty = true;
}

/** A break in every line of every plot (`null`: a gap), after the newest row. */
function addGaps() {
  for (const d of devices.values()) {
    for (const plot of d.plots) {
      if (!plot.xs.length) continue;
      plot.xs.push(plot.xs[plot.xs.length - 1] + 1e-6);
      for (const y of plot.ys) y.push(null);
      plot.dirty = true;
    }
  }
}

/** A JSON topic without its direction: `/{link}/{schema}`. */
function sinkKey(topic) {
  const match = LINK_TOPIC.exec(topic);
  return match && match[3] ? `/${match[1]}/${match[3]}` : topic;
}

function feedPlots(topic, t_s, message) {
  for (const { plot, cols } of sinks.get(sinkKey(topic)) || []) {
    let any = false;
    const values = cols.map(({ tokens, range }) => {
      const v = at(message, tokens);
      const ok = typeof v === "number" && Number.isFinite(v) && v >= range[0] && v <= range[1];
      any ||= ok;
      return ok ? v : undefined;
    });
    if (any) addRow(plot, t_s, cols, values);
  }
}

function drawMarkers(u, d) {
  const { min, max } = u.scales.x;
  const ctx = u.ctx;
  ctx.save();
  ctx.lineWidth = Math.max(1, devicePixelRatio);
  for (const e of d.log) {
    if (!(e.t_s >= min && e.t_s <= max)) continue;
    const x = Math.round(u.valToPos(e.t_s, "x", true));
    ctx.strokeStyle = LEVEL_COLORS[e.level] || "#888";
    ctx.beginPath();
    ctx.moveTo(x, u.bbox.top);
    ctx.lineTo(x, u.bbox.top + u.bbox.height);
    ctx.stroke();
  }
  ctx.restore();
}

function makeChart(plot) {
  const fg = getComputedStyle(document.body).color;
  const grid = { stroke: "rgba(128,128,128,0.2)", width: 1 };
  const axis = { stroke: fg, grid, ticks: grid };
  const opts = {
    title: plot.title,
    width: Math.max(200, plot.chart.clientWidth),
    height: PLOT_HEIGHT_PX,
    scales: { x: { time: plot.xs[0] > 1e8 } },
    axes: [axis, { ...axis, label: plot.panel.y_label }],
    series: [
      {},
      ...plot.series.map((s) => ({
        label: s.name,
        stroke: s.color,
        width: 1.5,
        points: { show: false },
        ...(s.held ? { dash: [6, 3], paths: stepped } : {}),
      })),
    ],
    hooks: { draw: [(u) => drawMarkers(u, plot.device)] },
  };
  plot.chart.replaceChildren();
  plot.uplot = new uPlot(opts, [plot.xs, ...plot.ys], plot.chart);
}

/** Drops rows older than the window, then redraws the plots that changed. */
function redraw() {
  for (const d of devices.values()) {
    let points = 0;
    for (const plot of d.plots) {
      points += plot.added;
      if (!plot.dirty) continue;
      const { xs, ys } = plot;
      const cut = xs.findIndex((x) => x >= xs[xs.length - 1] - WINDOW_S);
      if (cut > 0) {
        xs.splice(0, cut);
        for (const y of ys) y.splice(0, cut);
      }
      if (!plot.uplot) makeChart(plot);
      else plot.uplot.setData([xs, ...ys]);
      plot.dirty = false;
      plot.root.dataset.points = String(plot.added);
    }
    window.robowireLive.points[d.name] = points;
  }
  window.robowireLive.devices = [...devices.keys()];
}

function renderStates() {
  for (const d of devices.values()) {
    for (const [topic, s] of d.states) {
      if (!s.dirty) continue;
      s.dirty = false;
      if (!s.box) {
        s.table = h("tbody");
        s.pre = h("pre");
        s.raw = h("details", {}, h("summary", {}, "raw JSON"), s.pre);
        s.age = h("span", { class: "muted" });
        s.box = h("details", { open: "" }, h("summary", {}, `${topic.slice(d.name.length + 2)} `, s.age), h("table", {}, s.table), s.raw);
        if (!d.stateBox.querySelector("details")) d.stateBox.replaceChildren();
        d.stateBox.classList.remove("muted");
        d.stateBox.append(s.box);
      }
      s.age.textContent = `at ${clock(s.t_s)}`;
      const rows = [];
      for (const [k, v] of Object.entries(s.value ?? {})) {
        const scalar = v === null || typeof v !== "object";
        const small = Array.isArray(v) && v.length <= 4 && v.every((x) => x === null || typeof x !== "object");
        if (scalar || small) rows.push(h("tr", {}, h("th", {}, k), h("td", {}, short(v))));
        if (rows.length === STATE_FIELDS) break;
      }
      s.table.replaceChildren(...rows);
      if (s.raw.open) s.pre.textContent = JSON.stringify(s.value, null, 1);
    }
  }
}

function logEntry(e) {
  const level = LEVELS[e.level] || String(e.level);
  return h("li", { class: `level-${e.level}` }, `${clock(e.t_s)} ${level} ${e.name ? e.name + ": " : ""}${e.message}`);
}

function renderLog(d) {
  d.logList.replaceChildren(...d.log.slice().reverse().map(logEntry));
  const e = d.log[d.log.length - 1];
  d.last.textContent = e ? `${clock(e.t_s)} ${e.message}` : "";
}

function renderOtherLog() {
  document.getElementById("log-other").replaceChildren(...otherLog.slice().reverse().map(logEntry));
}

function onLog(m, logTime_s) {
  const ts = m.timestamp;
  const t_s = ts && typeof ts.sec === "number" ? ts.sec + (ts.nsec || 0) / 1e9 : logTime_s;
  const e = { t_s, level: m.level, message: String(m.message ?? ""), name: m.name || "" };
  const d = devices.get(e.name);
  const list = d ? d.log : otherLog;
  list.push(e);
  if (list.length > LOG_KEEP) list.shift();
  if (d) {
    renderLog(d);
    for (const plot of d.plots) plot.uplot?.redraw(false, false);
  } else {
    renderOtherLog();
  }
}

function onStats(m) {
  const now_ms = performance.now();
  const rows = new Map();
  for (const c of m.channels || []) {
    const match = LINK_TOPIC.exec(c.topic);
    const d = match && devices.get(deviceOf(match[1]));
    if (!d) continue;
    const prev = seenRates.get(c.topic);
    seenRates.set(c.topic, { seen: c.seen, at_ms: now_ms });
    const rate = prev && now_ms > prev.at_ms ? ((c.seen - prev.seen) * 1000) / (now_ms - prev.at_ms) : null;
    const cells = [c.topic.slice(d.name.length + 2), c.seen, c.sent, c.undecodable ?? "", rate === null ? "" : rate.toFixed(0)];
    if (!rows.has(d)) rows.set(d, []);
    rows.get(d).push(h("tr", {}, ...cells.map((v, i) => h("td", { class: i ? "num" : "topic" }, String(v)))));
  }
  for (const d of devices.values()) d.counts.replaceChildren(...(rows.get(d) || []));
  const clients = (m.clients || []).map((c) =>
    h("tr", {}, h("td", {}, c.addr), h("td", { class: "num" }, String(c.forwarded)), h("td", { class: "num" }, String(c.dropped))),
  );
  document.querySelector("#clients tbody").replaceChildren(...clients);
  document.getElementById("ring").textContent = m.ring_dropped ? `frames dropped before the view: ${m.ring_dropped}` : "";
}

function onMessage(channel, logTime_s, bytes) {
  let message;
  try {
    message = JSON.parse(utf8.decode(bytes));
  } catch (error) {
    if (!channel.warned) console.error(`${channel.topic}: not JSON (${error.message})`);
    channel.warned = true;
    return;
  }
  if (channel.topic === "/robowire/log") return onLog(message, logTime_s);
  if (channel.topic === "/robowire/live") return onStats(message);
  feedPlots(channel.topic, logTime_s, message);
  const match = LINK_TOPIC.exec(channel.topic);
  const d = match && match[2] === "received" && devices.get(deviceOf(match[1]));
  if (d) {
    const s = d.states.get(channel.topic) || {};
    d.states.set(channel.topic, Object.assign(s, { value: message, t_s: logTime_s, dirty: true }));
  }
}

/** The JSON channels plots need, received ones (the newest state), the log and the counts. */
function wanted(c) {
  if (c.encoding !== "json") return false;
  if (c.topic === "/robowire/log" || c.topic === "/robowire/live" || sinks.has(sinkKey(c.topic))) return true;
  const match = LINK_TOPIC.exec(c.topic);
  return Boolean(match && match[3] && match[2] === "received");
}

function subscribeWanted() {
  const subscriptions = [];
  for (const c of channels.values()) {
    if (subscribedChannels.has(c.id) || !wanted(c)) continue;
    const id = nextSubscription++;
    subscribed.set(id, c);
    subscribedChannels.add(c.id);
    subscriptions.push({ id, channelId: c.id });
  }
  if (subscriptions.length && ws && ws.readyState === WebSocket.OPEN) {
    ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
  }
}

/** /plots.json: its links' plots, then the subscriptions they need. */
function fetchPlots() {
  plotsFetch ??= fetch("plots.json", { cache: "no-store" })
    .then((r) => (r.ok ? r.json() : Promise.reject(new Error(`plots.json: HTTP ${r.status}`))))
    .then((p) => {
      for (const link of p.links || []) addLink(link);
      subscribeWanted();
      // A link advertised before /plots.json had it: asked again, a few times.
      const missing = [...askedLinks].filter(([link, tries]) => !links.has(link) && tries < PLOTS_TRIES);
      for (const [link, tries] of missing) askedLinks.set(link, tries + 1);
      if (missing.length) setTimeout(fetchPlots, RECONNECT_MS);
    })
    .catch((error) => console.error(String(error)))
    .finally(() => (plotsFetch = null));
  return plotsFetch;
}

function onControl(m) {
  switch (m.op) {
    case "serverInfo":
      serverName = m.name || "";
      document.getElementById("server").textContent = serverName;
      break;
    case "advertise": {
      let unknown = false;
      for (const c of m.channels) {
        channels.set(c.id, c);
        const match = LINK_TOPIC.exec(c.topic);
        if (!match) continue;
        if (!links.has(match[1]) && !askedLinks.has(match[1])) {
          askedLinks.set(match[1], 0);
          unknown = true;
        }
      }
      subscribeWanted();
      if (unknown) plotsFetch ? plotsFetch.then(fetchPlots) : fetchPlots();
      break;
    }
    case "unadvertise":
      for (const id of m.channelIds) {
        channels.delete(id);
        subscribedChannels.delete(id);
        for (const [sid, c] of subscribed) if (c.id === id) subscribed.delete(sid);
      }
      break;
    case "status":
      document.getElementById("server").textContent = `${serverName}: ${m.message}`;
      break;
  }
}

function onBinary(buffer) {
  const view = new DataView(buffer);
  if (view.byteLength < 13 || view.getUint8(0) !== 1) return; // messageData only
  const channel = subscribed.get(view.getUint32(1, true));
  if (!channel) return;
  const logTime_s = Number(view.getBigUint64(5, true)) / 1e9;
  onMessage(channel, logTime_s, new Uint8Array(buffer, 13));
}

function setConnected(connected) {
  window.robowireLive.connected = connected;
  document.getElementById("status").classList.toggle("connected", connected);
  document.getElementById("status-text").textContent = connected ? "connected" : "disconnected, reconnecting";
}

function connect() {
  ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/`, ["foxglove.sdk.v1"]);
  ws.binaryType = "arraybuffer";
  ws.onopen = () => setConnected(true);
  ws.onmessage = (e) => (typeof e.data === "string" ? onControl(JSON.parse(e.data)) : onBinary(e.data));
  ws.onclose = () => {
    if (window.robowireLive.connected) addGaps();
    setConnected(false);
    channels.clear();
    subscribed.clear();
    subscribedChannels.clear();
    askedLinks.clear();
    setTimeout(connect, RECONNECT_MS);
  };
}

window.addEventListener("resize", () => {
  for (const d of devices.values()) {
    for (const p of d.plots) p.uplot?.setSize({ width: Math.max(200, p.chart.clientWidth), height: PLOT_HEIGHT_PX });
  }
});
fetchPlots();
connect();
setInterval(redraw, REDRAW_MS);
setInterval(renderStates, STATE_MS);
