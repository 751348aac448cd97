#!/usr/bin/env node
// Live parameters from the experimenter's page in Debian's Chromium (headless, playwright-core;
// no browser download), for experimenter_params_test.sh:
//   node experimenter_params.mjs BASE_URL SCREENSHOT_DIR
// 0. its header shows the recording: rec.mcap, its samples growing, its size and time;
// 1. the experimenter's page sets mixer.gain to 0.25: its list shows "mixer.gain 0.9 → 0.25
//    (experimenter page)";
// 2. sets it to 7: the list shows the mixer's refusal ("must be <= 1, got 7");
// 3. gets it: "mixer.gain = 0.25";
// 4. a viewer's page lists the same answers, and when it asks, its socket is closed and nothing
//    more is answered.
import { chromium } from "playwright-core";

const [base, shotDir] = process.argv.slice(2);
const failures = [];
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
// The answers reach the page at most once a second: 10 s is ample, and a failure says what was listed.
const listed = (page) => page.evaluate(() => [...document.querySelectorAll("#params li")].map((li) => li.textContent));
async function expectListed(page, what, pattern) {
  try {
    await page.waitForFunction((src) => [...document.querySelectorAll("#params li")].some((li) => new RegExp(src).test(li.textContent)),
      pattern.source, { timeout: 10000 });
    console.log(what + ": " + (await listed(page)).find((t) => pattern.test(t)));
  } catch {
    failures.push(what + ": no answer matching " + pattern + " in " + JSON.stringify(await listed(page)));
  }
}
async function ask(page, name, value) {
  await page.fill("#pname", name);
  await page.fill("#pvalue", value ?? "");
  await page.click(value === undefined ? "#pget" : "#pset");
}
try {
  const context = await browser.newContext({ viewport: { width: 1200, height: 900 } });
  const page = await context.newPage();
  await page.goto(base + "/experimenter?token=experimenter-token-0001");  // the test graph's tokens
  await page.waitForFunction(() => document.getElementById("conn").textContent === "live", null, { timeout: 10000 });
  // No subject's page is open in this test: the header says so (sent once a second).
  try {
    await page.waitForFunction(() => document.getElementById("subject").textContent === "subject: no page", null, { timeout: 5000 });
  } catch {
    failures.push("the header's subject status: " + (await page.textContent("#subject")));
  }
  // The recording in the header: its file, samples (growing), size and time (the recorder's status).
  const recording = /^recording rec\.mcap · ([\d,]+) samples · \d+\.\d MB · 0:\d\d$/;
  try {
    await page.waitForFunction((src) => new RegExp(src).test(document.getElementById("recording").textContent), recording.source, { timeout: 5000 });
    const first = Number(recording.exec(await page.textContent("#recording"))[1].replace(/,/g, ""));
    await page.waitForFunction(([src, n]) => Number(new RegExp(src).exec(document.getElementById("recording").textContent)?.[1].replace(/,/g, "")) > n,
      [recording.source, first], { timeout: 5000 });
    console.log("the header: " + (await page.textContent("#recording")));
  } catch {
    failures.push("the header's recording: " + (await page.textContent("#recording")));
  }

  await ask(page, "mixer.gain", "0.25");
  await expectListed(page, "applied", /^\d{1,2}:\d\d:\d\d.*  mixer\.gain 0\.9 \u2192 0\.25 \(experimenter page\)$/);
  await ask(page, "mixer.gain", "7");
  await expectListed(page, "refused", /  mixer\.gain = 7 refused: must be <= 1, got 7 \(experimenter page\)$/);
  // Every text the status line shows (an answer can clear it within a frame of its showing).
  await page.evaluate(() => {
    const el = document.getElementById("psent");
    window.psentSeen = [];
    new MutationObserver(() => window.psentSeen.push(el.textContent)).observe(el, { childList: true, characterData: true, subtree: true });
  });
  await ask(page, "mixer.gain");
  await expectListed(page, "got", /  mixer\.gain = 0\.25 \(experimenter page\)$/);
  await page.waitForTimeout(200);
  const seen = await page.evaluate(() => window.psentSeen);
  if (!seen.some((t) => /^asked for mixer\.gain, waiting/.test(t))) failures.push("the page did not say its request was sent: " + JSON.stringify(seen));
  if (seen[seen.length - 1] !== "") failures.push("the page still waits for an answer it listed: " + JSON.stringify(seen));
  await page.screenshot({ path: `${shotDir}/experimenter_params.png` });

  const viewer = await context.newPage();
  await viewer.goto(base + "/experimenter?token=viewer-token-0000001");
  await viewer.waitForFunction(() => document.getElementById("conn").textContent === "live", null, { timeout: 10000 });
  await expectListed(viewer, "the viewer's list", /  mixer\.gain 0\.9 \u2192 0\.25 \(experimenter page\)$/);
  const before = (await listed(page)).length;
  await ask(viewer, "mixer.gain", "0.5");
  try {
    await viewer.waitForFunction(() => document.getElementById("conn").textContent === "disconnected", null, { timeout: 5000 });
  } catch {
    failures.push("a viewer's page that asked was not closed");
  }
  await page.waitForTimeout(2500);  // two rounds of answers: none for the viewer's request
  const after = await listed(page);
  if (after.length !== before || after.some((t) => /0\.5 \(/.test(t))) failures.push("the viewer's request was answered: " + JSON.stringify(after));
} catch (e) {
  failures.push(e.message.split("\n")[0]);
} finally {
  await browser.close();
}
for (const f of failures) console.error("FAIL: " + f);
console.log(failures.length ? "FAILED" : "set, refused and got from the experimenter's page; the viewer's page listed them and was closed when it asked");
process.exit(failures.length ? 1 : 0);
