#!/usr/bin/env bash
# splitsum against Mitsuba 3 (scalar_rgb, from PyPI, in a virtual environment under
# target/): single white-metal spheres (r 0.3, 0.5, 0.65, 0.8, 1) under every sunny
# environment of the tuning and the held-out sets (or those named after RES), rendered by
# Mitsuba's path tracer (one bounce: the exact reflectance integral, estimated), and
# splitsum's shading of the same pixels at 1, 4 and 16 fetches. Prints the table the README
# quotes. 22 s on 2 cores for all eight environments at 256 samples, 64² (once Mitsuba is
# installed and the example built).
# With --figure FILE it also writes the table as a generated figure of the guide (`bash
# scripts/dev.sh figures` writes book/src/figures/mitsuba.md so).
#   bash scripts/mitsuba.sh [--figure FILE] [SPP] [RES] [ENVIRONMENT...]
set -euo pipefail
cd "$(dirname "$0")/.."
FIGURE=()
if [ "${1:-}" = "--figure" ]; then
    FIGURE=("$2")
    shift 2
fi
# SPLITSUM_DRY_RUN: print the commands instead of running them (as scripts/dev.sh does).
dry() { [ -n "${SPLITSUM_DRY_RUN:-}" ]; }
run() { if dry; then printf 'dry-run:'; printf ' %q' "$@"; echo; return 0; fi; "$@"; }
SPP=${1:-256}
RES=${2:-64}
run bash scripts/dev.sh environments >&2
VENV=target/mitsuba-venv
if ! dry && [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install -q "mitsuba==3.9.1" "numpy>=1.26" >&2
fi
OUT=target/mitsuba
dry || { rm -rf "$OUT" && mkdir -p "$OUT"; }
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
run bash scripts/dev.sh cargo run --release -q -p splitsum-report --example mitsuba_spheres -- envs "$OUT" "${@:3}"
run "$VENV/bin/python" scripts/mitsuba_spheres.py render "$OUT" "$SPP" "$RES" >&2
run bash scripts/dev.sh cargo run --release -q -p splitsum-report --example mitsuba_spheres -- shade "$OUT"
run "$VENV/bin/python" scripts/mitsuba_spheres.py compare "$OUT" "$SPP" "$RES" ${FIGURE[@]+"${FIGURE[@]}"}
