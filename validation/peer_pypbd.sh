#!/usr/bin/env bash
# Peer timing: run Bender's PositionBasedDynamics (pypbd) on a TetGen liver mesh in the validation venv.
#
#   validation/peer_pypbd.sh MESH_BASE [steps] [iterations] [solid_model]
#   validation/peer_pypbd.sh data/meshes/liver_4k 200
#
# MESH_BASE is the mesh path without .node/.ele; a bare name such as liver_4k is looked up in
# $TISSUESIM_MESHES when set, else data/meshes. Prints the peer's one line: nodes tets iterations
# ms_per_step volume_ratio (scene: E=3000, nu=0.45, rho=1, dt=1 ms, gravity -9.81 y, top 3% fixed;
# see validation/peers/pypbd_liver.py).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PY="$ROOT/build/venv-validation/bin/python"
PEER="$ROOT/validation/peers/pypbd_liver.py"
MESH_DIR="${TISSUESIM_MESHES:-$ROOT/data/meshes}"

if [ $# -lt 1 ]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
MESH="$1"; shift
if [ ! -f "$MESH.node" ] && [ -f "$MESH_DIR/$MESH.node" ]; then
  MESH="$MESH_DIR/$MESH"
fi
[ -f "$MESH.node" ] && [ -f "$MESH.ele" ] ||
  { echo "peer_pypbd: no $MESH.node/.ele (nor in $MESH_DIR)" >&2; exit 2; }
[ -f "$PEER" ] || { echo "peer_pypbd: peer script not found at $PEER" >&2; exit 2; }
if ! "$PY" -c 'import pypbd, numpy' >/dev/null 2>&1; then
  "$ROOT/validation/setup_venv.sh" >&2
fi
exec "$PY" "$PEER" "$MESH" "$@"
