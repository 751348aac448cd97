#!/usr/bin/env node
// Drives the subject's page in Debian's Chromium (headless, playwright-core; no browser download)
// like a subject would, and writes what it did, with wall-clock times, for the checks:
//   node subject_page.mjs BASE_URL OUT.json SCREENSHOT_DIR
// 1. opens /subject (1000x800), waits until it steers;
// 2. rests the mouse released, holds the engage key (Space), moves along a circle of radius 20
//    (12 points, each held 400 ms), releases the key, rests;
// 3. engages again, holds still, then closes the tab while engaged;
// 4. on the experimenter's page, notes a line; saves screenshots of both pages.
// The workspace position of every mouse position is computed here from the canvas rectangle and
// the documented mapping (square of side min(w, h) - 48 px centred, 100 units across, y up), not
// by the page.
import { writeFile } from "node:fs/promises";
import { chromium } from "playwright-core";

const [base, outFile, shotDir] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
const log = { moves: [], key: [], closed_at: null, rtts: [] };
try {
  const context = await browser.newContext({ viewport: { width: 1000, height: 800 } });
  const page = await context.newPage();
  await page.goto(base + "/subject?token=subject-token-000001");  // the test graph's tokens
  await page.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 10000 });
  const rect = await page.evaluate(() => {
    const r = document.getElementById("canvas").getBoundingClientRect();
    return { left: r.left, top: r.top, width: r.width, height: r.height };
  });
  const side = Math.min(rect.width, rect.height) - 48, scale = side / 100;
  const cx = rect.left + rect.width / 2, cy = rect.top + rect.height / 2;
  const toScreen = (x, y) => ({ px: cx + x * scale, py: cy - y * scale });
  const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
  async function moveTo(x, y, engaged) {
    const s = toScreen(x, y);
    await page.mouse.move(s.px, s.py);
    // What the page must have reported: the workspace position of this screen point.
    log.moves.push({ t: Date.now(), x: (s.px - cx) / scale, y: -(s.py - cy) / scale, engaged });
  }
  await moveTo(-30, -30, false);
  await sleep(800);
  await page.keyboard.down("Space");
  log.key.push({ t: Date.now(), down: true });
  for (let i = 0; i <= 12; i++) {
    const a = (2 * Math.PI * i) / 12;
    await moveTo(20 * Math.cos(a), 20 * Math.sin(a), true);
    await sleep(400);
    if (i === 6) await page.screenshot({ path: `${shotDir}/subject_page.png` });
  }
  await page.keyboard.up("Space");
  log.key.push({ t: Date.now(), down: false });
  await moveTo(25, -10, false);
  await sleep(800);
  // Engaged again, then the tab goes away.
  await page.keyboard.down("Space");
  log.key.push({ t: Date.now(), down: true });
  await moveTo(10, 30, true);
  await sleep(800);
  log.rtts = (await page.evaluate(() => window.dyadStats())).rtts;
  log.closed_at = Date.now();
  await page.close();
  await sleep(800);
  const exp = await context.newPage();
  await exp.goto(base + "/experimenter?token=experimenter-token-0001");
  await exp.waitForFunction(() => document.getElementById("conn").textContent === "live", null, { timeout: 10000 });
  await sleep(1500);
  log.note = { text: "subject reported fatigue", t: Date.now() };
  await exp.fill("#note", log.note.text);
  await exp.click("#send");
  await sleep(500);
  await exp.screenshot({ path: `${shotDir}/experimenter_page.png` });
} finally {
  await browser.close();
}
await writeFile(outFile, JSON.stringify(log, null, 1));
console.log(`moves ${log.moves.length}, key events ${log.key.length}, pointer round trips ${log.rtts.length}`);
