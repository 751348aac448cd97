#!/usr/bin/env node
// The participants of bench_capacity.sh's serve mode (CAPACITY_FRONT=serve): sim_participant.mjs's
// own --online participants (SimParticipant, and ChromiumParticipant for the first K: the real
// page in Debian's Chromium), in this one Node process, arriving one after another as the direct
// mode's sessions start: participant i opens their link once participant i-1's trial has said
// hello (its graph is up and relayed), or has ended, or after --arrive-timeout s.
//
//   node online_clients.mjs [--dataset DIR] [--chromium K] [--cap S] [--arrive-timeout S]
//                           --in FILE SESSIONS_FILE
//     SESSIONS_FILE: "URL TOKEN" a line (URL: the front's, http://127.0.0.1:PORT).
//     --in FILE: written once every participant has had their hello (or failed to):
//                "<ms since the epoch> <how many had a hello>"; the bench's window starts there.
//     --cap S: the whole run at most (default 600); it ends earlier when every participant is done
//              or refused.
// Prints one JSON line per participant: sim_participant.mjs's summary (pointer samples, acks and
// their round trip through the front's relay, trials, the completion code, refused, pongs) plus
// ready_ms (the Ready press), hello_ms (their trial's first hello, relayed from the graph's web
// component), done_ms (done or refused; ms since the epoch, null: never), ready_to_hello_ms; then
// {"clients_cpu_s", "seconds"} for this process. For Chromium participants the hello is seen by
// polling the page (every 200 ms) and Ready when its click returns.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const simPath = path.join(here, "../../components/web/test/node/sim_participant.mjs");
const { SimParticipant, ChromiumParticipant, loadPrimitives, generatedPrimitives } = await import(simPath);
const wallMs = () => performance.timeOrigin + performance.now();

// Adds the arrival's times to a participant of either class (trials counts trial starts).
function timed(p) {
  p.readyMs = null, p.helloMs = null, p.doneMs = null;
  let trials = p.trials;
  Object.defineProperty(p, "trials", {
    get: () => trials,
    set: (v) => { if (v > trials && p.helloMs === null) p.helloMs = wallMs(); trials = v; },
  });
  p.finished.then(() => { p.doneMs = wallMs(); });
  const summary = p.summary.bind(p);
  p.summary = () => ({ ...summary(), ready_ms: p.readyMs, hello_ms: p.helloMs, done_ms: p.doneMs,
                       ready_to_hello_ms: p.readyMs !== null && p.helloMs !== null ? p.helloMs - p.readyMs : null });
  return p;
}

class TimedSim extends SimParticipant {
  connect() {  // its Ready: the last one sent before the trial's hello
    super.connect();
    const ws = this.ws, send = ws.send.bind(ws);
    ws.send = (data, ...rest) => {
      if (this.helloMs === null && typeof data === "string" && data.includes('"op":"ready"')) this.readyMs = wallMs();
      return send(data, ...rest);
    };
  }
}

class TimedChromium extends ChromiumParticipant {
  async open() {
    await super.open();
    const click = this.page.click.bind(this.page);
    this.page.click = async (selector, options) => {
      const r = await click(selector, options);
      if (selector === "#ready" && this.helloMs === null) this.readyMs = wallMs();
      return r;
    };
  }
}

function parse(argv) {
  const o = { dataset: "", chromium: 0, cap: 600, arriveTimeout: 60, in: "", file: "" };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === "--dataset") o.dataset = argv[++i];
    else if (a === "--chromium") o.chromium = Number(argv[++i]);
    else if (a === "--cap") o.cap = Number(argv[++i]);
    else if (a === "--arrive-timeout") o.arriveTimeout = Number(argv[++i]);
    else if (a === "--in") o.in = argv[++i];
    else if (!o.file) o.file = a;
    else o.file = null;
  }
  if (!o.file || !o.in || !(o.cap > 0) || !(o.arriveTimeout > 0) || !Number.isInteger(o.chromium) || o.chromium < 0) {
    console.error("usage: node online_clients.mjs [--dataset DIR] [--chromium K >= 0] [--cap S > 0] [--arrive-timeout S > 0] --in FILE SESSIONS_FILE");
    process.exit(2);
  }
  return o;
}

// Until p's trial said hello or p ended, at most `ms`.
async function arrived(p, ms) {
  const until = Date.now() + ms;
  while (p.helloMs === null && p.doneMs === null && Date.now() < until) await new Promise((r) => setTimeout(r, 20));
}

async function main(argv) {
  const o = parse(argv);
  // Stopped (the bench's cleanup, Ctrl-C): exit at once; playwright's exit hook kills Chromium's
  // process group (its own SIGTERM handler would close the browser and leave this process running).
  for (const [signal, code] of [["SIGINT", 130], ["SIGTERM", 143], ["SIGHUP", 129]]) process.on(signal, () => process.exit(code));
  const prims = loadPrimitives(o.dataset) ?? generatedPrimitives();
  const lines = fs.readFileSync(o.file, "utf8").split("\n").filter((l) => l.trim());
  const browser = o.chromium > 0
    ? await createRequire(simPath)("playwright-core").chromium.launch({ executablePath: "/usr/bin/chromium", args: ["--headless", "--no-sandbox", "--disable-gpu"],
                                                         handleSIGINT: false, handleSIGTERM: false, handleSIGHUP: false })
    : null;
  const people = lines.map((line, i) => {
    const [url, token, more] = line.trim().split(/\s+/);
    if (!/^https?:\/\//.test(url ?? "") || !token || more) throw new Error(`${o.file}:${i + 1}: expected "URL TOKEN", got '${line}'`);
    const options = { url, token, primitives: prims, seed: i + 1, online: true };
    return timed(i < o.chromium ? new TimedChromium(options, browser) : new TimedSim(options));
  });
  const t0 = Date.now(), cpu0 = process.cpuUsage();
  let cap;
  const capped = new Promise((r) => { cap = setTimeout(r, o.cap * 1000); });
  const started = [];
  const arrivals = (async () => {
    for (const p of people) {
      if (p.open) await p.open();
      p.start();
      started.push(p);
      await arrived(p, o.arriveTimeout * 1000);
    }
    fs.writeFileSync(o.in, `${Math.round(wallMs())} ${people.filter((p) => p.helloMs !== null).length}\n`);
  })();
  await Promise.race([arrivals.then(() => Promise.all(people.map((p) => p.finished))), capped]);
  clearTimeout(cap);
  await Promise.all(started.map((p) => p.stop()));
  await browser?.close();
  await new Promise((r) => setTimeout(r, 200));
  for (const p of people) console.log(JSON.stringify(p.summary()));
  const cpu = process.cpuUsage(cpu0);
  console.log(JSON.stringify({ clients_cpu_s: (cpu.user + cpu.system) / 1e6, seconds: (Date.now() - t0) / 1000 }));
  process.exit(0);  // a participant never started keeps no timer; an open page's does
}

main(process.argv.slice(2)).catch((e) => { console.error(String(e.stack ?? e)); process.exit(1); });
