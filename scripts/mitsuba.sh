#!/usr/bin/env bash
# splitsum against Mitsuba 3 (llvm_ad_rgb, from PyPI, in a virtual environment under
# target/): single spheres of white metal and of a coloured dielectric (r 0.3, 0.5, 0.65,
# 0.8, 1) under every sunny environment of the tuning and the held-out sets (or those named
# after RES), rendered by Mitsuba's path tracer with the glTF BRDF (scripts/mitsuba_gltf.py;
# one bounce: the exact reflectance integral, estimated), and splitsum's shading of the same
# pixels at 1, 4 and 16 fetches. Prints the table the guide quotes.
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
SPP=${1:-1024}
RES=${2:-64}
run bash scripts/dev.sh environments >&2
VENV=target/mitsuba-venv
if ! dry && [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install -q "mitsuba==3.9.1" "numpy>=1.26" >&2
fi
# The llvm variant compiles through the system's libLLVM, which Dr.Jit 1.5 needs at 16 or
# newer (LLVM 14 and 15 cannot lower its llvm.maximum on x86: "Cannot select: fmaximum").
llvm() { ls /usr/lib/*/libLLVM.so.[0-9][0-9]* /usr/lib/*/libLLVM-[0-9][0-9].so 2>/dev/null | grep -E 'LLVM(\.so\.|-)(1[6-9]|[2-9][0-9])' | sort -V | tail -1; }
if ! dry && [ -z "$(llvm)" ]; then
    echo "mitsuba.sh: installing libllvm19 (Mitsuba's llvm variant needs LLVM 16 or newer)" >&2
    if [ "$(id -u)" = 0 ]; then apt-get install -y -qq libllvm19 >&2; else sudo apt-get install -y -qq libllvm19 >&2; fi
fi
dry || export DRJIT_LIBLLVM_PATH="$(llvm)"
OUT=target/mitsuba
dry || { rm -rf "$OUT" && mkdir -p "$OUT"; }
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
run bash scripts/dev.sh cargo run --release -q -p splitsum-report --example mitsuba_spheres -- envs "$OUT" "${@:3}"
run "$VENV/bin/python" scripts/mitsuba_spheres.py render "$OUT" "$SPP" "$RES" >&2
run bash scripts/dev.sh cargo run --release -q -p splitsum-report --example mitsuba_spheres -- shade "$OUT"
run "$VENV/bin/python" scripts/mitsuba_spheres.py compare "$OUT" "$SPP" "$RES" ${FIGURE[@]+"${FIGURE[@]}"}
