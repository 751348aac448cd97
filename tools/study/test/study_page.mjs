#!/usr/bin/env node
// The experimenter's study page in Debian's Chromium (headless, playwright-core):
//   node study_page.mjs STUDY_PAGE_URL SCREENSHOT_DIR
// Marks consent (confirming the dialog), starts trial 1 and waits for it to complete, repeats it
// with a reason, starts trial 2 (adding a note while it runs) and stops it early, sees that it
// must be repeated, then withdraws the participant's consent keeping their data, and sees a note
// written from a terminal meanwhile (the shell script writes it once the withdrawal is logged). Before all that, malformed operations from a
// hand-made client are refused with their reasons. Fails (exit 1) at the first step the page gets wrong.
import { chromium } from "playwright-core";

const [url, shotDir] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
try {
  const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
  const answers = [];  // what the next confirm() dialogs are answered (then: OK)
  page.on("dialog", (d) => (answers.length === 0 || answers.shift() ? d.accept() : d.dismiss()));
  await page.goto(url);
  const text = (sel) => page.textContent(sel);
  const status = (k) => text(`tr[data-trial="${k}"] td:nth-child(4)`);
  const attempts = (k) => text(`tr[data-trial="${k}"] td:nth-child(5)`);
  const waitStatus = (k, s, ms = 20000) =>
    page.waitForFunction(([k, s]) => document.querySelector(`tr[data-trial="${k}"] td:nth-child(4)`)?.textContent === s, [k, s], { timeout: ms });
  await page.waitForSelector('tr[data-trial="1"]');
  // Malformed operations (a hand-made client, not the page) are refused: the socket that sent
  // them is closed with the reason, and nothing is written (the shell script reads the session
  // log: the page's note is its only note, the withdrawal its last line, consent its first).
  const bad = [
    ['{"op":"note"}', 'note: needs a string "text"'], ['{"op":"note","text":5}', 'note: needs a string "text"'],
    ['{"op":"withdraw"}', 'withdraw: needs a boolean "delete"'], ['{"op":"withdraw","delete":"yes"}', 'withdraw: needs a boolean "delete"'],
    ['{"op":"start","trial":"1"}', 'start: needs an integer "trial"'], ['{"op":"fly"}', "unknown op 'fly'"],
    ["[1]", 'not a JSON object with an "op"'],
  ];
  const closed = await page.evaluate(async (frames) => {
    const one = (frame) => new Promise((resolve) => {
      const s = new WebSocket(location.origin.replace(/^http/, "ws") + "/study/ws" + location.search);
      s.onopen = () => s.send(frame);
      s.onclose = (ev) => resolve([ev.code, ev.reason]);
    });
    const out = [];
    for (const frame of frames) out.push(await one(frame));
    return out;
  }, bad.map(([frame]) => frame));
  bad.forEach(([frame, reason], i) => {
    if (closed[i][0] !== 1008 || closed[i][1] !== reason)
      throw new Error(frame + " was answered " + JSON.stringify(closed[i]) + " (want 1008, " + reason + ")");
  });
  if ((await text("#consent")) !== "consent required, not given") throw new Error("consent shown as: " + (await text("#consent")));
  if (!(await page.isDisabled("#start"))) throw new Error("Start is enabled before consent");
  await page.click("#mark-consent");
  await page.waitForFunction(() => document.getElementById("consent").textContent === "consent given");
  const shown = await text('tr[data-trial="1"] td:nth-child(2)');
  if (!/^condition [AB]$/.test(shown)) throw new Error("a blind study's condition shown as: " + shown);
  if (!(await text("#start")).startsWith("Start trial 1 of 2")) throw new Error("Start says: " + (await text("#start")));
  await page.click("#start");
  await waitStatus(1, "running", 5000);
  await page.screenshot({ path: `${shotDir}/study_page_running.png` });
  await waitStatus(1, "complete");
  // A repetition needs its reason.
  await page.click('tr[data-trial="1"] button.repeat');
  if (!(await text("#message")).includes("Say why trial 1 is repeated")) throw new Error("a repeat without a reason: " + (await text("#message")));
  await page.fill("#reason", "the participant sneezed");
  await page.click('tr[data-trial="1"] button.repeat');
  await waitStatus(1, "running", 5000);
  await waitStatus(1, "complete");
  if ((await attempts(1)) !== "2") throw new Error("trial 1 attempts: " + (await attempts(1)));
  // Trial 2 stopped early: incomplete, and Start refuses to go on without a repetition.
  await page.click("#start");
  await waitStatus(2, "running", 5000);
  // A note while it runs: listed at once, with the trial it was written during.
  await page.fill("#note", "the participant | laughed");
  await page.click("#add-note");
  await page.waitForFunction(() => document.getElementById("notes").textContent.includes("(trial 2): the participant | laughed"));
  await page.click("#stop");
  await waitStatus(2, "stopped");
  if (!(await page.isDisabled("#start"))) throw new Error("Start is enabled after an incomplete trial");
  if (!(await text("#message")).includes("Trial 2 did not complete")) throw new Error("message: " + (await text("#message")));
  await page.screenshot({ path: `${shotDir}/study_page_done.png` });
  // The participant withdraws consent, and the data is kept (the second dialog answered Cancel).
  // (The session's end, where the runner exits by itself, is subject_link_test.sh's.)
  answers.push(true, false);
  await page.click("#withdraw");
  await page.waitForFunction(() => document.getElementById("consent").textContent.startsWith("consent withdrawn"));
  if (!(await page.isDisabled("#withdraw"))) throw new Error("withdraw is still offered after a withdrawal");
  if (!(await page.isHidden("#mark-consent"))) throw new Error("the page offers to mark consent again after a withdrawal");
  if (await page.isEnabled('tr[data-trial="1"] button.repeat')) throw new Error("a repetition is offered after a withdrawal");
  // A note from another terminal shows on the open page within a second or two.
  await page.waitForFunction(() => document.getElementById("notes").textContent.includes("from the terminal"), null, { timeout: 10000 });
  console.log("page: consent, trial 1 twice, trial 2 stopped (" + (await status(2)) + "), a note, consent withdrawn, a terminal's note shown");
} finally {
  await browser.close();
}
