#!/usr/bin/env node
// "Learn from this session" in Debian's Chromium (headless, playwright-core; no browser download):
//   node learn_page.mjs BASE_URL OUT.json SCREENSHOT_DIR CHOICE
// 1. the subject's page: three holds of 2.5 s, each a different shape (a circle, a square, a
//    stroke from left to right), released between them;
// 2. the experimenter's page shows "learn from this session" with the three demonstrations;
//    "learn" with CHOICE (e.g. "2,0": the stroke and the circle) trains, its loss shown as it trains;
// 3. the page then says the new model steers, with the time since the last demonstration.
// OUT.json: the wall-clock times of the last release, the click and the page's "done".
import { writeFile } from "node:fs/promises";
import { chromium } from "playwright-core";

const [base, outFile, shotDir, choice] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const out = {};
try {
  const context = await browser.newContext({ viewport: { width: 1000, height: 800 } });
  const subject = await context.newPage();
  await subject.goto(base + "/subject?token=subject-token-000001");
  await subject.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 10000 });
  const square = (u) => {  // u in [0, 2 pi]: the four sides in turn, from (-0.8, -0.8)
    const k = Math.min(3, Math.floor((2 * u) / Math.PI)), f = (2 * u) / Math.PI - k, a = -0.8 + 1.6 * f, b = 0.8 - 1.6 * f;
    return [[a, -0.8], [0.8, a], [b, 0.8], [-0.8, b]][k];
  };
  const shapes = [(u) => [Math.cos(u), Math.sin(u)], square, (u) => [-1 + u / Math.PI, 0.3]];
  for (const shape of shapes) {
    const [x0, y0] = shape(0);
    await subject.mouse.move(500 + 200 * x0, 400 - 200 * y0);
    await subject.keyboard.down("Space");
    for (let t = 0; t <= 2500; t += 100) {
      const [x, y] = shape((2 * Math.PI * t) / 2500);
      await subject.mouse.move(500 + 200 * x, 400 - 200 * y);
      await sleep(100);
    }
    await subject.keyboard.up("Space");
    out.last_release = Date.now();
    await sleep(600);
  }
  const page = await context.newPage();
  await page.goto(base + "/experimenter?token=experimenter-token-0001");
  await page.waitForFunction(() => document.querySelectorAll("#lsegs li").length === 3 &&
                             !document.getElementById("learnbox").hidden, null, { timeout: 10000 });
  out.segments = await page.evaluate(() => [...document.querySelectorAll("#lsegs li")].map((li) => li.textContent));
  await page.fill("#lchoice", choice);
  out.clicked = Date.now();
  await page.click("#learn");
  await page.waitForFunction(() => / loss /.test(document.getElementById("lstate").textContent), null, { timeout: 20000 });
  out.training = await page.evaluate(() => document.getElementById("lstate").textContent);
  await page.waitForFunction(() => /the new model steers/.test(document.getElementById("lstate").textContent), null, { timeout: 60000 });
  out.done = Date.now();
  out.state = await page.evaluate(() => document.getElementById("lstate").textContent);
  out.message = await page.evaluate(() => document.getElementById("lmsg").textContent);
  await page.screenshot({ path: `${shotDir}/experimenter_learned.png` });
} finally {
  await browser.close();
}
await writeFile(outFile, JSON.stringify(out, null, 1));
