#!/usr/bin/env node
// A stand-in for `dyad study serve`'s front, for testing the clients of its protocol (the
// subject's page in a browser, sim_participant.mjs --online) without a study: it serves the
// page file at /subject?token=T and speaks the front's side on /subject/ws?token=T:
//   node online_front.mjs PAGE_FILE PORT_FILE TRIALS TRIAL_MS
// Each token goes: consent -> (agree) -> waiting with "Start trial k of TRIALS" -> (ready) -> a
// trial: a new socket (1012 before it), a hello that makes it steer and a ping, TRIAL_MS long,
// then 1012 -> the next waiting ... -> done with the code "CODE-<token>". A socket that comes
// back during a trial (after a lost connection) gets the hello again; a trial ends on time whether
// the page is there or not (a page away then gets the next view when it comes). A token starting with
// "refused" gets {"op":"refused"} and a 1008 close. Each phase is answered on a fresh socket, as
// the front does. On SIGTERM it prints one JSON line per token: trials run, pointer samples in
// trials (engaged ones apart) and between them, pongs and whether each pong's id was a ping's,
// declined, done, sockets opened again during a trial and the longest time away during one (ms). Writes its port to PORT_FILE once it listens.
import fs from "node:fs";
import http from "node:http";
import { WebSocketServer } from "ws";

const [pageFile, portFile, trialsArg, trialMsArg] = process.argv.slice(2);
const trials = Number(trialsArg), trialMs = Number(trialMsArg);
if (!pageFile || !portFile || !(trials >= 1) || !(trialMs > 0)) {
  console.error("usage: node online_front.mjs PAGE_FILE PORT_FILE TRIALS TRIAL_MS");
  process.exit(2);
}
const html = fs.readFileSync(pageFile);
const people = new Map();  // token -> its state and counts
const person = (token) => {
  if (!people.has(token))
    people.set(token, { token, phase: "consent", next: 1, trials: 0, in_trial: 0, engaged: 0, between: 0, pongs: 0, bad_pongs: 0,
                        declined: false, done: false, returns: 0, away_ms: 0, pings: new Set(), n: 0, ws: null, left: 0, started: false });
  return people.get(token);
};
const json = (ws, m) => ws.send(JSON.stringify(m));

function open(ws, p) {
  if (p.token.startsWith("refused")) {
    json(ws, { op: "refused", message: "This link is already open in another window." });
    return setTimeout(() => ws.close(1008, "refused"), 50);
  }
  const ping = () => { const id = ++p.n; p.pings.add(id); json(ws, { op: "ping", id }); };
  ping();
  if (p.phase === "consent") json(ws, { op: "consent", text: "Do you agree?" });
  else if (p.phase === "waiting") json(ws, { op: "waiting", message: "Trial " + p.next + " of " + trials, ready: { label: "Start trial " + p.next + " of " + trials } });
  else if (p.phase === "trial") {
    ws.trial = true;
    json(ws, { op: "hello", role: "subject", steering: true, half_width: 50, engage_key: "Space", primitives: [], names: [], watermark: false, ask: false });
    setTimeout(ping, trialMs / 2);
    if (p.started) {  // back during the trial
      p.returns++, p.away_ms = Math.max(p.away_ms, Date.now() - p.left);
      return;
    }
    p.trials++, p.started = true;
    setTimeout(() => {
      p.next++, p.started = false;
      p.phase = p.next > trials ? "done" : "waiting";
      if (p.ws?.readyState === 1) p.ws.close(1012, "the trial is over");
    }, trialMs);
  } else if (p.phase === "done") {
    p.done = true;
    json(ws, { op: "done", message: "Thank you!", code: "CODE-" + p.token });
  } else if (p.phase === "declined") json(ws, { op: "waiting", message: "You did not agree: nothing was recorded." });
}

function onText(ws, p, m) {
  if (m.op === "pong") { p.pongs++; if (!p.pings.delete(m.id)) p.bad_pongs++; }
  else if (m.op === "pointer") {
    if (!ws.trial) p.between++;  // on a socket opened between trials (a trial's in-flight samples are its own)
    else { p.in_trial++; if (m.engaged) p.engaged++; }
  } else if (m.op === "consent" && p.phase === "consent") {
    p.phase = m.agree ? "waiting" : "declined", p.declined = !m.agree;
    ws.close(1012, "consent");
  } else if (m.op === "ready" && p.phase === "waiting") {
    p.phase = "trial";
    ws.close(1012, "a trial starts");
  }
}

const server = http.createServer((req, res) => {
  if (req.url.startsWith("/subject?")) { res.writeHead(200, { "Content-Type": "text/html; charset=utf-8" }); res.end(html); return; }
  res.writeHead(404); res.end();
});
const wss = new WebSocketServer({ noServer: true });
server.on("upgrade", (req, socket, head) => {
  const url = new URL(req.url, "http://x");
  if (url.pathname !== "/subject/ws" || !url.searchParams.get("token")) { socket.destroy(); return; }
  wss.handleUpgrade(req, socket, head, (ws) => {
    const p = person(url.searchParams.get("token"));
    p.ws = ws;
    ws.on("message", (data) => onText(ws, p, JSON.parse(String(data))));
    ws.on("close", () => { if (p.ws === ws) p.left = Date.now(); });
    open(ws, p);
  });
});
server.listen(0, "127.0.0.1", () => fs.writeFileSync(portFile, String(server.address().port) + "\n"));
process.on("SIGTERM", () => {
  for (const p of people.values()) {
    const { pings, n, next, ws, left, started, ...out } = p;  // eslint-disable-line no-unused-vars
    console.log(JSON.stringify(out));
  }
  process.exit(0);
});
