// Browser test of `grains view`: for each run directory given, starts the
// server on a free port, loads the page in Debian's headless chromium
// (never a downloaded browser), waits for the first frame, checks that the
// canvas is drawn and shows the run's grains, presses Play and sees the
// frame counter advance; any console error fails the test.
//
//   node view_test.mjs GRAINS_BINARY RUN_DIR...
//
// With VIEW_TEST_SHOTS=DIR set, a screenshot of each page after the first
// frame is saved there as view-<k>.png.
import { spawn } from "node:child_process";
import { mkdtempSync, readFileSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { chromium } from "playwright-core";

const [grains, ...runs] = process.argv.slice(2);
if (!grains || runs.length === 0) {
  console.error("usage: node view_test.mjs GRAINS_BINARY RUN_DIR...");
  process.exit(2);
}

/** Starts `grains view DIR --port 0`; resolves with the server and its address. */
function serve(dir) {
  return new Promise((resolve, reject) => {
    const child = spawn(grains, ["view", dir, "--port", "0"], { stdio: ["ignore", "pipe", "pipe"] });
    let out = "", err = "";
    const timer = setTimeout(() => reject(new Error(`no address from grains view ${dir}: ${out}${err}`)), 20000);
    child.stdout.on("data", (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m) { clearTimeout(timer); resolve({ child, url: m[0] }); }
    });
    child.stderr.on("data", (d) => { err += d; });
    child.on("exit", (code) => { clearTimeout(timer); reject(new Error(`grains view exited ${code}: ${err}`)); });
  });
}

const profile = mkdtempSync(join(tmpdir(), "grains-view-chromium-"));
// A fresh, empty profile (Playwright passes it as --user-data-dir).
const browser = await chromium.launchPersistentContext(profile, {
  executablePath: "/usr/bin/chromium",
  headless: true,
  viewport: { width: 900, height: 700 },
  args: [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    // WebGL2 without a GPU: ANGLE on SwiftShader.
    "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
  ],
});

let failures = 0;
for (const dir of runs) {
  const expected = JSON.parse(readFileSync(join(dir, "summary.json"), "utf8")).particles;
  const { child, url } = await serve(dir);
  const page = await browser.newPage();
  const errors = [];
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  page.on("pageerror", (e) => errors.push(String(e)));
  try {
    await page.goto(url);
    await page.waitForFunction(() => window.grainsView && window.grainsView.ready, null, { timeout: 30000 });
    const first = await page.evaluate(() => ({ ...window.grainsView, lit: window.grainsView.litPixels() }));
    if (first.grains !== expected) throw new Error(`${first.grains} grains shown, ${expected} expected`);
    if (!(first.lit > 200)) throw new Error(`canvas looks blank: ${first.lit} drawn pixels`);
    if (process.env.VIEW_TEST_SHOTS) {
      await page.screenshot({ path: join(process.env.VIEW_TEST_SHOTS, `view-${runs.indexOf(dir)}.png`) });
    }
    const counter = await page.textContent("#counter");
    await page.click("#play");
    await page.waitForFunction(() => window.grainsView.frame >= 2 || window.grainsView.errors.length, null, { timeout: 30000 });
    if (errors.length) throw new Error(`console errors: ${errors.join(" | ")}`);
    const later = await page.textContent("#counter");
    if (later === counter) throw new Error(`frame counter did not move: ${counter}`);
    if (errors.length) throw new Error(`console errors: ${errors.join(" | ")}`);
    console.log(`ok: ${dir}: ${first.grains} grains, ${first.lit} drawn pixels, ${first.frames} frames; "${counter}" -> "${later}"`);
  } catch (e) {
    failures++;
    console.error(`FAIL: ${dir}: ${e.message}`);
    await page.screenshot({ path: join(dir, "view-test-failure.png") }).catch(() => {});
  } finally {
    await page.close();
    child.kill();
  }
}
await browser.close();
rmSync(profile, { recursive: true, force: true });
process.exit(failures ? 1 : 0);
