#!/bin/sh
# Regenerate the evidence of docs/VALIDATION.md: accuracy against FEM, the paper's experiments and the probe
# force trace. One command from a fresh clone (meshes from data/meshes, or from
# TISSUESIM_MESHES=/path/to/meshes when set):
#
#     validation/run_evidence.sh                 # everything, ~10-15 min on 2 cores
#     validation/run_evidence.sh accuracy press  # only some parts (accuracy volume runtime large press), then plots
#
# Sets up the Python venv (validation/setup_venv.sh), builds and runs the Rust program
# (cargo run --release --example evidence), then validation/accuracy.py and validation/paper_experiments.py.
# Outputs: docs/data/*.csv, docs/data/accuracy_tables.md, docs/img/*.png (committed); build/evidence/ (node
# displacements, snapshots, VTU files for ParaView; not committed).
# Run the timing part (runtime) on an otherwise idle machine.
set -eu
cd "$(dirname "$0")/.."

parts=${*:-accuracy volume runtime large press}
validation/setup_venv.sh
PY=build/venv-validation/bin/python
cargo build --release --example evidence
EV="cargo run --release --quiet --example evidence --"
mkdir -p build/evidence docs/data docs/img

for part in $parts; do
    echo "== evidence: $part"
    case $part in
        accuracy) $EV accuracy --out build/evidence/accuracy ;;
        volume) $EV volume --out docs/data/volume_time.csv ;;
        runtime) $EV runtime --out docs/data/runtime.csv ;;
        large) $EV large --out build/evidence/large --summary docs/data/large_deformation.csv ;;
        press) $EV press --out docs/data/press_trace.csv ;;
        *) echo "unknown part $part (accuracy volume runtime large press)" >&2; exit 2 ;;
    esac
done

echo "== plots and tables"
if [ -f build/evidence/accuracy/runs.csv ]; then
    $PY validation/accuracy.py
fi
$PY validation/paper_experiments.py
echo "done: docs/data, docs/img (VTU for ParaView in build/evidence/large/vtu)"
