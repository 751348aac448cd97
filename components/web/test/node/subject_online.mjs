#!/usr/bin/env node
// The subject's page between trials as `dyad study serve` drives it, in Debian's Chromium
// (headless, playwright-core), against a small server here that speaks the front's side of the
// protocol (docs/components.md#web, "Between trials"; the page file itself, not a build's copy):
//   node subject_online.mjs PAGE_FILE SCREENSHOT_DIR
// Participant 1: a ping is answered with its id; the consent text is shown as written (the mouse
//   moving over it sends no pointer samples: no graph said hello), "I agree"
//   answers {"op":"consent","agree":true}; each 1012 close is followed by a new socket at once
//   (well under the page's one-second retry); "Start trial 1 of 1" is a button that answers
//   {"op":"ready"} once; the trial's hello makes the page steer, a ping meanwhile is answered;
//   after the trial the done view shows the completion code, Copy puts it on the clipboard, and
//   when the front closes that socket the page does not come back.
// Participant 2: a lab lobby's waiting message (no ready) shows no button; the consent's "I do not
//   agree" answers agree false.
// Participant 3: refused (the link open twice), closed 1008: the message stays, no new socket.
// Fails (exit 1) at the first thing the page gets wrong.
import fs from "node:fs";
import http from "node:http";
import { chromium } from "playwright-core";
import { WebSocketServer } from "ws";

const [pageFile, shotDir] = process.argv.slice(2);
const html = fs.readFileSync(pageFile);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// The front: every socket to /subject/ws is queued with its token, its messages queued too.
const sockets = [];
let socketWaiter = null;
const server = http.createServer((req, res) => {
  if (req.url.startsWith("/subject?")) { res.writeHead(200, { "Content-Type": "text/html; charset=utf-8" }); res.end(html); return; }
  res.writeHead(404); res.end();
});
const wss = new WebSocketServer({ noServer: true });
server.on("upgrade", (req, socket, head) => {
  if (!req.url.startsWith("/subject/ws?")) { socket.destroy(); return; }
  wss.handleUpgrade(req, socket, head, (ws) => {
    const conn = { ws, token: new URL(req.url, "http://x").searchParams.get("token"), at: Date.now(), inbox: [], waiter: null };
    ws.on("message", (data) => {
      conn.inbox.push(JSON.parse(String(data)));
      if (conn.waiter) { const w = conn.waiter; conn.waiter = null; w(); }
    });
    sockets.push(conn);
    if (socketWaiter) { const w = socketWaiter; socketWaiter = null; w(); }
  });
});
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const base = `http://127.0.0.1:${server.address().port}`;

async function within(ms, what, ready) {
  const until = Date.now() + ms;
  for (;;) {
    const v = await ready();
    if (v) return v;
    if (Date.now() > until) throw new Error(`${what}: not within ${ms} ms`);
    await sleep(10);
  }
}
// The next socket of `token` (a new one after `after` sockets were seen).
async function nextSocket(token, after, ms = 3000) {
  return within(ms, `a socket for ${token}`, () => sockets.slice(after).find((c) => c.token === token));
}
// The next message of op `op` on `conn` (others before it are dropped).
async function nextMessage(conn, op, ms = 3000) {
  return within(ms, `{"op":"${op}"} from the page`, () => {
    while (conn.inbox.length) { const m = conn.inbox.shift(); if (m.op === op) return m; }
    return null;
  });
}
const send = (conn, m) => conn.ws.send(JSON.stringify(m));
// Closes `conn` with 1012 and waits for the page's next socket: it must come at once.
async function phaseChange(conn, token) {
  const n = sockets.length, closed = Date.now();
  conn.ws.close(1012, "the next part");
  const next = await nextSocket(token, n);
  const gap = next.at - closed;
  if (gap > 500) throw new Error(`after a 1012 close the page came back after ${gap} ms (want at once)`);
  return next;
}
const text = (page, sel) => page.textContent(sel);
const visible = (page, sel) => page.isVisible(sel);

