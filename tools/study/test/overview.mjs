#!/usr/bin/env node
// The experimenter's overview of `dyad study serve` in Debian's Chromium (headless, playwright-core):
//   node overview.mjs OVERVIEW_URL SCREENSHOT_DIR STOPPED REASON NOTED NOTE
// Waits until two sessions are in a trial at once and shows each one's trial (1 of 2), its
// condition's label (a blind study), a growing recording, its graph's step p99 and deadline
// misses, the page's round trip and, for one, "engaged" (a hold of the simulated participant);
// then adds NOTE to NOTED's session log and stops STOPPED's session with REASON (confirming the
// dialog) and sees it listed as ended with its reason. Exits 1 at the first thing it gets wrong.
import { chromium } from "playwright-core";

const [url, shotDir, stopped, reason, noted, note] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.DYAD_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"],
});
try {
  const page = await browser.newPage({ viewport: { width: 1300, height: 600 } });
  page.on("dialog", (d) => d.accept());
  await page.goto(url);
  const cell = (p, col) => page.textContent(`tr[data-participant="${p}"] td[data-col="${col}"]`);
  // Both in a trial, every column known (stats come once a second, the ping every 2 s).
  await page.waitForFunction(([a, b]) => [a, b].every((p) => {
    const row = (col) => document.querySelector(`tr[data-participant="${p}"] td[data-col="${col}"]`)?.textContent ?? "";
    return row("phase") === "in a trial" && row("p99") !== "" && !row("p99").startsWith("0.00") && row("misses") !== "" && row("rtt") !== "" && row("recording") !== "";
  }), [stopped, noted], { timeout: 15000 });
  await page.waitForFunction(([a, b]) => [a, b].some((p) =>
    document.querySelector(`tr[data-participant="${p}"] td[data-col="engaged"]`)?.textContent === "engaged"), [stopped, noted], { timeout: 8000 });
  for (const p of [stopped, noted]) {
    const got = {};
    for (const col of ["trial", "condition", "p99", "misses", "rtt", "recording"]) got[col] = await cell(p, col);
    console.log(p + ": " + JSON.stringify(got));
    if (got.trial !== "1 of 2") throw new Error(p + ": trial shown as " + got.trial);
    if (!/^condition [AB]$/.test(got.condition)) throw new Error(p + ": a blind study's condition shown as " + got.condition);
    if (!/^\d+\.\d\d ms \(\S+\)$/.test(got.p99) || got.p99.startsWith("0.00 ")) throw new Error(p + ": step p99 shown as " + got.p99);
    if (!/^\d+$/.test(got.misses)) throw new Error(p + ": misses shown as " + got.misses);
    if (!/^\d+(\.\d)? ms$/.test(got.rtt)) throw new Error(p + ": round trip shown as " + got.rtt);
    if (!/^\d+(\.\d)? [KM]?B$/.test(got.recording)) throw new Error(p + ": recording shown as " + got.recording);
  }
  await page.screenshot({ path: `${shotDir}/overview_two_trials.png` });
  await page.click(`tr[data-participant="${noted}"]`);
  await page.fill("#note", note);
  await page.click("#add-note");
  await page.waitForFunction((p) => document.getElementById("message").textContent === "Note added to " + p + "'s session log.", noted);
  await page.click(`tr[data-participant="${stopped}"]`);
  await page.click("#stop");  // no reason yet: refused by the page itself
  if ((await page.textContent("#message")) !== "Say why the session is stopped first.") throw new Error("a stop without a reason was sent");
  await page.fill("#reason", reason);
  await page.click("#stop");
  await page.waitForFunction(([p, r]) =>
    document.querySelector(`tr[data-participant="${p}"] td[data-col="phase"]`)?.textContent === "ended: " + r, [stopped, reason], { timeout: 5000 });
  if (!(await page.isDisabled("#stop")) || (await page.isHidden("#resume"))) throw new Error("an ended session: Stop enabled or no Resume");
  await page.screenshot({ path: `${shotDir}/overview_stopped.png` });
  console.log("overview: both sessions shown, a note added, " + stopped + "'s session stopped");
} catch (e) {
  console.error("FAIL: " + e.message);
  process.exitCode = 1;
} finally {
  await browser.close();
}
