#!/usr/bin/env node
// The subject's link for a whole session, in Debian's Chromium (headless, playwright-core):
//   node subject_link.mjs STUDY_PAGE_URL OUT_JSON SCREENSHOT_DIR
// On the experimenter's study page: the subject's link is shown before trial 1, and Start is
// refused while nobody has it open. The link opens the subject's page at once ("Welcome. Please
// wait"); the study page then sees it waiting. Trial 1 is started; as soon as the page steers it
// holds the mouse (moving) until the trial's graph is gone, then the same page (never reloaded)
// says to wait for the next part; likewise trial 2; then the session is over on both pages.
// Writes when each hold began (ms since the epoch) to OUT_JSON. Fails (exit 1) at the first step
// either page gets wrong.
import { writeFile } from "node:fs/promises";
import { chromium } from "playwright-core";

const [url, outFile, shotDir] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
const out = { holds: [] };
try {
  // Two windows, as on two screens: the experimenter's and the participant's.
  const study = await (await browser.newContext({ viewport: { width: 1100, height: 760 } })).newPage();
  const subject = await (await browser.newContext({ viewport: { width: 800, height: 600 } })).newPage();
  await study.goto(url);
  await study.waitForSelector('tr[data-trial="1"]');
  const link = await study.getAttribute("#subject-link", "href");
  if (!/^http:\/\/127\.0\.0\.1:\d+\/subject\?token=\w{16,}$/.test(link ?? "")) throw new Error("the subject's link on the study page: " + link);
  // Nobody has the page open yet: Start is refused, saying why.
  await study.click("#start");
  await study.waitForFunction(() => document.getElementById("message").textContent.includes("the subject's page is not open"));
  if (await study.isHidden("#anyway")) throw new Error("no Start anyway while the subject's page is not open");
  await subject.goto(link);
  await subject.evaluate(() => { window.sameDocument = "kept"; });
  await subject.waitForFunction(() => document.getElementById("waiting").textContent.startsWith("Welcome. Please wait"));
  await study.waitForFunction(() => document.getElementById("subject-state").textContent === "the subject's page is open and waiting");
  if (!(await study.isHidden("#anyway"))) throw new Error("Start anyway offered with the subject's page open");
  await subject.screenshot({ path: `${shotDir}/subject_waiting.png` });
  for (const k of [1, 2]) {
    await study.click("#start");
    // The trial's graph is up and the page steers: hold at once, moving, until the graph is gone.
    await subject.waitForFunction(() => document.getElementById("role").textContent === "you steer", null, { timeout: 20000 });
    await subject.bringToFront();
    await subject.mouse.move(400, 300);
    await subject.mouse.down();
    out.holds.push(Date.now());
    if (k === 1) {  // the study file's task, with the trial's time left
      await subject.waitForFunction(() => document.getElementById("timeleft").textContent.startsWith("time left: "), null, { timeout: 3000 });
      out.task = await subject.evaluate(() => ({ message: document.getElementById("taskmsg").textContent,
                                                 time_left: document.getElementById("timeleft").textContent }));
      await subject.mouse.move(420, 280);
      await subject.screenshot({ path: `${shotDir}/subject_task.png` });
    }
    if (k === 1 && (await study.textContent("#message")) !== "") throw new Error("a warning while trial 1 runs: " + (await study.textContent("#message")));
    for (let i = 0; !(await subject.evaluate(() => document.body.dataset.link === "closed")); i++) {
      if (i > 400) throw new Error("trial " + k + "'s graph did not end");
      await subject.mouse.move(400 + 100 * Math.cos(i / 5), 300 + 100 * Math.sin(i / 5));
      await new Promise((r) => setTimeout(r, 50));
    }
    await subject.mouse.up();
    const next = k === 1 ? "Thank you. Please wait for the next part." : "The session is over. Thank you for taking part!";
    await subject.waitForFunction((t) => document.getElementById("waiting").textContent === t, next, { timeout: 10000 });
    const role = await subject.textContent("#role"), hint = await subject.textContent("#hint");
    if (role !== "" || hint !== "") throw new Error("between trials the subject's page says: " + JSON.stringify([role, hint]));
  }
  await study.waitForFunction(() => document.getElementById("who").textContent.startsWith("session complete: the study runner has ended"));
  if ((await study.textContent("#message")) !== "") throw new Error("a warning after the session: " + (await study.textContent("#message")));
  if ((await subject.evaluate(() => window.sameDocument)) !== "kept") throw new Error("the subject's page was reloaded");
  await subject.screenshot({ path: `${shotDir}/subject_session_over.png` });
  console.log("pages: the subject's link before trial 1, one page kept across both trials, the session over on both");
} finally {
  await browser.close();
}
await writeFile(outFile, JSON.stringify(out));
