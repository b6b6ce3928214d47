// The peak resident memory of a puppeteer browser's GPU process, sampled every 250 ms
// (issue 33: the GPU process is where SwiftShader compiles shaders). Only the GPU process
// that this browser started counts, not another Chromium's on the same machine.
import { execSync } from "node:child_process";

// The GPU process's resident memory now, in KiB (0 when it has none, or has exited).
function gpuRss(browserPid) {
  try {
    return Math.max(0, ...execSync("ps -eo ppid=,rss=,args=").toString().split("\n")
      .map((l) => l.trim().split(/\s+/))
      .filter((w) => Number(w[0]) === browserPid && w.slice(2).some((a) => a === "--type=gpu-process"))
      .map((w) => Number(w[1])));
  } catch {
    return 0;
  }
}

// Starts sampling `browser`'s GPU process; `stop()` ends it and returns the peak in bytes.
export function sampleGpuPeak(browser) {
  const pid = browser.process().pid;
  let peak = 0;
  const timer = setInterval(() => { peak = Math.max(peak, gpuRss(pid)); }, 250);
  return { stop: () => { clearInterval(timer); peak = Math.max(peak, gpuRss(pid)); return peak * 1024; } };
}
