// What the browser tests share: a folder served on loopback (a secure context, where
// WebGPU is offered) and headless Chromium with WebGPU on SwiftShader.
import { createServer } from "node:http";
import { readFile } from "node:fs/promises";
import { extname, join, normalize } from "node:path";
import puppeteer from "puppeteer-core";

const types = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm" };

// Serves the files under `root` (nothing outside it); resolves to the server, listening.
export async function serveFolder(root) {
  const server = createServer(async (req, res) => {
    try {
      const path = normalize(decodeURIComponent(new URL(req.url, "http://x").pathname));
      if (path.split("/").includes("..")) throw new Error("outside");
      const body = await readFile(join(root, path));
      res.writeHead(200, { "content-type": types[extname(path)] ?? "application/octet-stream" });
      res.end(body);
    } catch {
      res.writeHead(404);
      res.end();
    }
  }).listen(0, "127.0.0.1");
  await new Promise((r) => server.once("listening", r));
  return server;
}

// Headless Chromium with WebGPU (SwiftShader); its output shown (the GPU process's exit
// is reported there). The compositor on SwiftShader's Vulkan too: without it a WebGPU
// canvas shows and reads back as transparent black in headless Chromium (a cleared canvas
// read 0,0,0,0 with --use-angle=swiftshader alone, 255,0,0,255 with these).
// Without `webgpu`, Chromium as a browser without WebGPU (the page's CPU fallback).
export function launchChromium({ webgpu = true } = {}) {
  const gpu = ["--enable-unsafe-webgpu", "--use-webgpu-adapter=swiftshader"];
  return puppeteer.launch({
    executablePath: "/usr/bin/chromium",
    headless: true,
    protocolTimeout: 900_000,
    dumpio: true,
    args: ["--no-sandbox", "--disable-gpu-sandbox", ...(webgpu ? gpu : ["--disable-features=WebGPU"]),
           "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--enable-features=Vulkan", "--use-vulkan=swiftshader", "--disable-background-networking",
           "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"],
  });
}
