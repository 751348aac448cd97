// What goes wrong online (#45 item 3), against `dyad study serve` run here (serve_test.sh makes
// the study): each case a scripted page, its frames and close codes checked, and the session log
// read back. Throws (exit 1) at the first case that fails, naming it.
//   node serve_cases.mjs DYAD STUDY_FILE DATA_DIR
import { spawn, spawnSync } from "node:child_process";
import fs from "node:fs";
import http from "node:http";
import WebSocket from "ws";

const [dyad, studyFile, data] = process.argv.slice(2);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const token = (p) => fs.readFileSync(`${data}/${p}/web-tokens`, "utf8").match(/^subject (\S+)$/m)[1];
const log = (p) => fs.existsSync(`${data}/${p}/session.log`)
  ? fs.readFileSync(`${data}/${p}/session.log`, "utf8").split("\n").filter((l) => l).map((l) => JSON.parse(l)) : [];
function check(ok, what) { if (!ok) throw new Error(what); }
// The session log's end of `trial` (the latest), once written (within `ms`).
async function ended(p, trial, ms = 10000) {
  const find = () => log(p).filter((e) => e.event === "end" && e.trial === trial).pop();
  for (let t = 0; t < ms && !find(); t += 100) await sleep(100);
  return find();
}

// `dyad study serve` on a free port; its output kept for the failure message.
class Front {
  async start() {
    fs.rmSync("port", { force: true });
    this.out = "";
    this.proc = spawn(dyad, ["study", "serve", studyFile, "--port", "0", "--port-file", "port"], { stdio: ["ignore", "pipe", "pipe"] });
    this.proc.stdout.on("data", (d) => { this.out += d; });
    this.proc.stderr.on("data", (d) => { this.out += d; });
    this.exited = new Promise((r) => this.proc.on("exit", (code, signal) => r(code ?? signal)));
    for (let i = 0; i < 100 && !(fs.existsSync("port") && fs.readFileSync("port", "utf8").trim()); i++) await sleep(100);
    this.port = Number(fs.readFileSync("port", "utf8"));
    this.url = `http://127.0.0.1:${this.port}`;
  }
  async stop(signal) {
    this.proc.kill(signal);
    return await this.exited;
  }
}

// One subject's page: its frames in order (pings answered and not kept), its close code.
class Page {
  constructor(front, tok, options = {}, silent = false) {
    this.frames = [];
    this.waiters = [];
    this.ws = new WebSocket(`ws://127.0.0.1:${front.port}/subject/ws?token=${tok}`, options);
    this.opened = new Promise((resolve, reject) => {
      this.ws.on("open", resolve);
      this.ws.on("unexpected-response", (req, res) => resolve(res.statusCode));
      this.ws.on("error", reject);
    });
    this.closed = new Promise((r) => this.ws.on("close", (code) => r(code)));
    this.ws.on("message", (d) => {
      const m = JSON.parse(String(d));
      if (m.op === "ping") return silent ? undefined : this.send({ op: "pong", id: m.id });
      this.frames.push(m);
      this.waiters = this.waiters.filter((w) => !w());
    });
  }
  send(m) { if (this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(m)); }
  // The first frame (from now on or already here) with op `op`, within `ms`.
  next(op, ms = 10000) {
    return new Promise((resolve, reject) => {
      const t = setTimeout(() => reject(new Error(`no '${op}' within ${ms} ms; frames: ${JSON.stringify(this.frames.map((f) => f.op))}`)), ms);
      const w = () => {
        const i = this.frames.findIndex((f) => f.op === op);
        if (i < 0) return false;
        clearTimeout(t);
        resolve(this.frames.splice(0, i + 1)[i]);
        return true;
      };
      if (!w()) this.waiters.push(w);
    });
  }
  // Steers for `ms`: engaged pointer samples every 50 ms (the page's keepalive), as a person holding.
  async steer(ms) {
    for (let t = 0; t < ms; t += 50) {
      this.send({ op: "pointer", x: 0.5 + 0.2 * Math.sin(t / 300), y: 0.5, engaged: true, t: Date.now(), wall: Date.now() });
      await sleep(50);
    }
    this.send({ op: "pointer", x: 0.5, y: 0.5, engaged: false, t: Date.now(), wall: Date.now() });
  }
}

// The page after Ready (or a 1012) reconnected to the trial's graph: its hello relayed.
async function intoTrial(front, tok) {
  const page = new Page(front, tok);
  await page.next("hello", 15000);
  return page;
}

