#!/usr/bin/env bash
# Create (idempotently) the validation virtual environment at build/venv-validation (relative to the repo
# root) and install pinned versions of scikit-fem, numpy, scipy, matplotlib, pyamg, pypbd, pymetis and gmsh from PyPI.
#
#   validation/setup_venv.sh            # create or update; safe to re-run
#   PYTHON=python3.11 validation/setup_venv.sh
#
# On a fresh Debian machine whose python3 lacks ensurepip (no python3-venv), it installs python3-venv with
# apt-get (as root, or through sudo when available) and retries.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/build/venv-validation"
PYTHON="${PYTHON:-python3}"

# Pinned versions (the set the committed reference results were produced with, CPython 3.11).
PINS=(
  "numpy==2.4.6"
  "scipy==1.17.1"
  "scikit-fem==12.0.2"
  "matplotlib==3.11.2"
  "pyamg==5.4.1"
  "pypbd==2.2.2"
  "pymetis==2025.2.2"  # fem_reference/mixed_reference: nested-dissection ordering for SuperLU
  "gmsh==4.15.2"  # validation/gmsh_organs.py: the meshes from a second mesher (manylinux wheel, no dependencies)
  # their dependencies, pinned too so a re-run installs the same set
  "contourpy==1.3.3" "cycler==0.12.1" "fonttools==4.68.0" "kiwisolver==1.5.1" "packaging==26.3"
  "pillow==13.0.0" "pygame==2.6.1" "PyOpenGL==3.1.10" "pyparsing==3.3.3" "python-dateutil==4.0.0"
  "tzdata==2026.6" "typing-extensions==4.16.0"
)

have_venv_support() {
  "$PYTHON" -c 'import ensurepip, venv' >/dev/null 2>&1
}

if [ ! -x "$VENV/bin/python" ]; then
  if ! have_venv_support; then
    echo "setup_venv: $PYTHON has no ensurepip/venv; installing python3-venv with apt-get" >&2
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then
      if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
        echo "setup_venv: not root and no sudo: install python3-venv yourself" >&2; exit 1
      fi
    fi
    $SUDO apt-get update
    # the versioned package (python3.11-venv) is what provides ensurepip on Debian 12
    PYV="$("$PYTHON" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y python3-venv "python${PYV}-venv" \
      || $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y python3-venv
  fi
  # a half-made venv (e.g. from a failed earlier run without ensurepip) is replaced
  rm -rf "$VENV"
  mkdir -p "$ROOT/build"
  "$PYTHON" -m venv "$VENV"
fi

# Skip pip when every pin is already satisfied (fast re-runs, works offline).
if "$VENV/bin/python" - "${PINS[@]}" <<'EOF' >/dev/null 2>&1
import sys
from importlib.metadata import version
for pin in sys.argv[1:]:
    name, want = pin.split('==')
    assert version(name) == want, pin
EOF
then
  echo "setup_venv: $VENV is up to date"
else
  "$VENV/bin/python" -m pip install --disable-pip-version-check "${PINS[@]}"
fi
"$VENV/bin/python" -c 'import numpy, scipy, skfem, pyamg, matplotlib, pypbd, gmsh, pymetis; print("setup_venv: ok: numpy", numpy.__version__, "scipy", scipy.__version__, "scikit-fem", skfem.__version__)'
