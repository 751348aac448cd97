#!/usr/bin/env node
// A simulated participant: a headless client of the subject's page (/subject/ws) that does what a
// person does on components/web/pages/subject.html, speaking the same protocol at the same rates
// (src/subject_channel.hpp), for bench/capacity and for tests of studies run online:
//   - connects with its token (reconnects a second after a close, as the page does; a 1008 close
//     is final), sends a pointer sample on each pointer event (a browser's pointermove, about
//     60 Hz here, at most one per 4 ms as the page), on each press and release, and every 50 ms
//     while engaged and still (the page's keepalive), each stamped "t" (the ack's round trip) and "wall"
//     (the event's wall-clock time: the server keeps the event -> published delay);
//   - draws the data set's primitives (an NRL folder: primitive_<id>_<sample>.csv, x,y rows at
//     100 ms; the experimenter's task target when one is set, else one at random), each as one
//     hold of the mouse button: its own pace (0.8 to 1.3 times the data set's), a small rotation,
//     scale and offset per hold, hand tremor, the events' timing jitter; between holds it rests
//     1 to 3 s and moves to the next start, released;
//   - answers "What were you drawing?" (after each hold of at least the page's minimum, and each
//     question after the trial) with what it drew, 1 to 3 s later, wrong with probability
//     `report_error`; after a hold it is asked about, it rests only once it has answered.
// Without a data set folder it draws generated shapes (a circle, a figure eight, a square), so it
// works from a clean clone. `speed` > 1 (tests) divides every duration of its behaviour (rests,
// holds, answers), never the pointer's event rate.
//
// --online: a participant of `dyad study serve` (the page's ops between trials, docs/components.md
// #web): on consent it agrees; on waiting with a Ready button it presses it 0.5 to 1.5 s later (its
// behaviour's time); it draws only during a trial (from a hello to the next close or waiting, as a
// person does not draw while a message covers the page); it answers each ping with its pong; after
// a close with code 1012 it reconnects at once; on done it keeps the completion code and stops, on
// refused it keeps the message and stops (the page's: no retry). A participant's line may ask for
// a lost connection: "drop:AT:AWAY" (seconds of real time, --speed aside) ends its socket AT s into
// its first trial without a close frame (a network gone, a closed laptop) and reconnects only AWAY
// s later (then as the page does).
//
//   node sim_participant.mjs [--dataset DIR] [--seconds S] [--report-error P] [--speed F] [--chromium K]
//                            [--online] SESSIONS_FILE
//     SESSIONS_FILE: one participant per line, "URL TOKEN [drop:AT:AWAY]" (URL: http://127.0.0.1:PORT); all run
//     in this one process for S seconds (default 30; --online: until each is done or refused, S at
//     most), then each prints one JSON line: pointer samples sent, acks, round trip median/p99 (ms),
//     holds, answers, closes, errors (--online also: trials started, the completion code or null,
//     refused: the message or null, pongs, dropped: when its connection was lost, ms since the
//     epoch, or null); the last line is this process's CPU time (Node's alone:
//     Chromium's own processes are not in it).
//     --chromium K: the first K participants in the real page in Chromium (ChromiumParticipant).
import fs from "node:fs";
import path from "node:path";
import WebSocket from "ws";

// A small seeded generator (mulberry32), so a participant's behaviour can be replayed.
export function rng(seed) {
  let a = seed >>> 0;
  const next = () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
  next.uniform = (lo, hi) => lo + (hi - lo) * next();
  next.gauss = () => Math.sqrt(-2 * Math.log(next() + 1e-12)) * Math.cos(2 * Math.PI * next());
  return next;
}

