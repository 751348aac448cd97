#!/usr/bin/env node
// The subject's page over TLS (tls_browser_test.sh):
//   node tls_page.mjs HOST:PORT SUBJECT_TOKEN UNTRUSTED_HOME
// - Chromium with $HOME's NSS database (the web CA trusted) opens https://HOST:PORT/subject,
//   steers (its WebSocket is wss://), and moves the pointer while engaged;
// - Chromium with an empty NSS database (UNTRUSTED_HOME) refuses the certificate;
// - http:// to the same port gets no page.
import { chromium } from "playwright-core";

const [hostPort, token, untrustedHome] = process.argv.slice(2);
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };
const launch = (env) => chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
  env,
});

const trusted = await launch({ ...process.env });
try {
  const page = await (await trusted.newContext({ viewport: { width: 800, height: 600 } })).newPage();
  await page.goto(`https://${hostPort}/subject?token=${token}`);
  await page.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 10000 });
  const box = await page.evaluate(() => { const r = document.getElementById("canvas").getBoundingClientRect(); return { x: r.left + r.width / 2, y: r.top + r.height / 2 }; });
  await page.mouse.move(box.x, box.y);
  await page.mouse.down();
  for (let i = 0; i < 20; i++) { await page.mouse.move(box.x + 5 * i, box.y); await page.waitForTimeout(50); }
  await page.mouse.up();
  const rtts = await page.evaluate(() => window.dyadStats().rtts.length);
  check(rtts > 0, "no pointer sample acknowledged over wss");
  let plain = "answered";
  try { await page.goto(`http://${hostPort}/subject?token=${token}`, { timeout: 5000 }); } catch (e) { plain = e.message.split("\n")[0]; }
  check(plain !== "answered", "plain HTTP on the TLS port served the page");
} catch (e) {
  check(false, "trusted browser: " + e.message.split("\n")[0]);
} finally {
  await trusted.close();
}

const untrusted = await launch({ ...process.env, HOME: untrustedHome });
try {
  const page = await (await untrusted.newContext()).newPage();
  let error = "";
  try { await page.goto(`https://${hostPort}/subject?token=${token}`, { timeout: 5000 }); } catch (e) { error = e.message; }
  check(/ERR_CERT_AUTHORITY_INVALID/.test(error), "a browser without the web CA did not refuse the certificate: " + (error.split("\n")[0] || "page opened"));
} finally {
  await untrusted.close();
}
for (const f of failures) console.error("FAIL: " + f);
console.log(failures.length ? "FAILED" : "trusted browser steered over wss; untrusted one refused the certificate; plain HTTP refused");
process.exit(failures.length ? 1 : 0);
