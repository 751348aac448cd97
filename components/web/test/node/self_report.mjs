#!/usr/bin/env node
// The subject's question in Debian's Chromium (headless, playwright-core; no browser download):
//   node self_report.mjs BASE_URL OUT.json SCREENSHOT_DIR
// 1. opens /subject, waits until it steers; a tap of the engage key (300 ms) must not ask;
// 2. a hold of 1.5 s: on its release the page asks "What were you drawing?" with one thumbnail
//    per primitive and "something else";
// 3. holding again dismisses the question unanswered; the release of that 1.2 s hold asks again;
// 4. 700 ms later the subject clicks the third thumbnail (choice 2); the question goes away and
//    a digit key then answers nothing;
// 5. the question never covers the workspace: while it is shown, every point of a 21 x 21 grid
//    over the workspace square (its edges included) is the canvas, and right after the release of
//    a third hold (1.2 s) a mouse press at the square's bottom centre, (0, -0.9 H), where the
//    question used to be, steers at once (the page shows ENGAGED, the question goes) and is held
//    600 ms; the shell test finds it engaged on human/input at that point; in a tall window (a
//    viewer's page, 600 x 900, the question shown) the band is below the square, no grid point
//    covered either.
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
  // 5. The workspace square as the page draws it (page px), and what lies on it.
  out.third = await hold(1200);
  await page.waitForFunction(() => document.getElementById("question").classList.contains("on"), null, { timeout: 3000 });
  const square = await page.evaluate(() => {
    const r = canvas.getBoundingClientRect(), tl = toCanvas(-H, H), br = toCanvas(H, -H);
    return { left: r.left + tl.px, top: r.top + tl.py, right: r.left + br.px, bottom: r.top + br.py, H };
  });
  out.square = square;
  out.question_box = await page.evaluate(() => {
    const r = document.getElementById("question").getBoundingClientRect();
    return { left: r.left, top: r.top, right: r.right, bottom: r.bottom };
  });
  const coveredPoints = (p, sq) => p.evaluate((sq) => {
    const out = [];
    for (let i = 0; i <= 20; i++)
      for (let j = 0; j <= 20; j++) {
        const x = sq.left + 1 + (sq.right - sq.left - 2) * i / 20, y = sq.top + 1 + (sq.bottom - sq.top - 2) * j / 20;
        const e = document.elementFromPoint(x, y);
        if (e !== canvas) out.push([Math.round(x), Math.round(y), e ? (e.id || e.tagName) : "nothing"]);
      }
    return out;
  }, sq);
  const covered = await coveredPoints(page, square);
  if (covered.length) fail(`the question covers the workspace at ${covered.length} of 441 points, e.g. ${JSON.stringify(covered.slice(0, 3))}`);
  const press = { x: (square.left + square.right) / 2, y: square.bottom - 0.05 * (square.bottom - square.top) };  // (0, -0.9 H)
  await page.mouse.move(press.x, press.y);
  await page.mouse.down();
  out.press = { start: Date.now(), x: 0, y: -0.9 * square.H };
  out.press_page = await page.evaluate(() => ({ engaged: document.getElementById("engaged").textContent,
                                               asking: document.getElementById("question").classList.contains("on") }));
  await sleep(600);
  out.press.end = Date.now();
  await page.mouse.up();
  if (out.press_page.engaged !== "ENGAGED") fail(`a press on the workspace right after a release did not steer (the page shows ${out.press_page.engaged})`);
  if (out.press_page.asking) fail("a press on the workspace right after a release left the question shown");
  await sleep(300);
  const tall = await (await browser.newContext({ viewport: { width: 600, height: 900 } })).newPage();
  await tall.goto(base + "/subject?token=viewer-token-0000001");
  await tall.waitForFunction(() => document.getElementById("role").textContent === "watching (viewer)", null, { timeout: 10000 });
  await tall.evaluate(() => showQuestion(true));  // a viewer is never asked: shown here for its place only
  const tallSquare = await tall.evaluate(() => {
    const r = canvas.getBoundingClientRect(), tl = toCanvas(-H, H), br = toCanvas(H, -H);
    return { left: r.left + tl.px, top: r.top + tl.py, right: r.left + br.px, bottom: r.top + br.py, H };
  });
  out.tall = { square: tallSquare, question_box: await tall.evaluate(() => {
    const r = document.getElementById("question").getBoundingClientRect();
    return { left: r.left, top: r.top, right: r.right, bottom: r.bottom };
  }) };
  const tallCovered = await coveredPoints(tall, tallSquare);
  if (tallCovered.length) fail(`in a 600 x 900 window the question covers the workspace at ${tallCovered.length} of 441 points`);
  if (out.tall.question_box.top < tallSquare.bottom) fail(`in a 600 x 900 window the question is not below the square: ${JSON.stringify(out.tall)}`);
} finally {
  await browser.close();
}
await writeFile(outFile, JSON.stringify(out, null, 1));
