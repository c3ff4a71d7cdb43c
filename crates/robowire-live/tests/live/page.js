// The live page in a headless Chromium (puppeteer-core on the system's browser: /usr/bin/chromium
// or $CHROMIUM). Run by the robowire-live tests.
//
// node page.js http://HOST:PORT/ OUT.png SECONDS_MAX [DEVICE,...]: opens the page, waits until every
// device it lists (window.robowireLive.devices) that has plots has one with at least MIN_POINTS
// points, and every DEVICE named is listed, or the server went away after the page connected,
// or SECONDS_MAX; screenshots the whole page to OUT.png;
// prints on stdout
//   {"devices": {"go2": {"plots", "points", "nonEmptyPlots", "inkPixels"}}, "connected", "wasConnected",
//    "consoleErrors": [...], "waited_ms"}
// where inkPixels counts the strongly coloured pixels (series, markers; not the grey axes and
// grid) in the device's plot canvases.
"use strict";

const puppeteer = require("puppeteer-core");

const MIN_POINTS = 20;
const POLL_MS = 250;

const [url, out, secondsMax, expected] = process.argv.slice(2);
const expectedDevices = expected ? expected.split(",") : [];
if (!url || !out || Number.isNaN(Number(secondsMax))) {
  console.error("usage: node page.js http://HOST:PORT/ OUT.png SECONDS_MAX [DEVICE,...]");
  process.exit(2);
}

/** In the page: per device, its plots, their points, and the coloured pixels they drew. */
function survey() {
  const live = window.robowireLive || { devices: [], connected: false };
  const devices = {};
  for (const name of live.devices) {
    const section = document.querySelector(`section[data-device="${CSS.escape(name)}"]`);
    const plots = section ? [...section.querySelectorAll("[data-topic-series]")] : [];
    const counts = plots.map((p) => Number(p.dataset.points) || 0);
    let inkPixels = 0;
    for (const canvas of section ? section.querySelectorAll("canvas") : []) {
      if (!canvas.width || !canvas.height) continue;
      const { data } = canvas.getContext("2d").getImageData(0, 0, canvas.width, canvas.height);
      for (let i = 0; i < data.length; i += 4) {
        const [r, g, b, a] = [data[i], data[i + 1], data[i + 2], data[i + 3]];
        if (a > 128 && Math.max(r, g, b) - Math.min(r, g, b) > 80) inkPixels++;
      }
    }
    devices[name] = {
      plots: plots.length,
      points: counts.reduce((a, b) => a + b, 0),
      nonEmptyPlots: counts.filter((n) => n > 0).length,
      maxPlotPoints: Math.max(0, ...counts),
      inkPixels,
    };
  }
  return { devices, connected: Boolean(live.connected) };
}

async function main() {
  const browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox", "--headless=new"],
  });
  const consoleErrors = [];
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 900 });
    page.on("console", (m) => m.type() === "error" && consoleErrors.push(m.text()));
    page.on("pageerror", (e) => consoleErrors.push(String(e.message || e)));
    page.on("requestfailed", (r) => consoleErrors.push(`${r.url()}: ${r.failure()?.errorText}`));
    const start = Date.now();
    await page.goto(url, { waitUntil: "load" });
    let seen;
    // Whether the page was connected at some point: a server that then goes away (a demo that
    // ended) ends the wait, what it drew stays.
    let wasConnected = false;
    for (;;) {
      seen = await page.evaluate(survey);
      const withPlots = Object.values(seen.devices).filter((d) => d.plots > 0);
      const listed = expectedDevices.every((name) => name in seen.devices);
      const done = listed && withPlots.length > 0 && withPlots.every((d) => d.maxPlotPoints >= MIN_POINTS);
      const gone = wasConnected && !seen.connected;
      wasConnected ||= seen.connected;
      if (done || gone || Date.now() - start > Number(secondsMax) * 1000) break;
      await new Promise((r) => setTimeout(r, POLL_MS));
    }
    const waited_ms = Date.now() - start;
    // A redraw after the last points, then the counts the screenshot shows.
    await new Promise((r) => setTimeout(r, POLL_MS));
    await page.screenshot({ path: out, fullPage: true });
    seen = await page.evaluate(survey);
    for (const d of Object.values(seen.devices)) delete d.maxPlotPoints;
    process.stdout.write(JSON.stringify({ ...seen, wasConnected, consoleErrors, waited_ms }) + "\n");
  } finally {
    await browser.close();
  }
}

main().catch((error) => {
  console.error(`page.js: ${error.stack || error}`);
  process.exit(1);
});