// The primitives of an NRL data set folder (the first sample of each), or null when absent.
export function loadPrimitives(dir) {
  if (!dir || !fs.existsSync(dir)) return null;
  const prims = [];
  for (const f of fs.readdirSync(dir)) {
    const m = /^primitive_(\d+)_0\.csv$/.exec(f);
    if (!m) continue;
    const rows = fs.readFileSync(path.join(dir, f), "utf8").trim().split("\n");
    const pts = rows.map((r) => r.split(",").slice(0, 2).map(Number));
    if (pts.some((p) => p.length < 2 || !p.every(Number.isFinite))) throw new Error(`${dir}/${f}: rows must be x,y numbers`);
    prims[Number(m[1])] = pts;
  }
  if (prims.length === 0) throw new Error(`${dir}: no primitive_<id>_0.csv files (an NRL data set folder)`);
  if (prims.some((p) => !p)) throw new Error(`${dir}: primitive ids are not 0..${prims.length - 1}`);
  return prims;
}

// Three shapes of 72 steps of 100 ms, radius 30: a circle, a figure eight, a square.
export function generatedPrimitives() {
  const n = 72, r = 30, out = [[], [], []];
  for (let i = 0; i < n; i++) {
    const a = (2 * Math.PI * i) / (n - 1);
    out[0].push([r * Math.cos(a), r * Math.sin(a)]);
    out[1].push([r * Math.sin(a), (r / 2) * Math.sin(2 * a)]);
    const s = (4 * i) / (n - 1), side = Math.min(3, Math.floor(s)), f = s - side;
    const corners = [[-r, -r], [r, -r], [r, r], [-r, r], [-r, -r]];
    const [a0, a1] = [corners[side], corners[side + 1]];
    out[2].push([a0[0] + f * (a1[0] - a0[0]), a0[1] + f * (a1[1] - a0[1])]);
  }
  return out;
}

// The point `u` (0..1) along a path of points, linearly between them.
function along(pts, u) {
  const s = Math.max(0, Math.min(1, u)) * (pts.length - 1), i = Math.min(pts.length - 2, Math.floor(s)), f = s - i;
  return [pts[i][0] + f * (pts[i + 1][0] - pts[i][0]), pts[i][1] + f * (pts[i + 1][1] - pts[i][1])];
}

const wallMs = () => performance.timeOrigin + performance.now();
const pct = (a, p) => { const s = [...a].sort((x, y) => x - y); return s.length ? s[Math.min(s.length - 1, Math.floor(p * s.length))] : null; };

