#!/usr/bin/env bash
# Build TissueSim.fmu and run its Python tests (fmpy) from the repository root.
#
#   fmu/test.sh [pytest arguments]
#
# Creates (once) a virtual environment in build/venv-fmu with the pinned packages of
# fmu/requirements-test.txt, builds the FMU with `cargo run --release -p tissuesim-fmu --bin
# build-fmu` (honours CARGO_TARGET_DIR, default target/), then runs `pytest tests/fmu -q`.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
VENV="$ROOT/build/venv-fmu"
REQ="$ROOT/fmu/requirements-test.txt"

if [ ! -x "$VENV/bin/python" ]; then
    rm -rf "$VENV"
    if ! python3 -m venv "$VENV" 2>/dev/null; then
        echo "fmu/test.sh: python3 -m venv failed; installing python3-venv" >&2
        rm -rf "$VENV"
        SUDO=""
        if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
        $SUDO apt-get update -qq
        $SUDO apt-get install -y -qq python3-venv
        python3 -m venv "$VENV"
    fi
fi

# Install the pinned packages unless this exact list is already installed.
STAMP="$VENV/.requirements-test.txt"
if ! cmp -s "$REQ" "$STAMP"; then
    "$VENV/bin/python" -m pip install --disable-pip-version-check -q -r "$REQ"
    cp "$REQ" "$STAMP"
fi

TARGET="${CARGO_TARGET_DIR:-$ROOT/target}"
case "$TARGET" in /*) ;; *) TARGET="$ROOT/$TARGET" ;; esac
export TISSUESIM_FMU="$TARGET/fmu/TissueSim.fmu"
cargo run --release -q -p tissuesim-fmu --bin build-fmu -- --out "$TISSUESIM_FMU"

exec "$VENV/bin/python" -m pytest tests/fmu -q "$@"