function statusAt(port, path, localAddress) {
  return new Promise((resolve, reject) =>
    http.get({ host: "127.0.0.1", port, path, localAddress }, (res) => { res.resume(); resolve(res.statusCode); }).on("error", reject));
}
const status = (front, path, localAddress) => statusAt(front.port, path, localAddress);

async function unknownTokens(front) {
  check(await status(front, `/subject?token=${token("P01")}`) === 200, "a participant's link opens the page");
  check(await status(front, "/subject?token=0123456789abcdef0123456789abcdef") === 404, "an unknown token's page is 404");
  const ws = new Page(front, "0123456789abcdef0123456789abcdef");
  check(await ws.opened === 404, "an unknown token's handshake is 404");
  // Another address (127.0.0.2) guesses: 404 ten times, then 429 for its unknown tokens; its known
  // tokens still open (behind a proxy every participant shares the guesser's address); 127.0.0.1 is unaffected.
  const codes = [];
  for (let i = 0; i < 12; i++) codes.push(await status(front, `/subject?token=guess${i}`, "127.0.0.2"));
  check(codes.slice(0, 11).every((c) => c === 404) && codes[11] === 429, `10 guesses then 429: ${codes}`);
  check(await status(front, `/subject?token=guess-more`, "127.0.0.2") === 429, "a guessing address is refused a minute");
  check(await status(front, `/subject?token=${token("P01")}`, "127.0.0.2") === 200, "a known token from the guessing address opens");
  const known = new Page(front, token("P02"), { localAddress: "127.0.0.2" });
  check((await known.next("consent")).op === "consent", "a known token's socket from the guessing address opens");
  known.ws.close();
  await known.closed;
  check(await status(front, `/subject?token=${token("P01")}`) === 200, "another address is not limited");
  console.log("ok: unknown tokens 404, an address guessing 429");
}

// A participant whose session the lab holds (its session.lock, as `dyad study run` holds it) is asked to come back.
async function heldByTheLab(front) {
  const holder = spawn("flock", [`${data}/P04/session.lock`, "sleep", "3"]);
  const exited = new Promise((r) => holder.on("exit", r));
  await sleep(300);
  const page = new Page(front, token("P04"));
  const refused = await page.next("refused");
  check(/open elsewhere/.test(refused.message) && await page.closed === 1008, `held by the lab: ${refused.message}`);
  await exited;
  console.log("ok: a session the lab holds is refused online, and the lab's study run while a page is live");
}

async function openTwiceAndMaxSessions(front) {
  const first = new Page(front, token("P01"));
  check((await first.next("consent")).text.includes("I agree"), "the consent page shows the study's text");
  const second = new Page(front, token("P01"));
  const refused = await second.next("refused");
  check(refused.message === "This link is already open in another window.", `open twice: ${refused.message}`);
  check(await second.closed === 1008, "the second page is closed with 1008");
  const p2 = new Page(front, token("P02"));
  await p2.next("consent");
  const p3 = new Page(front, token("P03"));  // max_sessions 2: P01 and P02 are live
  const full = await p3.next("refused");
  check(full.message.startsWith("Please come back later"), `max_sessions: ${full.message}`);
  check(await p3.closed === 1008, "refused at max_sessions: 1008");
  check(log("P03").length === 0, "nothing logged for a participant refused at max_sessions");
  // One runner per participant: the lab's `dyad study run` of P01 is refused while P01's page is live.
  const lab = spawnSync(dyad, ["study", "run", studyFile, "--participant", "P01", "--consent", "--yes"], { encoding: "utf8" });
  check(lab.status === 2 && lab.stderr.includes("holds P01's session"), `study run during the online session: ${lab.status} ${lab.stderr}`);
  check(!log("P01").length, "the refused study run marked nothing");
  p2.ws.close();
  await sleep(3600);  // P02's session stays live reconnect_s (3 s) after its page left
  // P02 comes back and declines: told so politely, closed (1008: the page stays), logged; the slot is free at once.
  const declining = new Page(front, token("P02"));
  await declining.next("consent");
  declining.send({ op: "consent", agree: false });
  check((await declining.next("refused")).message.startsWith("You did not agree"), "declined: a polite end");
  check(await declining.closed === 1008, "declined: the page is closed (1008)");
  check(log("P02").some((e) => e.event === "declined"), "declined: logged");
  const p3again = new Page(front, token("P03"));
  await p3again.next("consent");
  // P01 and P03 live (max_sessions 2): P02, who declined, reopening the link hears that, not "come back later".
  const reopened = new Page(front, token("P02"));
  const declined = await reopened.next("refused");
  check(declined.message.startsWith("You did not agree") && await reopened.closed === 1008, `declined at max_sessions: ${declined.message}`);
  p3again.ws.close();
  await p3again.closed;  // the front hears the close before P03's next page opens (else: open twice)
  console.log("ok: a link open twice is refused (1008); max_sessions refuses a new participant until a session ends; a declined consent ends politely");
  return first;
}

