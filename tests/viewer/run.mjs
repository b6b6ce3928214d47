// Serves the viewer page (this folder), the renderer (node_modules) and DATA on loopback,
// opens the page in headless Chromium (WebGL2 on SwiftShader) and renders the models of
// JOBS ({ folders, models, sheen_e, w, h, exposure, mips }) under each lighting, writing
// the frames to OUTPUT as JSON ({ folder, model, mips, px } per frame, model-major), or the
// browser's error to stderr.
import { createServer } from "node:http";
import { readFile, writeFile } from "node:fs/promises";
import { extname, join } from "node:path";
import puppeteer from "puppeteer-core";

const [data, jobsPath, output] = process.argv.slice(2);
const here = new URL(".", import.meta.url).pathname;
const types = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm", ".png": "image/png" };
const server = createServer(async (req, res) => {
  const path = decodeURIComponent(new URL(req.url, "http://x").pathname);
  const file = path.startsWith("/data/") ? join(data, path.slice(6))
    : path.startsWith("/viewer/") ? join(here, "node_modules/@khronosgroup/gltf-viewer/dist", path.slice(8))
    : join(here, path);
  try {
    const body = await readFile(file);
    res.writeHead(200, { "content-type": types[extname(file)] ?? "application/octet-stream" });
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
  protocolTimeout: 600_000,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
         "--disable-background-networking", "--disable-component-update", "--no-first-run"],
});
try {
  const page = await browser.newPage();
  // The renderer looks for a Draco decoder it is not given (no model here is compressed):
  // its error is logged, not fatal; a failed render rejects the evaluation below.
  page.on("pageerror", (e) => console.error("page error:", String(e)));
  await page.goto(`http://127.0.0.1:${server.address().port}/index.html`);
  await page.waitForFunction("window.ready === true");
  const out = await page.evaluate(async (o) => await window.render(o), JSON.parse(await readFile(jobsPath, "utf8")));
  await writeFile(output, JSON.stringify(out));
} finally {
  await browser.close();
  server.close();
}
