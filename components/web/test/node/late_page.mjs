#!/usr/bin/env node
// The subject's page for web.clock_waits_for_the_page, headless (`ws`): it opens DELAY_MS after
// it is started (a page that comes late), steers (a released pointer sample every 50 ms, as the
// page's pointer events) until the graph closes it or STEER_MS have passed, and prints one JSON
// line: {"opened": wall-clock ms of the socket's open, "steering": whether the page steered}.
//   node late_page.mjs WS_URL DELAY_MS STEER_MS
// WS_URL: ws://127.0.0.1:PORT/subject/ws?token=SUBJECT_TOKEN.
import WebSocket from "ws";

const [url, delayArg, steerArg] = process.argv.slice(2);
const delay = Number(delayArg), steer = Number(steerArg);
if (!url || !(delay >= 0) || !(steer > 0)) { console.error("usage: node late_page.mjs WS_URL DELAY_MS STEER_MS"); process.exit(2); }

await new Promise((r) => setTimeout(r, delay));
const ws = new WebSocket(url, { headers: { Origin: url.replace(/^ws/, "http").replace(/\/subject.*/, "") } });
let steering = false, n = 0;
ws.on("message", (data) => { const m = JSON.parse(String(data)); if (m.op === "hello" || m.op === "role") steering = steering || m.steering; });
const closed = new Promise((r) => ws.on("close", r));
await new Promise((resolve, reject) => { ws.on("open", resolve); ws.on("error", reject); });
const opened = Date.now();
const timer = setInterval(() => {
  n++;
  if (ws.readyState === WebSocket.OPEN)
    ws.send(JSON.stringify({ op: "pointer", x: 10 * Math.cos(n / 20), y: 10 * Math.sin(n / 20), engaged: false, t: performance.now() }));
}, 50);
await Promise.race([closed, new Promise((r) => setTimeout(r, steer))]);
clearInterval(timer);
ws.close();
console.log(JSON.stringify({ opened, steering }));
