// One scripted session with the viewer in headless Chromium (Debian's, via
// playwright-core). It only acts and records what the page shows; the checks
// live in tests/test_viewer_browser.py, which compares the records with
// hand-derived numbers.
//
//   node viewer_session.mjs URL OUT.json [SCREENSHOT.png]
import { chromium } from "playwright-core";
import { mkdtempSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

const [url, outPath, shotPath] = process.argv.slice(2);
// Chromium's profile (2-3 MB): in WIRECHECK_PROFILE_PARENT when the test gives one (its own temporary
// folder, so even a killed run leaves nothing in the system's), removed whenever node exits.
const userDataDir = mkdtempSync(join(process.env.WIRECHECK_PROFILE_PARENT || tmpdir(), "wirecheck-chromium-"));
process.on("exit", () => rmSync(userDataDir, { recursive: true, force: true, maxRetries: 3 }));
const context = await chromium.launchPersistentContext(userDataDir, {
  executablePath: process.env.WIRECHECK_CHROMIUM || "/usr/bin/chromium",
  headless: true,
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"],
  viewport: { width: 1600, height: 1200 },
});
const page = context.pages()[0] || await context.newPage();
const consoleErrors = [];
page.on("console", (m) => { if (m.type() === "error") consoleErrors.push(m.text()); });
page.on("pageerror", (e) => consoleErrors.push(String(e)));

const idle = async () => {
  await page.waitForFunction(() => window.viewerIdle && window.viewerIdle() && document.getElementById("view-json").textContent.length > 0);
};
const snap = async (label) => ({
  label,
  json: JSON.parse(await page.textContent("#view-json")),
  image: await page.getAttribute("#frame", "src"),
  cameraText: await page.textContent("#camera-text"),
  command: await page.inputValue("#command"),
  message: (await page.isVisible("#message")) ? await page.textContent("#message") : null,
});
const records = [];

await page.goto(url);
await idle();
records.push(await snap("start"));

// drag 180 px to the left on the frame: orbit 90 degrees
const box = await page.locator("#frame").boundingBox();
const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
await page.mouse.move(cx + 90, cy);
await page.mouse.down();
await page.mouse.move(cx - 90, cy, { steps: 12 });
await page.mouse.up();
await idle();
records.push(await snap("orbit"));

// one wheel notch of 100: dolly out by exp(0.1)
await page.mouse.move(cx, cy);
await page.mouse.wheel(0, 100);
await idle();
records.push(await snap("dolly"));

// shift-drag by (+50, +30): pan
await page.keyboard.down("Shift");
await page.mouse.move(cx, cy);
await page.mouse.down();
await page.mouse.move(cx + 50, cy + 30, { steps: 5 });
await page.mouse.up();
await page.keyboard.up("Shift");
await idle();
records.push(await snap("pan"));

// the oracle overlay for this view: the page says it is drawing while pyrender starts
await page.check("#overlay");
const busyShown = await page.waitForSelector("#busy", { state: "visible", timeout: 5000 })
  .then(() => page.textContent("#busy")).catch(() => null);
await idle();
await page.waitForSelector("#overlay-json", { state: "visible" });
const overlay = JSON.parse(await page.textContent("#overlay-json"));
const diffSrc = await page.getAttribute("#diff", "src");
if (shotPath) await page.screenshot({ path: shotPath, fullPage: true });
// at 1,400 x 900 with the overlay's three panes, the controls stay in view
await page.setViewportSize({ width: 1400, height: 900 });
const controlsBox = await page.locator("#controls").boundingBox();
await page.setViewportSize({ width: 1600, height: 1200 });
await page.uncheck("#overlay");
await idle();

// hidden lines on
await page.check("#hidden_lines");
await idle();
records.push(await snap("hidden"));

// bad input: NaN in the FOV field, then near beyond far
await page.fill("#fov", "NaN");
await page.press("#fov", "Enter");
await page.locator("#fov").blur();
await idle();
records.push(await snap("fov-nan"));
await page.fill("#near", "500");
await page.locator("#near").blur();
await idle();
records.push(await snap("near-far"));
// the error stays in view when the page is scrolled to its end
await page.setViewportSize({ width: 1400, height: 600 });
await page.evaluate(() => window.scrollTo(0, document.body.scrollHeight));
const messageBox = await page.locator("#message").boundingBox();
await page.evaluate(() => window.scrollTo(0, 0));
await page.setViewportSize({ width: 1600, height: 1200 });

// the server still answers: step one frame
await page.click("#step");
await idle();
records.push(await snap("step"));

// play for a moment, then pause
await page.click("#play");
await page.waitForTimeout(700);
await page.click("#play");
await idle();
records.push(await snap("played"));

// reset: the starting view, frame included; then a step and a reload: a fresh start again
await page.click("#reset");
await idle();
records.push(await snap("reset"));
await page.click("#step");
await idle();
await page.reload();
await idle();
records.push(await snap("reload"));
const overlayAfterReload = await page.isChecked("#overlay");

const profileRows = await page.$$eval("#profile-table tbody tr", (rows) => rows.map((r) => r.dataset.stage));
const fpsText = await page.textContent("#fps");

await context.close();
writeFileSync(outPath, JSON.stringify({ records, overlay, diffSrc: diffSrc ? diffSrc.length : 0,
                                        profileRows, fpsText, consoleErrors, busyShown, controlsBox,
                                        messageBox, overlayAfterReload }, null, 1));
