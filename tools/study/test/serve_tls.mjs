#!/usr/bin/env node
// The certificate of `dyad study serve --tls-certificate` refused where it must be (serve_tls_test.sh):
//   node serve_tls.mjs HOST:PORT TOKEN UNTRUSTED_HOME
// - Chromium with an empty NSS database (UNTRUSTED_HOME) refuses the certificate;
// - http:// to the same port gets no page.
import { chromium } from "playwright-core";

const [hostPort, token, untrustedHome] = process.argv.slice(2);
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
  env: { ...process.env, HOME: untrustedHome },
});
try {
  const page = await (await browser.newContext()).newPage();
  let error = "";
  try { await page.goto(`https://${hostPort}/subject?token=${token}`, { timeout: 5000 }); } catch (e) { error = e.message; }
  check(/ERR_CERT_AUTHORITY_INVALID/.test(error), "a browser without the web CA did not refuse the certificate: " + (error.split("\n")[0] || "page opened"));
  let plain = "answered";
  try { await page.goto(`http://${hostPort}/subject?token=${token}`, { timeout: 5000 }); } catch (e) { plain = e.message.split("\n")[0]; }
  check(plain !== "answered", "plain HTTP on the TLS port served the page");
} finally {
  await browser.close();
}
for (const f of failures) console.error("FAIL: " + f);
console.log(failures.length ? "FAILED" : "untrusted browser refused the certificate; plain HTTP got no page");
process.exit(failures.length ? 1 : 0);
