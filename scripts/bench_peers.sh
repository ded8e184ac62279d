#!/usr/bin/env bash
# Speed: tissuesim against Bender's PositionBasedDynamics (pypbd) on the same meshes, scene and
# dt, in one run; then tissuesim alone on the DESIGN §7 haptic scene with and without a probe.
#
#   scripts/bench_peers.sh [meshes (default liver_1k6,liver_4k,liver_10k)] [steps (default 1000)]
#
# Peer scene (../shared/peers/pypbd_liver.py): mesh units, E = 3000, nu = 0.45, rho = 1,
# dt = 1 ms, top 3% fixed, gravity; pypbd: FEM-based PBD tet constraints, 5 iterations, run with
# OMP_NUM_THREADS=1 and =2. tissuesim runs the same scene single-threaded (cargo bench --bench
# step -- --scene pypbd). The peer prints a mean over its steps, so the ratio is of means;
# tissuesim's median and p99 are given beside it. Writes docs/data/peers.csv and
# docs/data/bench_haptic.csv. Run it on an otherwise idle machine.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
MESHES="${1:-liver_1k6,liver_4k,liver_10k}"
STEPS="${2:-1000}"
OUT="$ROOT/docs/data"
mkdir -p "$OUT"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

validation/setup_venv.sh >/dev/null
cargo bench --bench step --no-run -q

echo "mesh,nodes,tissuesim_median_ms,tissuesim_p99_ms,tissuesim_mean_ms,pypbd_1thread_ms,pypbd_2threads_ms,ratio_1thread,ratio_2threads,pypbd_volume_ratio" > "$OUT/peers.csv"
printf '%-10s %7s | %-28s | %-19s | %s\n' "mesh" "nodes" "tissuesim median/p99/mean ms" "pypbd 1t / 2t ms" "speed-up 1t / 2t"
IFS=',' read -ra LIST <<< "$MESHES"
for mesh in "${LIST[@]}"; do
  cargo bench -q --bench step -- --scene pypbd --meshes "$mesh" --steps "$STEPS" --csv "$TMP/ours.csv" >/dev/null
  # Row without the probe: scene,mesh,probe,particles,pairs,substeps,median,p99,max,mean,...
  IFS=',' read -r _ _ _ nodes _ _ median p99 _ mean _ < <(grep ",false," "$TMP/ours.csv")
  p1=$(OMP_NUM_THREADS=1 validation/peer_pypbd.sh "$mesh" 200)
  p2=$(OMP_NUM_THREADS=2 validation/peer_pypbd.sh "$mesh" 200)
  ms1=$(echo "$p1" | awk '{print $4}')
  ms2=$(echo "$p2" | awk '{print $4}')
  vol=$(echo "$p1" | awk '{print $5}')
  r1=$(awk -v a="$ms1" -v b="$mean" 'BEGIN{printf "%.1f", a/b}')
  r2=$(awk -v a="$ms2" -v b="$mean" 'BEGIN{printf "%.1f", a/b}')
  echo "$mesh,$nodes,$median,$p99,$mean,$ms1,$ms2,$r1,$r2,$vol" >> "$OUT/peers.csv"
  printf '%-10s %7s | %8.3f %8.3f %8.3f    | %8.3f %8.3f   | %5sx %5sx\n' "$mesh" "$nodes" "$median" "$p99" "$mean" "$ms1" "$ms2" "$r1" "$r2"
done

echo
echo "DESIGN §7 haptic scene (SI, dt = 1 ms), single-threaded:"
cargo bench -q --bench step -- --scene haptic --meshes liver_1k6,liver_4k,liver_10k,liver_31k --steps "$STEPS" --csv "$OUT/bench_haptic.csv"
