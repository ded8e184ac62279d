#!/usr/bin/env bash
# The whole test suite: formatting, lints, Rust tests (solver, mesh I/O, C ABI from Rust),
# the C and C++ programs (header compiled as C and C++, programs built, run, and run under
# valgrind), the install (cmake/install.sh into a temporary prefix, then a CMake and a
# pkg-config consumer built against it and run), and the FMU (built, validated and simulated
# by fmpy in a virtual environment this script creates).
#
#   scripts/test_all.sh
#
# Needs only what a fresh Debian machine with the Rust toolchain, a C/C++ compiler and Python 3
# has, and a clone of the repository (the test meshes are in data/meshes); installs valgrind,
# cmake, pkg-config and python3-venv with apt-get if they are missing, and fmpy from PyPI into
# build/venv-fmu.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

section() { printf '\n==== %s ====\n' "$*"; }

section "cargo fmt --check"
cargo fmt --all -- --check

section "cargo clippy (warnings are errors)"
cargo clippy --workspace --all-targets --release -- -D warnings

section "Rust tests (release: the physics runs for simulated seconds)"
cargo test --workspace --release

section "C programs (examples_c/run_tests.sh: build, run, valgrind)"
examples_c/run_tests.sh

section "install (examples_c/test_install.sh: cmake/install.sh, CMake and pkg-config consumers)"
examples_c/test_install.sh

section "FMU (fmu/test.sh: build TissueSim.fmu, fmpy validate and simulate)"
fmu/test.sh

section "Python (python/test.sh: the wheel in build/venv-python, ruff, pytest, viewer under Xvfb)"
python/test.sh

section "all suites passed"
