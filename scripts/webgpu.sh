#!/usr/bin/env bash
# splitsum in a browser: builds the library for wasm32-unknown-unknown (tests/webgpu, with
# wasm-bindgen), installs what that needs (the wasm32 target, wasm-bindgen-cli at the
# version the crate pins, Debian's chromium, puppeteer-core), then runs the test that bakes
# in headless Chromium's WebGPU (SwiftShader) and compares with the CPU backend.
set -euo pipefail
cd "$(dirname "$0")/.."
# SPLITSUM_DRY_RUN: print the commands instead of running them (as scripts/dev.sh does).
dry() { [ -n "${SPLITSUM_DRY_RUN:-}" ]; }
run() { if dry; then printf 'dry-run:'; printf ' %q' "$@"; echo; return 0; fi; "$@"; }
dry || rustup target add wasm32-unknown-unknown >&2
WASM_BINDGEN=0.2.130
if ! dry && [ "$(wasm-bindgen --version 2>/dev/null)" != "wasm-bindgen $WASM_BINDGEN" ]; then
    cargo install wasm-bindgen-cli --version "$WASM_BINDGEN" >&2
fi
if ! dry && ! command -v chromium >/dev/null; then
    if [ "$(id -u)" = 0 ]; then apt-get install -y -qq chromium >&2; else sudo apt-get install -y -qq chromium >&2; fi
fi
dry || (
    cd tests/webgpu
    cargo build --release --target wasm32-unknown-unknown
    wasm-bindgen --target web --out-dir pkg target/wasm32-unknown-unknown/release/splitsum_webgpu_check.wasm
    npm install --no-audit --no-fund --silent
)
run env XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}" cargo test --release -p splitsum-tests --test suite library::a_bake_in_the_browsers_webgpu_matches_the_cpu -- --ignored --nocapture