const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
const gaps = [];
try {
  // Participant 1: consent, ready, the trial, done.
  const ctx = await browser.newContext({ viewport: { width: 900, height: 700 } });
  await ctx.grantPermissions(["clipboard-read", "clipboard-write"], { origin: base });
  const page = await ctx.newPage();
  await page.goto(base + "/subject?token=participant-one-token");
  let c = await nextSocket("participant-one-token", 0);
  send(c, { op: "ping", id: 41 });
  if ((await nextMessage(c, "pong")).id !== 41) throw new Error("the pong's id is not the ping's");
  const consent = "This study is about drawing with a robot.\n\nYou may stop at any time.";
  send(c, { op: "consent", text: consent });
  await page.waitForSelector("#consent.on", { timeout: 3000 });
  if ((await page.$eval("#consent-text", (e) => e.innerText)) !== consent) throw new Error("the consent text is not shown as written");
  await page.screenshot({ path: `${shotDir}/online_consent.png` });
  // No graph on this socket: the mouse moving over the page sends nothing to the front.
  for (const [x, y] of [[100, 100], [300, 200], [500, 600]]) await page.mouse.move(x, y);
  await sleep(100);
  if (c.inbox.some((m) => m.op === "pointer")) throw new Error("pointer samples to the front between trials");
  await page.click("#agree");
  if ((await nextMessage(c, "consent")).agree !== true) throw new Error("I agree did not answer agree: true");
  let t = Date.now();
  c = await phaseChange(c, "participant-one-token");
  gaps.push(c.at - t);
  if (await visible(page, "#agree")) throw new Error("the consent buttons are still shown after its socket closed");
  send(c, { op: "waiting", message: "Trial 1 of 1: draw with the robot for 4 seconds.", ready: { label: "Start trial 1 of 1" } });
  await page.waitForFunction(() => document.getElementById("ready").textContent === "Start trial 1 of 1", null, { timeout: 3000 });
  if ((await text(page, "#waiting-text")) !== "Trial 1 of 1: draw with the robot for 4 seconds.") throw new Error("the waiting message");
  await page.screenshot({ path: `${shotDir}/online_ready.png` });
  await page.click("#ready");
  await nextMessage(c, "ready");
  await page.click("#ready", { force: true, timeout: 1000 }).catch(() => {});  // disabled now: no second ready
  await sleep(200);
  if (c.inbox.some((m) => m.op === "ready")) throw new Error("Ready answered twice");
  t = Date.now();
  c = await phaseChange(c, "participant-one-token");
  gaps.push(c.at - t);
  // The trial: the relayed graph's hello; the front's ping beside it.
  send(c, { op: "hello", role: "subject", steering: true, half_width: 50, engage_key: "Space", primitives: [], names: [], watermark: false, ask: false });
  await page.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 3000 });
  if (await visible(page, "#waiting")) throw new Error("the waiting view is still shown during the trial");
  send(c, { op: "ping", id: 42 });
  if ((await nextMessage(c, "pong")).id !== 42) throw new Error("the pong during the trial");
  t = Date.now();
  c = await phaseChange(c, "participant-one-token");
  gaps.push(c.at - t);
  send(c, { op: "done", message: "Thank you for taking part!", code: "C0DE-7F3A" });
  await page.waitForSelector("#done.on", { timeout: 3000 });
  if ((await text(page, "#done-message")) !== "Thank you for taking part!" || (await text(page, "#done-code")) !== "C0DE-7F3A")
    throw new Error("the done view: " + (await text(page, "#done")));
  await page.click("#copy");
  await page.waitForFunction(() => document.getElementById("copy").textContent !== "Copy", null, { timeout: 2000 });
  const copied = await page.evaluate(() => navigator.clipboard.readText());
  if (copied !== "C0DE-7F3A") throw new Error(`Copy put '${copied}' on the clipboard`);
  await page.screenshot({ path: `${shotDir}/online_done.png` });
  let n = sockets.length;
  c.ws.close(1000, "done");
  await sleep(1800);
  if (sockets.length !== n) throw new Error("the page came back after done");
  if (!(await visible(page, "#done-code"))) throw new Error("the code is gone after the socket closed");

  // Participant 2: a lab lobby's waiting (no button), then consent declined.
  const page2 = await (await browser.newContext()).newPage();
  await page2.goto(base + "/subject?token=participant-two-token");
  c = await nextSocket("participant-two-token", n);
  send(c, { op: "waiting", message: "Welcome. Please wait." });
  await page2.waitForFunction(() => document.getElementById("waiting").textContent === "Welcome. Please wait.", null, { timeout: 3000 });
  if (await visible(page2, "#ready")) throw new Error("a Ready button without ready");
  send(c, { op: "consent", text: "Consent?" });
  await page2.waitForSelector("#consent.on", { timeout: 3000 });
  await page2.click("#decline");
  if ((await nextMessage(c, "consent")).agree !== false) throw new Error("I do not agree did not answer agree: false");

  // Participant 3: refused, closed 1008: the message stays, the page does not come back.
  n = sockets.length;
  const page3 = await (await browser.newContext()).newPage();
  await page3.goto(base + "/subject?token=participant-three-token");
  c = await nextSocket("participant-three-token", n);
  send(c, { op: "refused", message: "This link is already open in another window." });
  await sleep(100);
  c.ws.close(1008, "refused");
  await sleep(1800);
  if (sockets.length !== n + 1) throw new Error("the refused page came back");
  if ((await text(page3, "#waiting")) !== "This link is already open in another window.") throw new Error("the refusal: " + (await text(page3, "#waiting")));
  await page3.screenshot({ path: `${shotDir}/online_refused.png` });
} finally {
  await browser.close();
  server.close();
}
console.log(`the online page: consent, ready, trial, done, refused; new sockets ${gaps.join(", ")} ms after each 1012 close`);
