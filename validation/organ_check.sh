#!/usr/bin/env bash
# Diagnostic of docs/VALIDATION.md section 1.4: is the liver's softness due to its graded mesh?
# Runs the liver scene (E 3000, nu 0.3, rho 1, g 0.981, top 10% fixed) on the project's own
# quasi-uniform default organ, against scikit-fem P1/P2 on the same mesh.
#
#   validation/organ_check.sh            # ~2 min; prints relative L2 errors
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
DIR=build/evidence/organ_check
PY=build/venv-validation/bin/python
validation/setup_venv.sh >/dev/null
mkdir -p "$DIR"
cargo run -q --release --example organ_check -- export "$DIR"
"$PY" validation/organ_check.py "$DIR"
echo "P1 (linear tets) vs P2:"; "$PY" validation/compare.py "$DIR/organ_p1.csv" "$DIR/organ_p2.csv" | tail -1
for hg in 0.05 0 2; do
  cargo run -q --release --example organ_check -- run "$DIR/organ_mls_hg$hg.csv" "$hg"
  echo "point-based, hourglass $hg, vs P2:"; "$PY" validation/compare.py "$DIR/organ_mls_hg$hg.csv" "$DIR/organ_p2.csv" | tail -1
done
