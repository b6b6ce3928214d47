// Serves the web page's build (web/dist) on loopback, opens it in headless Chromium with WebGPU (SwiftShader),
// bakes the equirect in INPUT (little-endian f32: width, height, size, then RGB texels)
// with splitsum's kernels on the page's WebGPU device, and writes what the textures hold
// to OUTPUT (f32), or the browser's message to OUTPUT.err.
import { readFile, writeFile } from "node:fs/promises";
import { sampleGpuPeak } from "./gpu-memory.mjs";
import { launchChromium, serveFolder } from "./browser.mjs";

const [input, output] = process.argv.slice(2);
// The page's build (bash scripts/web.sh), whose wasm also holds bake_textures.
const server = await serveFolder(new URL("../../web/dist", import.meta.url).pathname);
const browser = await launchChromium();
// The GPU process's peak resident memory goes in OUTPUT.txt and OUTPUT.peak (bytes).
const sampler = sampleGpuPeak(browser);
try {
  const page = await browser.newPage();
  page.on("console", (m) => console.error("page:", m.text()));
  await page.goto(`http://127.0.0.1:${server.address().port}/index.html?check`);
  await page.waitForFunction(() => window.splitsumWasm, { timeout: 300_000 });
  const bytes = await readFile(input);
  const header = new Uint32Array(bytes.buffer, bytes.byteOffset, 3);
  const texels = Array.from(new Float32Array(bytes.buffer, bytes.byteOffset + 12, (bytes.length - 12) / 4));
  const result = await page.evaluate(async (texels, w, h, size) => {
    const s = window.splitsumWasm;
    try {
      const t0 = performance.now();
      const out = await s.bake_textures(new Float32Array(texels), w, h, size);
      return { ms: performance.now() - t0, out: Array.from(out) };
    } catch (e) {
      return { error: String(e) };
    }
  }, texels, header[0], header[1], header[2]);
  if (result.error) {
    await writeFile(output + ".err", result.error);
    console.error("error:", result.error);
  } else {
    const peak = sampler.stop();
    const said = `bake and readback ${result.ms.toFixed(0)} ms in headless Chromium (SwiftShader), GPU process peak ${(peak / 2 ** 20).toFixed(0)} MiB`;
    console.error(said);
    await writeFile(output, Buffer.from(new Float32Array(result.out).buffer));
    await writeFile(output + ".txt", said + "\n");
    await writeFile(output + ".peak", String(peak));
  }
} finally {
  sampler.stop();
  await browser.close();
  server.close();
}