export class SimParticipant {
  // url: http://HOST:PORT; token: the subject's; primitives: [[x,y],...] each; seed: its behaviour.
  constructor({ url, token, primitives, seed = 1, reportError = 0.1, speed = 1, online = false, drop = null }) {
    this.wsUrl = url.replace(/^http/, "ws") + "/subject/ws?token=" + encodeURIComponent(token);
    this.origin = url;
    this.prims = primitives;
    this.r = rng(seed);
    this.reportError = reportError;
    this.speed = speed;
    this.stats = { sent: 0, acks: 0, rtts: [], holds: 0, answers: 0, closes: 0, errors: [] };
    this.half = 50, this.steering = false, this.ask = false, this.askAfterMs = 1000, this.target = -1;
    this.cursor = [0, 0], this.down = false, this.lastSent = 0, this.timers = new Set();
    this.drawn = [];  // the primitive drawn in each hold long enough to be asked about
    // --online: between trials (consent, waiting) or in one; what the front said at the end.
    this.online = online, this.inTrial = !online;
    this.trials = 0, this.code = null, this.refused = null, this.pongs = 0;
    this.betweenSeen = true;  // a hello after consent or waiting starts a trial (after a reconnect it does not)
    this.drop = drop, this.dropped = null, this.backAt = 0;  // drop: {at, away} s; dropped: when (ms since the epoch)
    this.finished = new Promise((r) => { this.finish = r; });  // resolves on done or refused
  }
  later(ms, fn) {  // fn after ms of its behaviour's time
    const t = setTimeout(() => { this.timers.delete(t); if (!this.stopped) fn(); }, ms / this.speed);
    this.timers.add(t);
  }
  start() { this.connect(); this.rest(); this.startKeepalive(); }
  startKeepalive() {  // the page's keepalive: while held and the pointer still (no sample for 45 ms)
    this.keepalive = setInterval(() => { if (this.down && performance.now() - this.lastSent >= 45) this.send(true); }, 50);
  }
  stop() {
    this.stopped = true;
    clearInterval(this.keepalive);
    for (const t of this.timers) clearTimeout(t);
    this.ws?.close();
  }
  connect() {
    this.ws = new WebSocket(this.wsUrl, { headers: { Origin: this.origin } });
    this.ws.on("message", (data) => this.onMessage(JSON.parse(String(data))));
    this.ws.on("error", (e) => { if (this.stats.errors.length < 5) this.stats.errors.push(String(e.message)); });
    this.ws.on("close", (code) => {
      this.stats.closes++, this.steering = false, this.down = false, this.inTrial = !this.online;
      // The page's second, at any speed; after 1012 (the front's next phase) at once.
      const wait = Math.max(code === 1012 ? 0 : 1000, this.backAt - Date.now());  // real ms (later() divides by speed)
      if (!this.stopped && code !== 1008) this.later(wait * this.speed, () => this.connect());
    });
  }
  // drop:AT:AWAY: AT s from now the socket ends without a close frame; no new one for AWAY s.
  loseConnection() {
    this.dropped = 0;
    setTimeout(() => {
      if (this.stopped) return;
      this.dropped = Date.now(), this.backAt = this.dropped + 1000 * this.drop.away;
      this.ws.terminate();
    }, 1000 * this.drop.at);
  }
  // --online: the front's ops between trials (and its ping at any time); true when `m` was one.
  onFrontMessage(m) {
    const reply = (r) => { if (this.ws?.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(r)); };
    if (m.op === "ping") reply({ op: "pong", id: m.id }), this.pongs++;
    else if (m.op === "consent") this.inTrial = false, this.betweenSeen = true, reply({ op: "consent", agree: true });
    else if (m.op === "waiting") {
      this.inTrial = false, this.down = false, this.betweenSeen = true;
      if (m.ready) {
        const ws = this.ws;  // a Ready pressed on the socket it was shown on (a new one shows it again)
        this.later(this.r.uniform(500, 1500), () => { if (this.ws === ws) reply({ op: "ready" }); });
      }
    } else if (m.op === "done" || m.op === "refused") {
      if (m.op === "done") this.code = m.code ?? "";
      else this.refused = m.message;
      this.stop();
      this.finish();
    } else return false;
    return true;
  }
  onMessage(m) {
    if (this.online && this.onFrontMessage(m)) return;
    if (m.op === "hello") {
      if (this.online && this.betweenSeen) this.trials++, this.betweenSeen = false;
      this.inTrial = true;
      if (this.drop && this.dropped === null) this.loseConnection();
      this.half = m.half_width, this.steering = m.steering, this.ask = !!m.ask, this.askAfterMs = 1000 * (m.ask_after_hold_s ?? 1);
      this.drawn = [], this.trialOver = false, this.answering = -1;  // a new graph: a new trial (the page forgets the last one's question)
    } else if (m.op === "role") {
      this.steering = m.steering;
    } else if (m.op === "task") {
      this.target = m.target;
    } else if (m.op === "ack") {
      this.stats.acks++;
      if (this.stats.rtts.length < 100000) this.stats.rtts.push(performance.now() - m.t);
    } else if (m.op === "question") {  // after the trial: nobody steers; the steering page answers
      this.trialOver = true;
      if (!(m.segment >= 0 && this.steering) || this.answering === m.segment) return;  // each question answered once
      this.answering = m.segment;
      this.later(this.r.uniform(1000, 3000), () => this.answer(this.drawn[m.segment] ?? 0, m.segment));
    }
  }
  // The page's send(): at most one sample per 4 ms unless forced (a press, a release, the keepalive).
  send(force) {
    if (this.ws?.readyState !== WebSocket.OPEN || !this.inTrial) return;
    const now = performance.now();
    if (!force && now - this.lastSent < 4) return;
    this.lastSent = now;
    const clamp = (v) => Math.max(-this.half, Math.min(this.half, v));
    this.ws.send(JSON.stringify({ op: "pointer", x: clamp(this.cursor[0]), y: clamp(this.cursor[1]), engaged: this.down && this.steering && !this.trialOver,
                                  t: now, wall: wallMs() }));
    this.stats.sent++;
  }
  // The page's pointer events: a move, the mouse button's press and release.
  moved() { this.send(false); }
  press() { this.down = true; this.send(true); }
  release() { this.down = false; this.send(true); }
  choose(drawn) {
    if (this.r() >= this.reportError) return drawn;
    return this.r() < 0.3 ? -1 : Math.floor(this.r() * this.prims.length);
  }
  answer(drawn, segment) {
    if (this.ws?.readyState !== WebSocket.OPEN) return;
    const choice = this.choose(drawn);
    this.ws.send(JSON.stringify(segment === undefined ? { op: "self_report", choice } : { op: "self_report", choice, segment }));
    this.stats.answers++;
  }
  // Pointer events about every 16.7 ms (a 60 Hz display), each 1-3 ms late or early.
  moveEvery(durationMs, at, done) {
    const t0 = performance.now();
    const step = () => {
      if (!this.inTrial) { if (this.down) this.release(); return this.rest(); }  // --online: the trial ended (a hold is let go)
      const u = (this.speed * (performance.now() - t0)) / durationMs;
      this.cursor = at(Math.min(1, u));
      this.moved();
      if (u >= 1) return done();
      this.later(this.speed * (16.7 + this.r.uniform(-2, 2)), step);
    };
    step();
  }
  // Released: rests, then moves the pointer to the next primitive's start and draws it.
  rest() {
    // The trial is over, or not begun (--online): the person does not draw.
    if (this.trialOver || !this.inTrial) return this.later(1000, () => this.rest());
    const k = this.target >= 0 && this.target < this.prims.length ? this.target : Math.floor(this.r() * this.prims.length);
    const p = this.prims[k], ang = this.r.uniform(-0.08, 0.08), sc = this.r.uniform(0.9, 1.1);
    const off = [this.r.uniform(-3, 3), this.r.uniform(-3, 3)];
    const shape = p.map(([x, y]) => [sc * (x * Math.cos(ang) - y * Math.sin(ang)) + off[0], sc * (x * Math.sin(ang) + y * Math.cos(ang)) + off[1]]);
    const from = [...this.cursor], to = shape[0];
    this.later(this.r.uniform(1000, 3000), () =>
      this.moveEvery(this.r.uniform(400, 900), (u) => [from[0] + u * (to[0] - from[0]), from[1] + u * (to[1] - from[1])],
                     () => this.draw(k, shape)));
  }
  // One hold: the shape at its own pace with tremor (a slowly varying offset plus jitter).
  draw(k, shape) {
    const ms = shape.length * 100 * this.r.uniform(0.8, 1.3), held = performance.now();
    let tremor = [0, 0];
    this.press();
    this.moveEvery(ms, (u) => {
      tremor = tremor.map((v) => 0.9 * v + 0.15 * this.r.gauss());
      const [x, y] = along(shape, u);
      return [x + tremor[0] + 0.1 * this.r.gauss(), y + tremor[1] + 0.1 * this.r.gauss()];
    }, () => {
      this.release();
      this.stats.holds++;
      if (performance.now() - held >= this.askAfterMs) {  // real time: the page's minimum hold
        this.drawn.push(k);
        // A person answers before drawing again: an answer sent during the next hold is not taken
        // (the page asks about a finished hold), so the rest starts once it is given.
        if (this.ask && this.steering) return this.later(this.r.uniform(1000, 3000), () => { this.answer(k); this.rest(); });
      }
      this.rest();
    });
  }
  summary() {
    const s = this.stats;
    const online = this.online ? { trials: this.trials, code: this.code, refused: this.refused, pongs: this.pongs, dropped: this.dropped || null } : {};
    return { sent: s.sent, acks: s.acks, rtt_median_ms: pct(s.rtts, 0.5), rtt_p99_ms: pct(s.rtts, 0.99), holds: s.holds, answers: s.answers,
             closes: s.closes, errors: s.errors, ...online };
  }
}

