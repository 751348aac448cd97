#!/usr/bin/env node
// The subject's task in Debian's Chromium (headless, playwright-core; no browser download):
//   node subject_task.mjs BASE_URL OUT.json SCREENSHOT_DIR
// The experimenter's page sets the subject's screen: target primitive 3, a message, a countdown
// of 2 s, practice on. The subject's page (opened first) shows each: the target (its page state),
// the message, the countdown going 2, 1, "go", then nothing, and the practice badge. A second
// subject's page opened mid-way gets the task as it stands. OUT.json: what the pages showed.
import { writeFile } from "node:fs/promises";
import { chromium } from "playwright-core";

const [base, outFile, shotDir] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const out = { countdown: [] };
try {
  const context = await browser.newContext({ viewport: { width: 1000, height: 800 } });
  const subject = await context.newPage();
  await subject.goto(base + "/subject?token=subject-token-000001");
  await subject.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 10000 });
  const shown = (page) => page.evaluate(() => ({
    target, message: document.getElementById("taskmsg").textContent,
    practice: getComputedStyle(document.getElementById("practice")).display !== "none",
    countdown: document.getElementById("countdown").textContent }));
  out.before = await shown(subject);
  const page = await context.newPage();
  await page.goto(base + "/experimenter?token=experimenter-token-0001");
  await page.waitForFunction(() => document.getElementById("ttarget").options.length === 8, null, { timeout: 10000 });
  // The targets by the data set's names.
  const labels = await page.evaluate(() => [...document.getElementById("ttarget").options].map((o) => o.textContent));
  if (labels.join("|") !== "none|circle (0)|square (1)|triangle (2)|figure eight (3)|star (4)|heart (5)|trefoil (6)")
    throw new Error("the target list: " + labels.join(", "));
  await page.selectOption("#ttarget", "3");
  await subject.waitForFunction(() => target === 3, null, { timeout: 5000 });
  await page.fill("#tmsg", "Draw the yellow shape");
  await page.click("#tmsgset");
  await subject.waitForFunction(() => document.getElementById("taskmsg").textContent === "Draw the yellow shape", null, { timeout: 5000 });
  await page.check("#tpractice");
  await subject.waitForFunction(() => getComputedStyle(document.getElementById("practice")).display !== "none", null, { timeout: 5000 });
  await page.fill("#tcount", "2");
  await page.click("#tgo");
  await subject.waitForFunction(() => document.getElementById("countdown").textContent === "2", null, { timeout: 5000 });
  // The countdown as the subject sees it, every 100 ms for 4 s.
  for (let i = 0; i < 40; i++) {
    const c = await subject.evaluate(() => document.getElementById("countdown").textContent);
    if (out.countdown[out.countdown.length - 1] !== c) out.countdown.push(c);
    if (i === 5) await subject.screenshot({ path: `${shotDir}/subject_task.png` });
    await sleep(100);
  }
  out.after = await shown(subject);
  const late = await context.newPage();  // opened after: gets the task as it stands
  await late.goto(base + "/subject?token=subject-token-000001");
  await late.waitForFunction(() => target === 3, null, { timeout: 5000 });
  out.late = await shown(late);
  await page.uncheck("#tpractice");
  await subject.waitForFunction(() => getComputedStyle(document.getElementById("practice")).display === "none", null, { timeout: 5000 });
  await sleep(300);
} finally {
  await browser.close();
}
await writeFile(outFile, JSON.stringify(out, null, 1));
