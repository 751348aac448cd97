#!/usr/bin/env node
// Hostile and careless clients against dyad's bridge (the experiment must not notice):
//   - N connections in a row (a reconnect storm), each sending one malformed or oversized
//     message: bad JSON, JSON of the wrong shape, unknown binary opcodes, short binary frames, a
//     frame past the size cap; each must be closed by the server with a reason (or refused);
//   - one client that subscribes to every channel and then never reads its socket.
//   node hostile_clients.mjs URL COUNT SECONDS_STALLED
// Prints a summary; exits 1 if the server stopped answering (a new client gets no serverInfo).
import WebSocket from "ws";

const [url, countArg, stalledArg] = process.argv.slice(2);
const count = Number(countArg ?? 1000);
const stalledSeconds = Number(stalledArg ?? 5);
const proto = ["foxglove.websocket.v1"];

const bad = [
  () => "{not json",
  () => "[1,2,3]",
  () => JSON.stringify({ op: 42 }),
  () => JSON.stringify({ op: "subscribe", subscriptions: [{ id: -1, channelId: "x" }] }),
  () => JSON.stringify({ op: "subscribe", subscriptions: "all" }),
  () => JSON.stringify({ op: "advertise", channels: [{ id: 1 }] }),
  () => Buffer.from([0x07, 1, 2, 3]),
  () => Buffer.from([0x01, 1]),
  () => Buffer.alloc(2 * 1024 * 1024, 1),  // past the default 1 MiB frame cap
  () => "\u0000\u00ff\ufffe",
  () => "[".repeat(500000),  // nesting that a recursive parser would follow into a stack overflow
];

function once(i) {
  return new Promise((resolve) => {
    const ws = new WebSocket(url, proto);
    let closedByServer = false, reason = "";
    const timer = setTimeout(() => { ws.terminate(); resolve({ closedByServer, reason, timeout: true }); }, 3000);
    ws.on("open", () => ws.send(bad[i % bad.length]()));
    ws.on("close", (code, r) => { closedByServer = true; reason = `${code} ${r}`; clearTimeout(timer); resolve({ closedByServer, reason }); });
    ws.on("error", () => {});
  });
}

async function stalled() {
  const ws = new WebSocket(url, proto);
  await new Promise((resolve) => ws.on("message", (data) => {
    const text = data.toString();
    if (text.includes('"op":"advertise"')) {
      const channels = JSON.parse(text).channels;
      ws.send(JSON.stringify({ op: "subscribe", subscriptions: channels.map((c, i) => ({ id: i + 1, channelId: c.id })) }));
      ws._socket.pause();  // never read again
      resolve();
    }
  }));
  return ws;
}

async function alive() {
  return new Promise((resolve) => {
    const ws = new WebSocket(url, proto);
    const timer = setTimeout(() => { ws.terminate(); resolve(false); }, 3000);
    ws.on("message", (d) => { if (d.toString().includes("serverInfo")) { clearTimeout(timer); ws.close(); resolve(true); } });
    ws.on("error", () => {});
  });
}

const staller = await stalled();
const reasons = new Map();
let closed = 0, timeouts = 0;
for (let i = 0; i < count; i += 4) {
  const batch = await Promise.all([0, 1, 2, 3].map((k) => once(i + k)));
  for (const r of batch) {
    if (r.closedByServer) closed++;
    if (r.timeout) timeouts++;
    const key = r.reason.replace(/\d+ bytes/, "N bytes");
    reasons.set(key, (reasons.get(key) ?? 0) + 1);
  }
}
await new Promise((r) => setTimeout(r, stalledSeconds * 1000));
const ok = await alive();
staller.terminate();
process.stdout.write(JSON.stringify({ sent: count, closed, timeouts, alive: ok, reasons: Object.fromEntries(reasons) }, null, 1) + "\n");
process.exit(ok && timeouts === 0 ? 0 : 1);