// The same person in the real subject's page, in Debian's Chromium (playwright-core): the same
// behaviour, its pointer events given to the page as mouse events (the page then sends what it
// sends), its answers as the question's keys (1..n, 0: something else). For checking that the
// headless client is faithful; the page keeps its round trips (window.dyadStats).
export class ChromiumParticipant extends SimParticipant {
  constructor(options, browser) {
    super(options);
    this.browser = browser;
    this.pageUrl = options.url + "/subject?token=" + encodeURIComponent(options.token);
    this.queue = Promise.resolve(), this.pendingMove = null;
  }
  async open() {
    this.context = await this.browser.newContext({ viewport: { width: 800, height: 800 } });
    this.page = await this.context.newPage();
    await this.page.goto(this.pageUrl);
    if (this.online) return;  // the front's views first: poll() answers them
    await this.page.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 20000 });
    await this.locate();
  }
  // --online: what the page shows, every 200 ms: its buttons pressed as the headless client
  // answers the ops (consent: I agree; Ready 0.5 to 1.5 s later), a trial from the page steering to
  // its not steering, the end (the code, or the refusal) read off the page.
  async poll() {
    const v = await this.page.evaluate(() => {
      const on = (id) => document.getElementById(id).classList.contains("on"), el = (id) => document.getElementById(id);
      return { consent: on("consent") && !el("agree").disabled, ready: on("waiting") && el("ready").textContent !== "" && !el("ready").disabled,
               done: on("done") ? el("done-code").textContent : null, refused: final && !on("done") ? el("waiting").textContent : null,  // eslint-disable-line no-undef
               steer: el("role").textContent === "you steer" };
    });
    if (v.steer && !this.inTrial) this.trials++, this.inTrial = true, this.then_(() => this.locate());
    if (!v.steer) this.inTrial = false;
    // A button gone before its click (its socket closed) is not an error: the front shows it again.
    const click = (sel) => this.page.click(sel, { timeout: 2000 }).catch(() => {});
    if (v.consent && !this.pending) this.pending = true, this.then_(() => click("#agree").finally(() => { this.pending = false; }));
    if (v.ready && !this.pending) {
      this.pending = true;
      this.later(this.r.uniform(500, 1500), () => this.then_(() => click("#ready").finally(() => { this.pending = false; })));
    }
    if (v.done !== null || v.refused !== null) {
      this.code = v.done, this.refused = v.refused, this.stopped = true;
      return this.finish();
    }
    this.later(200 * this.speed, () => this.poll().catch((e) => { if (this.stats.errors.length < 5) this.stats.errors.push(String(e.message)); }));
  }
  async locate() {  // the workspace's place on the screen, and what the page said in its hello
    Object.assign(this, await this.page.evaluate(() => {
      const r = document.getElementById("canvas").getBoundingClientRect(), v = view();  // eslint-disable-line no-undef
      return { map: { x0: r.left + v.cx, y0: r.top + v.cy, scale: v.scale }, ask, steering, half: H };  // eslint-disable-line no-undef
    }));
  }
  start() { this.rest(); if (this.online) this.poll(); }
  async stop() {
    this.stopped = true;
    for (const t of this.timers) clearTimeout(t);
    await this.queue.catch(() => {});
    this.rtts = (await this.page.evaluate(() => window.dyadStats()).catch(() => ({ rtts: [] }))).rtts;
    await this.context.close();
  }
  then_(fn) { this.queue = this.queue.then(fn).catch((e) => { if (this.stats.errors.length < 5) this.stats.errors.push(String(e.message)); }); }
  moved() {  // the newest position only, when the page is still busy with the last one
    const first = this.pendingMove === null;
    this.pendingMove = [this.map.x0 + this.map.scale * this.cursor[0], this.map.y0 - this.map.scale * this.cursor[1]];
    if (first) this.then_(() => { const [x, y] = this.pendingMove; this.pendingMove = null; return this.page.mouse.move(x, y); });
  }
  press() { this.down = true; this.moved(); this.then_(() => this.page.mouse.down()); }
  release() { this.down = false; this.then_(() => this.page.mouse.up()); this.then_(() => this.locate()); }
  answer(drawn) {
    const choice = this.choose(drawn);
    this.then_(() => this.page.keyboard.press(String(choice < 0 ? 0 : choice + 1)));
    this.stats.answers++;
  }
  summary() {
    const r = this.rtts ?? [];
    const online = this.online ? { trials: this.trials, code: this.code, refused: this.refused } : {};
    return { chromium: true, acks: r.length, rtt_median_ms: pct(r, 0.5), rtt_p99_ms: pct(r, 0.99), holds: this.stats.holds,
             answers: this.stats.answers, errors: this.stats.errors, ...online };
  }
}

