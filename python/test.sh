#!/usr/bin/env bash
# The Python package's tests, from a fresh virtual environment and the really built wheel.
#
#   python/test.sh [pytest arguments]
#
# Idempotent. Creates build/venv-python (python3-venv from apt-get when missing), installs the
# pinned python/requirements-test.txt (once per change of it), installs what the viewer needs
# to render off-screen (xvfb, Mesa) with apt-get when missing, checks the binding crate's
# formatting (cargo fmt --check; it is its own workspace, outside scripts/test_all.sh's),
# builds and installs the wheel with `pip install ./python` (CARGO_TARGET_DIR, default the
# root target/) with clippy's lints as errors on the binding crate, runs ruff on the Python
# code, then pytest under xvfb-run. No test collected (pytest's exit code 5) is a failure.
#
# Clippy runs inside the wheel's build: RUSTC_WORKSPACE_WRAPPER=clippy-driver and CLIPPY_ARGS
# are what `cargo clippy` itself sets, so the binding crate (the only workspace member) is
# compiled and linted in one pass and its dependencies are compiled once, for the wheel. A
# separate `cargo clippy` would check the whole solver's dependency tree again (2 minutes on
# 2 cores): the binding's workspace cannot reuse the root's artifacts, since pyo3 and numpy
# switch on features of shared dependencies (once_cell, num-complex `std`), which changes
# their hashes and those of everything built on them.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
VENV="$ROOT/build/venv-python"
REQ="$ROOT/python/requirements-test.txt"
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
APT_UPDATED=""
apt_install() {
    if [ -z "$APT_UPDATED" ]; then $SUDO apt-get update -qq; APT_UPDATED=1; fi
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "$@" >/dev/null
}
START=$SECONDS
step() { printf -- '--- python: %s (at %ds)\n' "$*" "$((SECONDS - START))"; }

# What the viewer needs off-screen: a virtual X server and Mesa's OpenGL (llvmpipe).
missing=()
command -v xvfb-run >/dev/null || missing+=(xvfb xauth)
for lib in libGL.so.1 libXrender.so.1 libX11.so.6; do
    ldconfig -p | grep -q "$lib" || missing+=(libgl1 libgl1-mesa-dri libglx-mesa0 libxrender1 libx11-6)
done
[ -e /usr/lib/x86_64-linux-gnu/dri/swrast_dri.so ] || missing+=(libgl1-mesa-dri)
if [ ${#missing[@]} -gt 0 ]; then
    step "apt-get install ${missing[*]}"
    apt_install $(printf '%s\n' "${missing[@]}" | sort -u)
fi

if [ ! -x "$VENV/bin/python" ]; then
    rm -rf "$VENV"
    if ! python3 -m venv "$VENV" 2>/dev/null; then
        rm -rf "$VENV"
        apt_install python3-venv
        python3 -m venv "$VENV"
    fi
fi
STAMP="$VENV/.requirements-test.txt"
if ! cmp -s "$REQ" "$STAMP"; then
    step "pip install -r python/requirements-test.txt"
    "$VENV/bin/python" -m pip install --disable-pip-version-check -q -r "$REQ"
    cp "$REQ" "$STAMP"
fi

step "cargo fmt --check (python/Cargo.toml)"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$ROOT/target}"
cargo fmt --manifest-path python/Cargo.toml -- --check

step "ruff"
"$VENV/bin/ruff" check python
"$VENV/bin/ruff" format --check python

CLIPPY_DRIVER="$(rustup which clippy-driver 2>/dev/null || true)"
if [ -z "$CLIPPY_DRIVER" ]; then CLIPPY_DRIVER="$(dirname "$(command -v cargo)")/clippy-driver"; fi
if [ ! -x "$CLIPPY_DRIVER" ]; then
    echo "python/test.sh: clippy-driver not found (rustup component add clippy)" >&2
    exit 1
fi
step "pip install ./python (the wheel, built by maturin; clippy -D warnings on the binding)"
RUSTC_WORKSPACE_WRAPPER="$CLIPPY_DRIVER" CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__" \
    "$VENV/bin/python" -m pip install --disable-pip-version-check -q --force-reinstall --no-deps ./python

step "pytest python/tests (under xvfb-run)"
status=0
TISSUESIM_REQUIRE_VIEW=1 xvfb-run -a -s "-screen 0 1280x1024x24" \
    "$VENV/bin/python" -m pytest python/tests -q -p no:cacheprovider "$@" || status=$?
step "done (pytest exit code $status)"
if [ "$status" = 5 ]; then
    echo "python/test.sh: pytest collected no test" >&2
fi
exit "$status"
