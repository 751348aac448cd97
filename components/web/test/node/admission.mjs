#!/usr/bin/env node
// Who may connect and who steers (web component):
//   node admission.mjs BASE_WS TOKEN
// - without the token (the graph set one) a client is refused; with ?token= it is admitted;
// - a browser Origin that is not allowed is refused; a localhost one is admitted;
// - two subject pages: the first steers, the second watches (its pointer is not published: no
//   ack); when the first leaves, the second is told it steers and its pointer is published.
import WebSocket from "ws";

const [base, token] = process.argv.slice(2);
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };

function open(path, opts = {}) {
  return new Promise((resolve) => {
    const ws = new WebSocket(base + path, opts.protocols ?? [], { headers: opts.headers ?? {} });
    const messages = [];
    ws.on("message", (d) => messages.push(JSON.parse(d.toString())));
    ws.on("open", () => resolve({ ws, messages, ok: true }));
    ws.on("error", () => resolve({ ws, messages, ok: false }));
    ws.on("unexpected-response", () => resolve({ ws, messages, ok: false }));
  });
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const q = `?token=${token}`;

const noToken = await open("/", { protocols: ["foxglove.websocket.v1"] });
check(!noToken.ok, "a Foxglove client without the token was admitted");
const withToken = await open("/" + q, { protocols: ["foxglove.websocket.v1"] });
check(withToken.ok, "a Foxglove client with the token was refused");
withToken.ws.close();
const evil = await open("/subject/ws" + q, { headers: { Origin: "http://evil.example" } });
check(!evil.ok, "a page from another origin was admitted");
const local = await open("/subject/ws" + q, { headers: { Origin: "http://localhost:1234" } });
check(local.ok, "a page from localhost was refused");

const second = await open("/subject/ws" + q);  // `local` came first: it steers
await sleep(300);
check(local.messages.find((m) => m.op === "hello")?.steering === true, "the first page does not steer");
check(second.messages.find((m) => m.op === "hello")?.steering === false, "the second page steers too");
second.ws.send(JSON.stringify({ op: "pointer", x: 1, y: 2, engaged: true, t: 1 }));
local.ws.send(JSON.stringify({ op: "pointer", x: 3, y: 4, engaged: true, t: 2 }));
await sleep(300);
check(!second.messages.some((m) => m.op === "ack"), "the watching page's pointer was published");
check(local.messages.some((m) => m.op === "ack" && m.t === 2), "the steering page's pointer was not published");
local.ws.close();
await sleep(300);
check(second.messages.some((m) => m.op === "role" && m.steering === true), "the second page was not handed the steering");
second.ws.send(JSON.stringify({ op: "pointer", x: 5, y: 6, engaged: true, t: 3 }));
await sleep(300);
check(second.messages.some((m) => m.op === "ack" && m.t === 3), "the new steering page's pointer was not published");
second.ws.close();
for (const f of failures) console.error("FAIL: " + f);
console.log(failures.length ? "FAILED" : "PASS");
process.exit(failures.length ? 1 : 0);
