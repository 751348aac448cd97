// The subject page's keepalive (c223f77), and sim_participant.mjs's copy of it: while engaged, a
// sample every 50 ms only when the pointer has been still for 45 ms (no sample sent since); a
// moving pointer's own samples (60 a second) are the keepalive. Each is driven on a clock of the
// test's own through the same second of a pointer held and moving at 60 Hz, a second held still
// and a second released. Before c223f77 both sent one every 50 ms while held, moving or not (20
// in the moving second). Run by keepalive_test.sh: node --test keepalive.mjs
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import vm from "node:vm";
import WebSocket from "ws";
import { SimParticipant } from "./sim_participant.mjs";

// drive: {tick(ms): the clock moves 1 ms at a time, firing the 50 ms interval; move(): a pointer
// event; press(), release()}. Returns the keepalives counted in each second.
function scenario(drive, keepalives) {
  const counted = [];
  const second = (each) => {
    const before = keepalives();
    for (let ms = 0; ms < 1000; ms++) { if (each) each(ms); drive.tick(); }
    counted.push(keepalives() - before);
  };
  drive.press();
  second((ms) => { if (ms % 17 === 0) drive.move(); });  // held, moving at ~60 Hz
  second();                                              // held, still
  drive.release();
  second();                                              // released
  return counted;
}

test("the page's keepalive (subject.html): only while held and still", () => {
  const page = fs.readFileSync(new URL("../../pages/subject.html", import.meta.url), "utf8");
  const rule = page.split("\n").filter((l) => l.startsWith("setInterval(") && l.includes("send(true)"));
  assert.equal(rule.length, 1, "subject.html: one keepalive line, setInterval(...send(true)...)");
  let now = 1000, held = false, interval = null, period = 0, keepalives = 0;
  const ctx = vm.createContext({
    performance: { now: () => now },
    engaged: () => held,
    send: (force) => { if (force && !ctx.moving) keepalives++; ctx.lastSent = now; },  // the page's send() sets lastSent
    setInterval: (fn, ms) => { interval = fn, period = ms; },
    lastSent: 0, moving: false,
  });
  vm.runInContext(rule[0], ctx);
  assert.equal(period, 50);
  const press = () => { held = true; ctx.moving = true; ctx.send(true); ctx.moving = false; };
  const drive = {
    tick: () => { now++; if (now % period === 0) interval(); },
    move: () => { ctx.moving = true; ctx.send(false); ctx.moving = false; },
    press,
    release: () => { held = false; ctx.moving = true; ctx.send(true); ctx.moving = false; },
  };
  const [moving, still, released] = scenario(drive, () => keepalives);
  assert.equal(moving, 0, "no keepalive while the pointer moves");
  assert.ok(still >= 19 && still <= 20, `one keepalive per 50 ms while still: ${still}`);
  assert.equal(released, 0, "none once released");
});

test("sim_participant.mjs's keepalive does as the page", (t) => {
  t.mock.timers.enable({ apis: ["setInterval"] });
  let now = 1000;
  t.mock.method(performance, "now", () => now);
  const p = new SimParticipant({ url: "http://127.0.0.1:9", token: "t", primitives: [] });
  let keepalives = 0, forced = false;
  p.ws = { readyState: WebSocket.OPEN, send: () => { if (forced === "keepalive") keepalives++; } };
  p.steering = true;
  const send = p.send.bind(p);
  p.send = (force) => { forced = force && !p.acting ? "keepalive" : false; send(force); };
  const acting = (fn) => () => { p.acting = true; fn(); p.acting = false; };
  p.startKeepalive();
  const drive = {
    tick: () => { now++; t.mock.timers.tick(1); },
    move: acting(() => { p.cursor = [p.cursor[0] + 0.1, 0]; p.moved(); }),
    press: acting(() => p.press()),
    release: acting(() => p.release()),
  };
  const [moving, still, released] = scenario(drive, () => keepalives);
  clearInterval(p.keepalive);
  assert.equal(moving, 0, "no keepalive while the pointer moves");
  assert.ok(still >= 19 && still <= 20, `one keepalive per 50 ms while still: ${still}`);
  assert.equal(released, 0, "none once released");
});
