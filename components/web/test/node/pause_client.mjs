#!/usr/bin/env node
// The subject's page for web.pause_without_subject, headless (`ws`): it steers for a while,
// leaves (its socket closes, as a closed tab's does), stays away, comes back and steers again,
// then stops; it prints the wall-clock times (ms) of each phase as one JSON line:
//   node pause_client.mjs WS_URL AWAY_MS
// WS_URL: ws://127.0.0.1:PORT/subject/ws?token=SUBJECT_TOKEN. While connected it sends a
// released pointer sample every 50 ms at a slowly moving position (the page's pointer events).
import WebSocket from "ws";

const [url, awayArg] = process.argv.slice(2);
const away = Number(awayArg);
if (!url || !(away > 0)) { console.error("usage: node pause_client.mjs WS_URL AWAY_MS"); process.exit(2); }
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// One visit: connects, sends samples for `ms`, closes; resolves with [open, closed] wall times.
async function visit(ms) {
  const ws = new WebSocket(url, { headers: { Origin: url.replace(/^ws/, "http").replace(/\/subject.*/, "") } });
  let steering = false, n = 0;
  ws.on("message", (data) => { const m = JSON.parse(String(data)); if (m.op === "hello" || m.op === "role") steering = m.steering; });
  await new Promise((resolve, reject) => { ws.on("open", resolve); ws.on("error", reject); });
  const opened = Date.now();
  const timer = setInterval(() => {
    n++;
    ws.send(JSON.stringify({ op: "pointer", x: 10 * Math.cos(n / 20), y: 10 * Math.sin(n / 20), engaged: false, t: performance.now() }));
  }, 50);
  await sleep(ms);
  clearInterval(timer);
  if (!steering) throw new Error("the page never steered");
  const closed = new Promise((r) => ws.on("close", r));
  ws.close();
  await closed;
  return [opened, Date.now()];
}

const first = await visit(2500);
await sleep(away);
const second = await visit(2500);
console.log(JSON.stringify({ first, second }));
