#!/usr/bin/env node
// The subject's question in Debian's Chromium (headless, playwright-core; no browser download):
//   node self_report.mjs BASE_URL OUT.json SCREENSHOT_DIR
// 1. opens /subject, waits until it steers; a tap of the engage key (300 ms) must not ask;
// 2. a hold of 1.5 s: on its release the page asks "What were you drawing?" with one thumbnail
//    per primitive and "something else";
// 3. holding again dismisses the question unanswered; the release of that 1.2 s hold asks again;
// 4. 700 ms later the subject clicks the third thumbnail (choice 2); the question goes away and
//    a digit key then answers nothing.
// OUT.json gets the wall-clock times of the holds and the answer, for the shell test's checks.
import { writeFile } from "node:fs/promises";
import { chromium } from "playwright-core";

const [base, outFile, shotDir] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const fail = (why) => { throw new Error(why); };
const out = {};
try {
  const page = await (await browser.newContext({ viewport: { width: 1000, height: 800 } })).newPage();
  await page.goto(base + "/subject?token=subject-token-000001");
  await page.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 10000 });
  const asking = () => page.evaluate(() => document.getElementById("question").classList.contains("on"));
  await page.mouse.move(500, 400);
  async function hold(ms) {
    await page.keyboard.down("Space");
    const start = Date.now();
    for (let t = 0; t < ms; t += 100) {
      await page.mouse.move(500 + 80 * Math.cos(t / 300), 400 + 80 * Math.sin(t / 300));
      await sleep(100);
    }
    await page.keyboard.up("Space");
    return { start, end: Date.now() };
  }
  await hold(300);
  await sleep(300);
  if (await asking()) fail("a 300 ms tap was asked about");
  out.first = await hold(1500);
  await page.waitForFunction(() => document.getElementById("question").classList.contains("on"), null, { timeout: 3000 });
  out.choices = await page.evaluate(() => [...document.querySelectorAll("#choices button")].map((b) => Number(b.dataset.choice)));
  out.captions = await page.evaluate(() => [...document.querySelectorAll("#choices button")].map((b) => b.querySelector(".name")?.textContent ?? b.textContent));
  await page.screenshot({ path: `${shotDir}/subject_question.png` });
  await page.keyboard.down("Space");
  await sleep(150);
  if (await asking()) fail("holding again did not dismiss the question");
  await page.keyboard.up("Space");
  out.second = await hold(1200);
  await page.waitForFunction(() => document.getElementById("question").classList.contains("on"), null, { timeout: 3000 });
  await sleep(700);
  out.answered_at = Date.now();
  await page.click('#choices button[data-choice="2"]');
  if (await asking()) fail("the question stayed after the answer");
  await page.keyboard.press("Digit4");  // nothing is asked: no second answer
  await sleep(500);
} finally {
  await browser.close();
}
await writeFile(outFile, JSON.stringify(out, null, 1));
