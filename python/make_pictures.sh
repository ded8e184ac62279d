#!/usr/bin/env bash
# The pictures of the main scenario in the README (pressing, grasping, cutting), made by the
# viewer off-screen from the repository root:
#
#   python/make_pictures.sh            # docs/img/python_{press,grasp,cut}.png
#
# Uses $PYTHON (default build/venv-python/bin/python, made by python/test.sh) with tissuesim
# and pyvista installed; runs under xvfb-run when there is no display.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
PYTHON="${PYTHON:-$ROOT/build/venv-python/bin/python}"
RUN=()
if [ -z "${DISPLAY:-}" ]; then RUN=(xvfb-run -a -s "-screen 0 1280x1024x24"); fi
mkdir -p docs/img
for scenario in press grasp cut; do
    steps=(); if [ "$scenario" = cut ]; then steps=(--steps 130); fi  # the piece just cut off
    "${RUN[@]}" "$PYTHON" -m tissuesim.view --scenario "$scenario" --size 640 480 "${steps[@]}" \
        --screenshot "docs/img/python_$scenario.png"
done
