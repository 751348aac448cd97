#!/usr/bin/env node
// The certificate of `dyad study serve --tls-certificate` where participants meet it (serve_tls_test.sh):
//   node serve_tls.mjs PORT TOKEN UNTRUSTED_HOME
// - Chromium with $HOME's NSS database (the web CA trusted), resolving study.test to 127.0.0.1,
//   opens the link as DATA/links.csv has it (https://study.test:PORT/subject?token=TOKEN): its
//   WebSocket is admitted (the consent page shows, which the front sends over it: TOKEN is a
//   participant who has not consented);
// - Chromium with an empty NSS database (UNTRUSTED_HOME) refuses the certificate;
// - http:// to the same port gets no page.
import { chromium } from "playwright-core";

const [port, token, untrustedHome] = process.argv.slice(2);
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };
const launch = (env, args = []) => chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking", ...args],
  env,
});

const trusted = await launch({ ...process.env }, ["--host-resolver-rules=MAP study.test 127.0.0.1"]);
try {
  const page = await (await trusted.newContext()).newPage();
  await page.goto(`https://study.test:${port}/subject?token=${token}`);
  const consent = await page.waitForFunction(() => document.getElementById("consent").classList.contains("on"), null, { timeout: 5000 })
    .then(() => true, () => false);
  check(consent, "the link at study.test (links.csv's host) did not get the consent page over wss (its origin refused?)");
} catch (e) {
  check(false, "trusted browser at study.test: " + e.message.split("\n")[0]);
} finally {
  await trusted.close();
}

const untrusted = await launch({ ...process.env, HOME: untrustedHome });
try {
  const page = await (await untrusted.newContext()).newPage();
  let error = "";
  try { await page.goto(`https://127.0.0.1:${port}/subject?token=${token}`, { timeout: 5000 }); } catch (e) { error = e.message; }
  check(/ERR_CERT_AUTHORITY_INVALID/.test(error), "a browser without the web CA did not refuse the certificate: " + (error.split("\n")[0] || "page opened"));
  let plain = "answered";
  try { await page.goto(`http://127.0.0.1:${port}/subject?token=${token}`, { timeout: 5000 }); } catch (e) { plain = e.message.split("\n")[0]; }
  check(plain !== "answered", "plain HTTP on the TLS port served the page");
} finally {
  await untrusted.close();
}
for (const f of failures) console.error("FAIL: " + f);
console.log(failures.length ? "FAILED" : "links' host got the consent page over wss; untrusted browser refused the certificate; plain HTTP got no page");
process.exit(failures.length ? 1 : 0);