async function main(argv) {
  const opts = { dataset: "", seconds: 30, reportError: 0.1, speed: 1, chromium: 0, online: false };
  const files = [];
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === "--dataset") opts.dataset = argv[++i];
    else if (argv[i] === "--seconds") opts.seconds = Number(argv[++i]);
    else if (argv[i] === "--report-error") opts.reportError = Number(argv[++i]);
    else if (argv[i] === "--speed") opts.speed = Number(argv[++i]);
    else if (argv[i] === "--chromium") opts.chromium = Number(argv[++i]);
    else if (argv[i] === "--online") opts.online = true;
    else files.push(argv[i]);
  }
  if (files.length !== 1 || !(opts.seconds > 0) || !(opts.reportError >= 0 && opts.reportError <= 1) || !(opts.speed > 0) || !Number.isInteger(opts.chromium) || opts.chromium < 0) {
    console.error("usage: node sim_participant.mjs [--dataset DIR] [--seconds S > 0] [--report-error P in 0..1] [--speed F > 0] [--chromium K >= 0] [--online] SESSIONS_FILE");
    process.exit(2);
  }
  const prims = loadPrimitives(opts.dataset) ?? generatedPrimitives();
  const lines = fs.readFileSync(files[0], "utf8").split("\n").filter((l) => l.trim());
  const browser = opts.chromium > 0
    ? await (await import("playwright-core")).chromium.launch({ executablePath: "/usr/bin/chromium", args: ["--headless", "--no-sandbox", "--disable-gpu"] })
    : null;
  const people = lines.map((line, i) => {
    const [url, token, extra, more] = line.trim().split(/\s+/);
    const drop = /^drop:(\d+(?:\.\d+)?):(\d+(?:\.\d+)?)$/.exec(extra ?? "");
    if (!/^https?:\/\//.test(url ?? "") || !token || (extra && !drop) || more || (drop && i < opts.chromium))
      throw new Error(`${files[0]}:${i + 1}: expected "URL TOKEN" or "URL TOKEN drop:AT:AWAY" (seconds; not for a --chromium participant), got '${line}'`);
    const o = { url, token, primitives: prims, seed: i + 1, reportError: opts.reportError, speed: opts.speed, online: opts.online,
                drop: drop ? { at: Number(drop[1]), away: Number(drop[2]) } : null };
    return i < opts.chromium ? new ChromiumParticipant(o, browser) : new SimParticipant(o);
  });
  for (const p of people) if (p.open) await p.open();
  const cpu0 = process.cpuUsage();
  people.forEach((p) => p.start());
  // --online: until each is done or refused (S seconds at most); else S seconds.
  let timer;
  const ended = opts.online ? Promise.all(people.map((p) => p.finished)) : new Promise(() => {});
  await Promise.race([ended, new Promise((r) => { timer = setTimeout(r, opts.seconds * 1000); })]);
  clearTimeout(timer);
  await Promise.all(people.map((p) => p.stop()));
  await browser?.close();
  await new Promise((r) => setTimeout(r, 200));
  for (const p of people) console.log(JSON.stringify(p.summary()));
  const cpu = process.cpuUsage(cpu0);
  console.log(JSON.stringify({ clients_cpu_s: (cpu.user + cpu.system) / 1e6, seconds: opts.seconds }));
}

if (import.meta.url === `file://${process.argv[1]}`) main(process.argv.slice(2)).catch((e) => { console.error(String(e.message ?? e)); process.exit(1); });
