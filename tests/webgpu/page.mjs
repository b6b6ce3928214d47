// The web page as a user meets it, in headless Chromium with WebGPU (SwiftShader): serves
// web/dist (bash scripts/web.sh), opens the page, drops the HDRI file INPUT on it, waits for
// its bake, screenshots the canvas (the sphere grid) to OUT/grid.png, clicks each
// target's download and keeps the zips as OUT/TARGET.zip; OUT/page.json says how long each took and
// the GPU process's peak memory; OUT/page.png is the whole page (the README's picture).
// The browser's message, if any, goes to OUT/error.txt. With --no-webgpu the browser has
// no WebGPU, and the page falls back to the CPU backend compiled to wasm.
//
//   node tests/webgpu/page.mjs INPUT OUT [--no-webgpu]
import { readFile, readdir, writeFile, mkdir, rm } from "node:fs/promises";
import { basename, join } from "node:path";
import { sampleGpuPeak } from "./gpu-memory.mjs";
import { launchChromium, serveFolder } from "./browser.mjs";

const [input, out, flag] = process.argv.slice(2);
await mkdir(out, { recursive: true });
const downloads = join(out, "downloads");
await rm(downloads, { recursive: true, force: true });
await mkdir(downloads);
const server = await serveFolder(new URL("../../web/dist", import.meta.url).pathname);
const browser = await launchChromium({ webgpu: flag !== "--no-webgpu" });
const sampler = sampleGpuPeak(browser);
const seconds = (t) => Number(((performance.now() - t) / 1000).toFixed(2));
const report = {};
try {
  const page = await browser.newPage();
  page.on("console", (m) => console.error("page:", m.text()));
  await page.setViewport({ width: 1000, height: 800, deviceScaleFactor: 1 });
  const session = await page.createCDPSession();
  await session.send("Browser.setDownloadBehavior", { behavior: "allow", downloadPath: downloads });
  let t = performance.now();
  await page.goto(`http://127.0.0.1:${server.address().port}/index.html`);
  await page.waitForFunction(() => ["ready", "error"].includes(document.body.dataset.state), { timeout: 600_000 });
  report.open_s = seconds(t);
  report.backend = await page.$eval("#backend", (e) => e.textContent);
  // Dropped as a user drops it: a drop event carrying the file.
  const bytes = (await readFile(input)).toString("base64");
  t = performance.now();
  await page.evaluate((name, b64) => {
    const bin = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const data = new DataTransfer();
    data.items.add(new File([bin], name));
    document.getElementById("drop").dispatchEvent(new DragEvent("drop", { dataTransfer: data, bubbles: true, cancelable: true }));
  }, basename(input), bytes);
  await page.waitForFunction(() => ["shown", "error"].includes(document.body.dataset.state), { timeout: 600_000 });
  report.bake_s = seconds(t);
  report.message = await page.$eval("#message", (e) => e.textContent);
  if ((await page.evaluate(() => document.body.dataset.state)) === "error") throw new Error(report.message);
  // Two frames, so that the drawn one is on screen.
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  // One more frame, timed (on WebGPU: recording and submitting it; on the CPU: drawing it).
  report.draw_ms = Number((await page.evaluate(() => { const t = performance.now(); window.splitsumPage.draw(0, 0, 0, 1); return performance.now() - t; })).toFixed(1));
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  await (await page.$("#view")).screenshot({ path: join(out, "grid.png") });
  await page.screenshot({ path: join(out, "page.png"), clip: { x: 0, y: 0, width: 1000, height: 680 } });
  // Each target's download, as a user clicks it.
  report.downloads = {};
  for (const target of ["splitsum", "khronos", "bevy", "filament"]) {
    t = performance.now();
    await page.click(`button.target[value="${target}"]`);
    let zip = null;
    while (!zip) {
      await new Promise((r) => setTimeout(r, 250));
      zip = (await readdir(downloads)).find((f) => f.endsWith(`-${target}.zip`));
      if ((await page.evaluate(() => document.body.dataset.state)) === "error") throw new Error(await page.$eval("#message", (e) => e.textContent));
    }
    await page.waitForFunction(() => document.body.dataset.state === "shown");
    report.downloads[target] = `${seconds(t)} s: ${await page.$eval("#message", (e) => e.textContent)}`;
    await writeFile(join(out, `${target}.zip`), await readFile(join(downloads, zip)));
  }
} catch (e) {
  await writeFile(join(out, "error.txt"), String(e));
  console.error("error:", String(e));
} finally {
  report.gpu_process_peak_mib = Math.round(sampler.stop() / 2 ** 20);
  await writeFile(join(out, "page.json"), JSON.stringify(report, null, 1));
  console.error(JSON.stringify(report));
  await browser.close();
  server.close();
}
