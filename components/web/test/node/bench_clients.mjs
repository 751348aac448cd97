#!/usr/bin/env node
// Clients for bench/web/bench_web.sh (not a test):
//   node bench_clients.mjs foxglove URL TOPIC SECONDS N   N Foxglove clients subscribed to every
//        channel (N=1: also prints TOPIC's samples/s and bytes per sample as JSON)
//   node bench_clients.mjs pointer URL SAMPLES            the subject's page in Chromium: SAMPLES
//        pointer moves at 100 Hz while engaged; prints the page->component->page round trips
import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";
import { chromium } from "playwright-core";
const { FoxgloveClient } = wsProtocol;
const [mode, url, ...rest] = process.argv.slice(2);
const pct = (a, p) => { const s = [...a].sort((x, y) => x - y); return s[Math.min(s.length - 1, Math.floor(p * s.length))]; };

if (mode === "foxglove") {
  const [topic, seconds, n] = [rest[0], Number(rest[1]), Number(rest[2])];
  const counts = [];
  for (let i = 0; i < n; i++) {
    const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
    const c = { samples: 0, bytes: 0, start: 0, drops: 0 };
    counts.push(c);
    client.on("advertise", (chs) => { for (const ch of chs) if (!topic || ch.topic === topic) client.subscribe(ch.id); c.start = performance.now(); });
    client.on("message", ({ data }) => { c.samples++; c.bytes += data.byteLength; });
    client.on("status", (s) => { const m = /dropped (\d+)/.exec(s.message); if (m) c.drops += Number(m[1]); });
    setTimeout(() => client.close(), seconds * 1000);
  }
  await new Promise((r) => setTimeout(r, seconds * 1000 + 200));
  const c = counts[0];
  const secs = (performance.now() - c.start) / 1000;
  console.log(JSON.stringify({ samples_per_s: Math.round(c.samples / secs), bytes_per_sample: c.samples ? Math.round(c.bytes / c.samples) : 0, drops_reported: c.drops }));
} else if (mode === "pointer") {
  const samples = Number(rest[0]);
  const b = await chromium.launch({ executablePath: "/usr/bin/chromium", args: ["--headless", "--no-sandbox", "--disable-gpu"] });
  const p = await (await b.newContext({ viewport: { width: 800, height: 800 } })).newPage();
  await p.goto(url + "/subject?token=subject-token-000001");  // bench_web.sh's graph
  await p.waitForFunction(() => document.getElementById("role").textContent === "you steer");
  await p.mouse.move(400, 400);
  await p.keyboard.down("Space");
  for (let i = 0; i < samples; i++) { await p.mouse.move(400 + 100 * Math.cos(i / 20), 400 + 100 * Math.sin(i / 20)); await p.waitForTimeout(10); }
  await p.waitForTimeout(300);
  const rtts = (await p.evaluate(() => window.dyadStats())).rtts;
  await b.close();
  console.log(JSON.stringify({ n: rtts.length, median_ms: pct(rtts, 0.5), p99_ms: pct(rtts, 0.99) }));
}