// A page whose connection died without a close answers no ping: a new page of its link replaces it.
async function silentPage(front) {
  const silent = new Page(front, token("P03"), {}, true);
  await silent.next("consent");
  check(await new Page(front, token("P03")).next("refused") !== undefined, "a live first page: the second is refused");
  await sleep(5500);  // 2 ping intervals + 1 s without a pong
  const fresh = new Page(front, token("P03"));
  await fresh.next("consent");
  check(await silent.closed === 1001, "the silent page is closed (1001)");
  // A frame over 16 KiB (a page's are a few hundred bytes) closes the page: 1009.
  fresh.ws.send(JSON.stringify({ op: "pong", pad: "x".repeat(20000) }));
  const big = await Promise.race([fresh.closed, sleep(3000).then(() => "still open")]);
  check(big === 1009, `a 20 KB frame closes the page with 1009: ${big}`);
  // A trial that cannot start (P03's token file no longer private: the graph would not get its
  // token) tells the page, which is closed (1008), instead of leaving its Ready pressed.
  const p3 = new Page(front, token("P03"));
  await p3.next("consent");
  p3.send({ op: "consent", agree: true });
  await p3.next("waiting");
  fs.chmodSync(`${data}/P03/web-tokens`, 0o644);
  p3.send({ op: "ready" });
  const cannot = await p3.next("refused", 5000).finally(() => fs.chmodSync(`${data}/P03/web-tokens`, 0o600));
  check(/Something went wrong on our side/.test(cannot.message) && await p3.closed === 1008, `cannot start: ${cannot.message}`);
  check(!log("P03").some((e) => e.event === "start"), "nothing started for P03");
  console.log("ok: a page silent for 5 s is replaced by a new page of its link; a 20 KB frame closes a page; a trial that cannot start tells its page");
}

// The trial's graph picked its own port (web.port=0 on its command line, no port of the front's
// choosing) and wrote it into the participant's folder; that port is the graph's web component.
// The `dyad run` processes of p's trials: [pid, argv].
function trialGraphs(p) {
  return fs.readdirSync("/proc").filter((d) => /^\d+$/.test(d)).map((d) => {
    try { return [Number(d), fs.readFileSync(`/proc/${d}/cmdline`, "utf8").split("\0")]; } catch { return [0, []]; }
  }).filter(([, a]) => a[1] === "run" && a.some((x) => x.startsWith(`recorder.file=`) && x.includes(`${data}/${p}/`)));
}

async function trialPort(p, trial) {
  const file = `${data}/${p}/.trial-${trial}.port`;
  check(fs.existsSync(file), `no port file ${file}`);
  const port = Number(fs.readFileSync(file, "utf8"));
  const runs = trialGraphs(p).map(([, a]) => a);
  check(runs.length === 1 && runs[0].includes("web.port=0") && runs[0].some((x) => x.startsWith("web.port_file=")),
    `the trial's graph binds port 0 and writes its port file: ${JSON.stringify(runs)}`);
  check(await statusAt(port, `/subject?token=${token(p)}`) === 200, `the port file's ${port} is the graph's web component`);
}

async function lostAndBack(front, p01) {
  for (let i = 0; i < 5; i++) p01.send({ op: "consent", agree: true });  // answered once, the rest ignored
  const waiting = await p01.next("waiting");
  check(waiting.ready?.label === "Start trial 1 of 2", `Ready: ${JSON.stringify(waiting)}`);
  await sleep(300);
  check(!p01.frames.some((f) => f.op === "waiting"), `5 consents, 1 view: ${JSON.stringify(p01.frames)}`);
  check(log("P01").filter((e) => e.event === "consent").length === 1, "5 consents, 1 logged");
  p01.send({ op: "ready" });
  check(await p01.closed === 1012, "the trial starts: the page's socket closed with 1012");
  let page = await intoTrial(front, token("P01"));
  await trialPort("P01", 1);
  await page.steer(1000);
  page.ws.terminate();  // the connection lost for 1 s (< reconnect_s): the trial goes on
  await sleep(1000);
  page = await intoTrial(front, token("P01"));
  await page.steer(1500);
  check(await page.closed === 1012, "the trial ended: 1012");
  const end = await ended("P01", 1);
  check(end?.outcome === "complete", `back in time: trial 1 complete: ${JSON.stringify(end)}`);
  check(!fs.existsSync(`${data}/P01/.trial-1.port`), "the trial's port file is removed at its end");
  console.log("ok: a page back within reconnect_s: the trial goes on, complete");
  // Trial 2: the page leaves for good: stopped after reconnect_s, incomplete with the reason.
  const next = new Page(front, token("P01"));
  check((await next.next("waiting")).ready?.label === "Start trial 2 of 2", "trial 2 comes next");
  next.send({ op: "ready" });
  await next.closed;
  (await intoTrial(front, token("P01"))).ws.terminate();
  const lost = await ended("P01", 2);
  check(lost?.outcome === "incomplete" && lost.incomplete === "the participant's connection was lost for more than 3 s",
    `lost: ${JSON.stringify(lost)}`);
  const back = new Page(front, token("P01"));
  const again = await back.next("waiting");
  check(again.ready?.label === "Start trial 2 of 2" && /starts again/.test(again.message), `repeated: ${JSON.stringify(again)}`);
  back.ws.close();
  await back.closed;
  console.log("ok: a page gone more than reconnect_s: the trial incomplete with its reason, then repeated");
}

