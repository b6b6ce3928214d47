// Each compute kernel's pipeline, and each of the display's two render pipelines (the
// fragment shader with its vertex shader), built alone in headless Chromium's WebGPU
// (SwiftShader) from its modules as WGSL, each in a fresh browser: the time to build it and
// the GPU process's peak resident memory (issue 33: which pipelines a browser can build).
//
//   mkdir -p target/wgsl && for f in spirv/src/modules/*.spv; do
//       naga "$f" "target/wgsl/$(basename "$f" .spv).wgsl"; done
//   (cd tests/webgpu && npm install) && node tests/webgpu/pipelines.mjs target/wgsl [NAME]
//
// Prints a line per kernel: name, WGSL size, milliseconds, peak MiB, and the error and
// the device's loss message if any.
import { createServer } from "node:http";
import { readFile, readdir } from "node:fs/promises";
import puppeteer from "puppeteer-core";
import { sampleGpuPeak } from "./gpu-memory.mjs";
const [dir, only] = process.argv.slice(2);
const root = dir.endsWith("/") ? dir : dir + "/";
// An empty page on loopback (a secure context, where WebGPU is offered).
const server = createServer((req, res) => { res.writeHead(200, { "content-type": "text/html" }); res.end("<!doctype html>"); }).listen(0, "127.0.0.1");
await new Promise((r) => server.once("listening", r));
// A fragment shader is built with the vertex shader its pipeline uses (display/src/render):
// the full-screen triangle for the scene, the mesh's (position, normal, tangent, uv) for
// meshes. Vertex shaders are not built alone.
const vertexOf = { display_scene_fs: "display_fullscreen_vs", display_mesh_fs: "display_mesh_vs" };
const files = (await readdir(root)).filter((f) => f.endsWith(".wgsl") && !f.endsWith("_vs.wgsl") && (!only || f.includes(only)));
for (const f of files) {
  const browser = await puppeteer.launch({ executablePath: "/usr/bin/chromium", headless: true, protocolTimeout: 300_000,
    args: ["--no-sandbox", "--disable-gpu-sandbox", "--enable-unsafe-webgpu", "--use-webgpu-adapter=swiftshader"] });
  const sampler = sampleGpuPeak(browser);
  try {
    const page = await browser.newPage();
    await page.goto(`http://127.0.0.1:${server.address().port}/`);
    const code = await readFile(root + f, "utf8");
    const name = f.replace(".wgsl", "");
    const vs = vertexOf[name];
    const vcode = vs ? await readFile(root + vs + ".wgsl", "utf8") : null;
    const r = await page.evaluate(async (code, name, vs, vcode) => {
      const a = await navigator.gpu.requestAdapter(); const d = await a.requestDevice({ requiredLimits: { maxStorageBuffersPerShaderStage: a.limits.maxStorageBuffersPerShaderStage } });
      let lost = null; d.lost.then((i) => { lost = i.message; });
      const t0 = performance.now();
      try {
        const m = d.createShaderModule({ code });
        if (vs) {
          const mesh = vs === "display_mesh_vs";
          const attributes = [[0, "float32x3", 0], [1, "float32x3", 12], [2, "float32x4", 24], [3, "float32x2", 40]]
            .map(([shaderLocation, format, offset]) => ({ shaderLocation, format, offset }));
          await d.createRenderPipelineAsync({
            layout: "auto",
            vertex: { module: d.createShaderModule({ code: vcode }), entryPoint: vs, buffers: mesh ? [{ arrayStride: 48, attributes }] : [] },
            fragment: { module: m, entryPoint: name, targets: [{ format: "rgba8unorm" }] },
            depthStencil: { format: "depth32float", depthWriteEnabled: true, depthCompare: "less" },
          });
        } else {
          await d.createComputePipelineAsync({ layout: "auto", compute: { module: m, entryPoint: name } });
        }
        return { ms: performance.now() - t0, lost };
      } catch (e) { return { ms: performance.now() - t0, error: String(e), lost }; }
    }, code, name, vs, vcode);
    const peak = sampler.stop();
    console.log(`${name}\t${(code.length / 1024).toFixed(0)} KB\t${r.ms.toFixed(0)} ms\tpeak ${(peak / 2 ** 20).toFixed(0)} MiB\t${r.error ?? ""}\t${r.lost ?? ""}`);
  } catch (e) { console.log(`${f}\tfailed: ${e}\tpeak ${(sampler.stop() / 2 ** 20).toFixed(0)} MiB`); }
  finally { await browser.close(); }
}
server.close();
