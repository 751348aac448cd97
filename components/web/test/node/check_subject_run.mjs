#!/usr/bin/env node
// Checks a recording of the browser test against what the browser did (subject_page.mjs):
//   node check_subject_run.mjs LOG.json RECORDING.mcap PERIOD_MS
// - human/input follows the mouse: every sample stamped 150..400 ms after a move (before the next
//   one) is within 0.5 units of that move's workspace position;
// - engaged exactly while the key was held: samples stamped > 150 ms after a key event show it;
// - the executed position (robot/state) moves toward the human while engaged;
// - the tab closed while engaged: the first sample stamped more than one period + 150 ms after the
//   close is disengaged;
// - the note typed on the experimenter's page is recorded on experiment/notes, stamped when sent.
import { readFile, open } from "node:fs/promises";
import { McapIndexedReader } from "@mcap/core";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { decompress } from "fzstd";

const [logFile, mcapFile, periodArg] = process.argv.slice(2);
const period = Number(periodArg);
const log = JSON.parse(await readFile(logFile, "utf8"));
const handle = await open(mcapFile, "r");
const reader = await McapIndexedReader.Initialize({
  readable: {
    size: async () => BigInt((await handle.stat()).size),
    read: async (offset, size) => { const b = new Uint8Array(Number(size)); await handle.read(b, 0, b.length, Number(offset)); return b; },
  },
  decompressHandlers: { zstd: (data, size) => decompress(data, new Uint8Array(Number(size))) },
});
const decoders = new Map();
for (const ch of reader.channelsById.values()) {
  const schema = reader.schemasById.get(ch.schemaId);
  decoders.set(ch.topic, new MessageReader(schema.name, parseIDL(new TextDecoder().decode(schema.data))));
}
async function samples(topic) {
  const out = [];
  for await (const m of reader.readMessages({ topics: [topic] })) {
    const msg = decoders.get(topic).readMessage(m.data);
    out.push({ t: Number(msg.header.stamp_ns / 1000000n), msg });
  }
  return out;
}
const human = await samples("human/input");
const state = await samples("robot/state");
const failures = [];
const fail = (m) => { if (failures.length < 20) failures.push(m); };

// 1. Position.
let checked = 0;
for (let i = 0; i < log.moves.length; i++) {
  const m = log.moves[i];
  const end = Math.min(m.t + 400, i + 1 < log.moves.length ? log.moves[i + 1].t : Infinity);
  for (const s of human.filter((h) => h.t >= m.t + 150 && h.t < end)) {
    checked++;
    const d = Math.hypot(s.msg.x - m.x, s.msg.y - m.y);
    if (d > 0.5) fail(`move ${i} at (${m.x.toFixed(2)}, ${m.y.toFixed(2)}): human/input (${s.msg.x.toFixed(2)}, ${s.msg.y.toFixed(2)}) is ${d.toFixed(2)} away`);
  }
}
if (checked < 20) fail(`only ${checked} human/input samples fell in the move windows`);

// 2. Engagement follows the key (and the close).
const events = [...log.key.map((k) => ({ t: k.t, engaged: k.down })), { t: log.closed_at, engaged: false }].sort((a, b) => a.t - b.t);
const expectedAt = (t) => { let e = false; for (const ev of events) if (ev.t <= t) e = ev.engaged; return e; };
let engagedChecked = 0;
for (const s of human) {
  if (s.t < log.moves[0].t) continue;
  if (events.some((ev) => Math.abs(s.t - ev.t) < 150 + period)) continue;  // within a step of a change
  engagedChecked++;
  if (s.msg.engaged !== expectedAt(s.t)) fail(`human/input at ${s.t} engaged=${s.msg.engaged}, key says ${expectedAt(s.t)}`);
}

// 3. The executed position moves toward the human while engaged (over the circle's first hold).
const down = log.key[0].t;
const target = log.moves.find((m) => m.t >= down);
const near = (t) => state.reduce((best, s) => (Math.abs(s.t - t) < Math.abs(best.t - t) ? s : best), state[0]);
const before = near(target.t), after = near(target.t + 380);  // the end of that hold
const dist = (s) => Math.hypot(s.msg.x - target.x, s.msg.y - target.y);
if (!(dist(after) < dist(before) - 5)) fail(`robot did not move toward the human: ${dist(before).toFixed(1)} -> ${dist(after).toFixed(1)} units`);

// 4. Disengaged within one step of the tab closing.
const firstAfter = human.find((h) => h.t > log.closed_at + period + 150);
if (!firstAfter) fail("no human/input after the tab closed");
else if (firstAfter.msg.engaged) fail(`still engaged ${firstAfter.t - log.closed_at} ms after the tab closed`);
// 5. The experimenter's note is recorded, stamped when it was sent.
const notes = await samples("experiment/notes");
const note = notes.find((n) => n.msg.text === log.note.text);
if (!note) fail("the experimenter's note is not in the recording");
else if (Math.abs(note.t - log.note.t) > 1000 || note.msg.author !== "experimenter") fail(`note stamped ${note.t - log.note.t} ms from when it was sent, author ${note.msg.author}`);

const lastEngaged = [...human].reverse().find((h) => h.msg.engaged);
const disengageMs = lastEngaged ? lastEngaged.t - log.closed_at : null;

console.log(JSON.stringify({ human: human.length, state: state.length, position_checks: checked, engaged_checks: engagedChecked,
  last_engaged_after_close_ms: disengageMs, pointer_rtt_ms: log.rtts.length ? log.rtts.slice().sort((a, b) => a - b)[Math.floor(log.rtts.length / 2)] : null }));
if (failures.length) { for (const f of failures) console.error("FAIL: " + f); process.exit(1); }
console.log("PASS");