async function restarts(front) {
  // SIGTERM mid-trial: the trial stopped as `study run` does; the next front repeats it.
  const p4 = new Page(front, token("P04"));
  await p4.next("consent");
  p4.send({ op: "consent", agree: true });
  await p4.next("waiting");
  p4.send({ op: "ready" });
  await p4.closed;
  await intoTrial(front, token("P04"));
  check(await front.stop("SIGTERM") === 0, `SIGTERM: exit 0\n${front.out}`);
  const stopped = await ended("P04", 1);
  check(stopped?.outcome === "stopped", `SIGTERM mid-trial: ${JSON.stringify(stopped)}`);
  await front.start();
  let page = new Page(front, token("P04"));
  check(/starts again/.test((await page.next("waiting")).message), "after a restart the trial is repeated");
  page.send({ op: "ready" });
  await page.closed;
  await intoTrial(front, token("P04"));
  // SIGKILL mid-trial: the graph ends by its parent-death signal; a start without its end.
  await front.stop("SIGKILL");
  await sleep(1500);
  const starts = log("P04").filter((e) => e.event === "start"), ends = log("P04").filter((e) => e.event === "end");
  check(starts.length === 2 && ends.length === 1, `SIGKILL: a start without its end: ${JSON.stringify(log("P04"))}`);
  check(starts[1].reason === "attempt 1 was stopped", `attempt 2's reason: ${starts[1].reason}`);
  await front.start();
  page = new Page(front, token("P04"));
  await page.next("waiting");
  page.send({ op: "ready" });
  await page.closed;
  await intoTrial(front, token("P04"));
  const third = log("P04").filter((e) => e.event === "start")[2];
  check(third?.attempt === 3 && third.reason === "the server restarted during attempt 2", `attempt 3: ${JSON.stringify(third)}`);
  // A graph that does not end (stopped here by SIGSTOP): SIGTERM, and the front waits for it; a
  // second SIGTERM exits at once, saying so; the graph ends by its parent-death SIGINT once it runs.
  const graphs = trialGraphs("P04");
  check(graphs.length === 1, `P04's trial graph: ${JSON.stringify(graphs)}`);
  process.kill(graphs[0][0], "SIGSTOP");
  front.proc.kill("SIGTERM");
  for (let t = 0; t < 5000 && !front.out.includes("dyad study serve: stopping"); t += 50) await sleep(50);
  const waiting = await Promise.race([front.exited, sleep(500).then(() => "waiting")]);
  check(waiting === "waiting", `the front waits for its trial's graph: ${waiting}`);
  front.proc.kill("SIGTERM");
  const second = await Promise.race([front.exited, sleep(3000).then(() => "still there")]);
  process.kill(graphs[0][0], "SIGCONT");
  check(second === 130 && front.out.includes("a second stop: exiting now"), `a second SIGTERM: ${second}`);
  console.log("ok: a second SIGTERM while the front waits for a trial's graph exits at once (130)");
  console.log("ok: restarts (SIGTERM, SIGKILL) keep the log; the unfinished trial is repeated with its reason");
}

const front = new Front();
try {
  await front.start();
  await unknownTokens(front);
  await heldByTheLab(front);
  const p01 = await openTwiceAndMaxSessions(front);
  await silentPage(front);
  await lostAndBack(front, p01);
  await restarts(front);
} catch (e) {
  console.error(`FAIL: ${e.message}\n--- dyad study serve:\n${front.out}`);
  front.proc?.kill("SIGKILL");
  process.exit(1);
}
process.exit(0);
