#!/usr/bin/env bash
# Builds splitsum's web page into web/dist/ (a static folder: serve it with any web server,
# e.g. `python3 -m http.server -d web/dist 8000`, and open http://localhost:8000).
# Installs what it needs: the wasm32 target and the wasm-bindgen CLI at the version
# web/Cargo.lock pins (crates.io).
set -euo pipefail
cd "$(dirname "$0")/.."
# SPLITSUM_DRY_RUN (tests/commands.rs): nothing is installed or built.
if [ -n "${SPLITSUM_DRY_RUN:-}" ]; then
    echo "web.sh (dry run): would build web/ for wasm32 and bind it into web/dist" >&2
    exit 0
fi
rustup target add wasm32-unknown-unknown >&2
want=$(sed -n '/^name = "wasm-bindgen"$/{n;s/^version = "\(.*\)"/\1/p}' web/Cargo.lock)
if [ "$(wasm-bindgen --version 2>/dev/null)" != "wasm-bindgen $want" ]; then
    # Not --locked: its lock pins crates (webpki-roots 1.0.11) this registry lacks.
    # --force: cargo's records may say it is installed where the binary is gone. About 2
    # minutes on two cores.
    echo "web.sh: installing wasm-bindgen-cli $want (crates.io)" >&2
    cargo +stable install --force wasm-bindgen-cli --version "$want" >&2
fi
(cd web && cargo +stable build --release --target wasm32-unknown-unknown >&2)
rm -rf web/dist
mkdir -p web/dist
wasm-bindgen --target web --out-dir web/dist/pkg web/target/wasm32-unknown-unknown/release/splitsum_web.wasm
cp web/index.html web/page.js web/dist/
# The sample the page offers: the CC0 courtyard the command line embeds.
cp splitsum/assets/courtyard.exr web/dist/
echo "web.sh: built web/dist ($(du -sh web/dist | cut -f1)); serve it with: python3 -m http.server -d web/dist 8000" >&2
