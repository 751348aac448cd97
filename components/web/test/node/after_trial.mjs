#!/usr/bin/env node
// Asking after the trial (self_reports: after_trial) in Debian's Chromium (headless,
// playwright-core; no browser download):
//   node after_trial.mjs BASE_URL OUT.json SCREENSHOT_DIR timed|button
// timed (the graph has ask_after_s): the subject taps (300 ms: no event), holds 1.5 s, holds
//   1.2 s, then waits. When the trial ends the page asks "What were you drawing here? (1 of 2)"
//   with the first hold's stroke (the pointer's path while held: every point the browser moved
//   to, nothing else) and the robot's path beside it; Space then steers nothing, nor does an engaged pointer sample
//   sent on the page's own socket (the server refuses to steer); a second subject's page opened
//   now is shown "The subject is answering (1 of 2)" without the choices; the subject clicks the
//   third thumbnail (choice 2); 700 ms into the second question presses 0 ("something else"); the
//   page then thanks them and the graph ends by itself.
// button: one hold of 1.5 s, then the experimenter's page's "end the trial and ask the subject";
//   the subject's page asks "1 of 1" and nobody answers (the graph's timeout ends it).
// OUT.json: the holds' and answers' wall-clock times and what the pages showed.
import { writeFile } from "node:fs/promises";
import { chromium } from "playwright-core";

const [base, outFile, shotDir, mode] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const fail = (why) => { throw new Error(why); };
const out = { holds: [], titles: [] };
try {
  const context = await browser.newContext({ viewport: { width: 1000, height: 800 } });
  const page = await context.newPage();
  await page.goto(base + "/subject?token=subject-token-000001");
  await page.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 10000 });
  const asking = () => page.evaluate(() => document.getElementById("question").classList.contains("on"));
  const title = () => page.evaluate(() => document.getElementById("question-title").textContent);
  let at = [500, 400];  // where the browser's pointer is (page px)
  await page.mouse.move(...at);
  async function hold(ms) {
    const points = [at];  // where the pointer was while held
    await page.keyboard.down("Space");
    const start = Date.now();
    for (let t = 0; t < ms; t += 100) {
      at = [500 + 120 * Math.cos(t / 250), 400 + 120 * Math.sin(t / 250)];
      await page.mouse.move(...at);
      points.push(at);
      await sleep(100);
    }
    await page.keyboard.up("Space");
    return { start, end: Date.now(), points };
  }
  // The question's paths against the browser's pointer while held (workspace units, the page's
  // mapping: the square centred in the canvas, side min(width, height) - 48 px): how far a
  // path's farthest point is from every pointer position, and how many pointer positions the
  // stroke misses (none within 0.3).
  const comparePaths = (points) => page.evaluate((pts) => {
    const r = canvas.getBoundingClientRect(), scale = (Math.min(r.width, r.height) - 48) / (2 * H);
    const held = pts.map(([px, py]) => [(px - r.left - r.width / 2) / scale, -(py - r.top - r.height / 2) / scale]);
    const dist = (p, path) => Math.min(...path.map(([x, y]) => Math.hypot(p[0] - x, p[1] - y)));
    const stroke = lastQuestion.stroke ?? [], robot = lastQuestion.robot ?? [];
    return { stroke_points: stroke.length, stroke_off: Math.max(0, ...stroke.map((p) => dist(p, held))),
             stroke_missed: held.filter((p) => !stroke.length || dist(p, stroke) > 0.3).length,
             robot_points: robot.length, robot_off: Math.max(0, ...robot.map((p) => dist(p, held))) };
  }, points);
  // The question's picture: how many of the trace canvas's pixels are drawn.
  const tracePixels = () => page.evaluate(() => {
    const c = document.getElementById("trace"), d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n++;
    return n;
  });
  const waitTitle = (text) => page.waitForFunction((t) => document.getElementById("question").classList.contains("on") &&
      document.getElementById("question-title").textContent === t, text, { timeout: 20000 });
  if (mode === "timed") {
    await hold(300);
    await sleep(300);
    if (await asking()) fail("asked before the trial ended");
    out.holds.push(await hold(1500));
    await sleep(400);
    if (await asking()) fail("after_trial asked after a release (that is after_event)");
    out.holds.push(await hold(1200));
    await waitTitle("What were you drawing here? (1 of 2)");
    out.asked_at = Date.now();
    out.titles.push(await title());
    out.trace_pixels = await tracePixels();
    out.paths = await comparePaths(out.holds[0].points);
    out.choices = await page.evaluate(() => [...document.querySelectorAll("#choices button")].map((b) => Number(b.dataset.choice)));
    await page.screenshot({ path: `${shotDir}/after_trial_question.png` });
    // Nobody steers after the trial: the engage key does nothing, and the question stays.
    out.steer_tried_at = Date.now();
    await page.keyboard.down("Space");
    await page.mouse.move(300, 300);
    await sleep(300);
    out.engaged_text = await page.evaluate(() => document.getElementById("engaged").textContent);
    await page.keyboard.up("Space");
    await page.evaluate(() => ws.send(JSON.stringify({ op: "pointer", x: 10, y: 10, engaged: true })));  // the server's check
    const watcher = await context.newPage();
    await watcher.goto(base + "/subject?token=subject-token-000001");
    await watcher.waitForFunction(() => document.getElementById("question").classList.contains("on"), null, { timeout: 10000 });
    out.watcher = await watcher.evaluate(() => ({
      title: document.getElementById("question-title").textContent,
      choices_shown: getComputedStyle(document.getElementById("choices")).display !== "none",
      trace_shown: getComputedStyle(document.getElementById("trace")).display !== "none" }));
    await watcher.close();
    if (!(await asking())) fail("holding after the trial dismissed the question");
    await page.click('#choices button[data-choice="2"]');
    out.answers = [Date.now()];
    await waitTitle("What were you drawing here? (2 of 2)");
    out.titles.push(await title());
    await sleep(700);
    out.answers.push(Date.now());
    await page.keyboard.press("Digit0");
    await waitTitle("Thank you. This trial is over.");
    out.titles.push(await title());
    await page.screenshot({ path: `${shotDir}/after_trial_thanks.png` });
    // The graph ends by itself; the thanks stay on the page after it is gone.
    await page.waitForFunction(() => document.body.dataset.link === "closed", null, { timeout: 20000 });
    out.thanks_after_end = await title();
  } else {
    const experimenter = await context.newPage();
    await experimenter.goto(base + "/experimenter?token=experimenter-token-0001");
    await experimenter.waitForFunction(() => !document.getElementById("askform").hidden, null, { timeout: 10000 });
    out.holds.push(await hold(1500));
    await experimenter.waitForFunction(() => document.getElementById("askholds").textContent === "1 holds to ask about so far", null,
                                       { timeout: 5000 });
    await experimenter.click("#asknow");
    out.asked_at = Date.now();
    await waitTitle("What were you drawing here? (1 of 1)");
    out.titles.push(await title());
    await experimenter.waitForFunction(() => document.getElementById("subject").textContent.includes("questions: 0 of 1 answered"), null,
                                       { timeout: 5000 });
    out.experimenter_says = await experimenter.evaluate(() => document.getElementById("subject").textContent);
    out.button_disabled = await experimenter.evaluate(() => document.getElementById("asknow").disabled);
    // Unanswered: the timeout ends the run; the question goes with it.
    await page.waitForFunction(() => document.body.dataset.link === "closed", null, { timeout: 20000 });
    out.asking_after_end = await asking();
  }
} finally {
  await browser.close();
}
await writeFile(outFile, JSON.stringify(out, null, 1));
