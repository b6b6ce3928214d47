// The page's controls: dropping or choosing a file, the progress of its bake, orbiting,
// exposure and the fetch ladder, and the downloads. Everything else is splitsum's wasm
// (web/src/lib.rs). document.body.dataset.state says where the page is: opening, ready,
// baking, shown, zipping or error (the browser test waits on it).
import init, * as splitsum from "./pkg/splitsum_web.js";

const $ = (id) => document.getElementById(id);
const canvas = $("view");
const view = { yaw: 0, pitch: 0, exposure: 0, fetches: 1 };
let page = null;
let name = null;

const state = (s) => (document.body.dataset.state = s);
const say = (text, error = false) => {
  $("message").textContent = text;
  $("message").className = error ? "error" : "";
};

function draw() {
  if (!page || !name) return;
  try {
    page.draw(view.yaw, view.pitch, view.exposure, view.fetches);
  } catch (e) {
    say(String(e), true);
  }
}

let queued = false;
function redraw() {
  if (queued) return;
  queued = true;
  requestAnimationFrame(() => {
    queued = false;
    draw();
  });
}

async function bake(fileName, bytes) {
  state("baking");
  for (const b of document.querySelectorAll(".target")) b.disabled = true;
  say(`reading and baking ${fileName}…`);
  $("progress").value = 0;
  const start = performance.now();
  // The device works after the steps are submitted: the bar follows the estimates.
  const timer = setInterval(() => {
    const est = page.estimate();
    const elapsed = (performance.now() - start) / 1000;
    if (est > 0) $("progress").value = Math.min(elapsed / est, 0.99);
    say(`${page.step() || "reading"}: ${elapsed.toFixed(1)} s of about ${est.toFixed(1)} s`);
  }, 100);
  // A frame first, so that the message shows before a CPU bake holds the page.
  await new Promise((r) => setTimeout(r, 30));
  try {
    const said = await page.load(fileName, bytes);
    name = fileName;
    $("progress").value = 1;
    say(said);
    for (const b of document.querySelectorAll(".target")) b.disabled = false;
    draw();
    state("shown");
  } catch (e) {
    say(String(e), true);
    state(name ? "shown" : "error");
  } finally {
    clearInterval(timer);
  }
}

async function download(target) {
  state("zipping");
  say(`baking the ${target} folder with the default settings (CPU backend)…`);
  await new Promise((r) => setTimeout(r, 30));
  try {
    const start = performance.now();
    const zip = await page.download(target);
    const stem = name.replace(/\.[^.]*$/, "");
    const a = document.createElement("a");
    a.href = URL.createObjectURL(new Blob([zip], { type: "application/zip" }));
    a.download = `${stem}-${target}.zip`;
    document.body.append(a);
    a.click();
    a.remove();
    say(`${a.download}: ${(zip.length / 2 ** 20).toFixed(1)} MiB in ${((performance.now() - start) / 1000).toFixed(1)} s`);
  } catch (e) {
    say(String(e), true);
  }
  state("shown");
}

function wire() {
  const drop = $("drop");
  for (const t of ["dragenter", "dragover"]) document.addEventListener(t, (e) => { e.preventDefault(); drop.classList.add("over"); });
  document.addEventListener("dragleave", () => drop.classList.remove("over"));
  document.addEventListener("drop", async (e) => {
    e.preventDefault();
    drop.classList.remove("over");
    const file = e.dataTransfer.files[0];
    if (file) await bake(file.name, new Uint8Array(await file.arrayBuffer()));
  });
  $("file").addEventListener("change", async (e) => {
    const file = e.target.files[0];
    if (file) await bake(file.name, new Uint8Array(await file.arrayBuffer()));
  });
  $("sample").addEventListener("click", async () => {
    const bytes = new Uint8Array(await (await fetch("courtyard.exr")).arrayBuffer());
    await bake("courtyard.exr", bytes);
  });
  $("exposure").addEventListener("input", (e) => {
    view.exposure = Number(e.target.value);
    $("stops").textContent = `${view.exposure >= 0 ? "+" : ""}${view.exposure} stops`;
    redraw();
  });
  $("fetches").addEventListener("change", (e) => { view.fetches = Number(e.target.value); redraw(); });
  $("reset").addEventListener("click", () => { view.yaw = 0; view.pitch = 0; redraw(); });
  for (const b of document.querySelectorAll(".target")) b.addEventListener("click", () => download(b.value));
  // Orbit: a drag across the canvas turns the camera half a turn (frames coalesced to one
  // per animation frame; on the CPU a 640×360 frame takes about 0.1 s).
  let from = null;
  canvas.addEventListener("pointerdown", (e) => { from = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener("pointermove", (e) => {
    if (!from) return;
    view.yaw -= ((e.clientX - from[0]) / canvas.clientWidth) * 180;
    view.pitch = Math.max(-85, Math.min(85, view.pitch + ((e.clientY - from[1]) / canvas.clientHeight) * 90));
    from = [e.clientX, e.clientY];
    redraw();
  });
  canvas.addEventListener("pointerup", () => { from = null; redraw(); });
}

state("opening");
wire();
try {
  await init();
  // The browser test of the library alone (tests/webgpu/run.mjs) calls the wasm itself.
  window.splitsumWasm = splitsum;
  if (new URLSearchParams(location.search).has("check")) throw "opened for the library's check";
  page = await splitsum.open(canvas);
  window.splitsumPage = page;
  window.splitsumGpu = !page.backend().startsWith("the CPU");
  $("backend").textContent = `baking and drawing on ${page.backend()}`;
  if (!window.splitsumGpu) {
    $("nogpu").hidden = false;
    $("nogpu").textContent =
      "This browser offers no WebGPU, so splitsum bakes on the CPU compiled to WebAssembly (one thread) " +
      "and draws with its CPU reference renderer: slower, the same numbers. Chrome and Edge 113+ have WebGPU.";
  }
  state("ready");
} catch (e) {
  say(`splitsum could not start: ${e}`, true);
  state("error");
}
