// Serves this folder on loopback, opens it in headless Chromium with WebGPU (SwiftShader),
// bakes the equirect in INPUT (little-endian f32: width, height, size, then RGB texels)
// with splitsum's kernels on the page's WebGPU device, and writes what the textures hold
// to OUTPUT (f32), or the browser's message to OUTPUT.err.
import { createServer } from "node:http";
import { readFile, writeFile } from "node:fs/promises";
import { extname, join } from "node:path";
import puppeteer from "puppeteer-core";
import { sampleGpuPeak } from "./gpu-memory.mjs";

const [input, output] = process.argv.slice(2);
const root = new URL(".", import.meta.url).pathname;
const types = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm" };
const server = createServer(async (req, res) => {
  try {
    const body = await readFile(join(root, decodeURIComponent(new URL(req.url, "http://x").pathname)));
    res.writeHead(200, { "content-type": types[extname(req.url)] ?? "application/octet-stream" });
    res.end(body);
  } catch {
    res.writeHead(404);
    res.end();
  }
}).listen(0, "127.0.0.1");
await new Promise((r) => server.once("listening", r));
const browser = await puppeteer.launch({
  executablePath: "/usr/bin/chromium",
  headless: true,
  protocolTimeout: 900_000,
  dumpio: true,
  args: ["--no-sandbox", "--disable-gpu-sandbox", "--enable-unsafe-webgpu", "--use-webgpu-adapter=swiftshader", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"],
});
// The GPU process's peak resident memory goes in OUTPUT.txt and OUTPUT.peak (bytes).
const sampler = sampleGpuPeak(browser);
try {
  const page = await browser.newPage();
  page.on("console", (m) => console.error("page:", m.text()));
  await page.goto(`http://127.0.0.1:${server.address().port}/index.html`);
  const bytes = await readFile(input);
  const header = new Uint32Array(bytes.buffer, bytes.byteOffset, 3);
  const texels = Array.from(new Float32Array(bytes.buffer, bytes.byteOffset + 12, (bytes.length - 12) / 4));
  const result = await page.evaluate(async (texels, w, h, size) => {
    const s = await window.splitsum;
    try {


      const t0 = performance.now();
      const out = await s.bake(new Float32Array(texels), w, h, size);
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
