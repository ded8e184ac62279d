#!/usr/bin/env bash
# Speed: tissuesim against Bender's PositionBasedDynamics (pypbd) on the same meshes, scene and
# dt, in one run (each on one thread and on two); then tissuesim alone on the haptic
# scene with and without a probe (the four livers and the three-organ scene), the speed-up of two
# threads over one with the serial share it implies (Amdahl) and its projection to 4-16 threads.
#
#   scripts/bench_peers.sh [meshes (default liver_1k6,liver_4k,liver_10k)] [steps (default 1000)]
#
# Peer scene (validation/peers/pypbd_liver.py): mesh units, E = 3000, nu = 0.45, rho = 1,
# dt = 1 ms, top 3% fixed, gravity; pypbd: FEM-based PBD tet constraints, 5 iterations, run with
# OMP_NUM_THREADS=1 and =2. tissuesim runs the same scene with Settings::threads 1 and 2 (cargo
# bench --bench step -- --scene pypbd --threads N). The peer prints a mean over its steps, so the
# ratios are of means (1 thread vs 1 thread, 2 vs 2); tissuesim's median and p99 are given beside
# them. Writes docs/data/peers.csv, docs/data/bench_haptic.csv and docs/data/step_times_haptic.txt
# (the haptic scene's step-time distribution), docs/data/speedup_haptic.txt. Run it on an idle
# machine.
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

echo "mesh,nodes,tissuesim_1t_median_ms,tissuesim_1t_p99_ms,tissuesim_1t_mean_ms,tissuesim_2t_median_ms,tissuesim_2t_p99_ms,tissuesim_2t_mean_ms,pypbd_1t_ms,pypbd_2t_ms,ratio_1t,ratio_2t,pypbd_volume_ratio" > "$OUT/peers.csv"
printf '%-10s %6s | %-24s | %-24s | %-17s | %s\n' "mesh" "nodes" "ours 1t median/p99/mean" "ours 2t median/p99/mean" "pypbd 1t / 2t" "speed-up 1t / 2t"
ours() { # mesh threads -> "nodes median p99 mean" of the run without probe
  cargo bench -q --bench step -- --scene pypbd --meshes "$1" --steps "$STEPS" --threads "$2" --csv "$TMP/ours.csv" >/dev/null
  # scene,threads,mesh,probe,particles,pairs,substeps,median,p99,max,mean,...
  grep ",false," "$TMP/ours.csv" | awk -F, '{print $5, $8, $9, $11}'
}
IFS=',' read -ra LIST <<< "$MESHES"
for mesh in "${LIST[@]}"; do
  read -r nodes m1 q1 a1 < <(ours "$mesh" 1)
  read -r _ m2 q2 a2 < <(ours "$mesh" 2)
  p1=$(OMP_NUM_THREADS=1 validation/peer_pypbd.sh "$mesh" 200)
  p2=$(OMP_NUM_THREADS=2 validation/peer_pypbd.sh "$mesh" 200)
  ms1=$(echo "$p1" | awk '{print $4}')
  ms2=$(echo "$p2" | awk '{print $4}')
  vol=$(echo "$p1" | awk '{print $5}')
  r1=$(awk -v a="$ms1" -v b="$a1" 'BEGIN{printf "%.1f", a/b}')
  r2=$(awk -v a="$ms2" -v b="$a2" 'BEGIN{printf "%.1f", a/b}')
  echo "$mesh,$nodes,$m1,$q1,$a1,$m2,$q2,$a2,$ms1,$ms2,$r1,$r2,$vol" >> "$OUT/peers.csv"
  printf '%-10s %6s | %7.3f %7.3f %7.3f  | %7.3f %7.3f %7.3f  | %7.3f %7.3f | %5sx %5sx\n' "$mesh" "$nodes" "$m1" "$q1" "$a1" "$m2" "$q2" "$a2" "$ms1" "$ms2" "$r1" "$r2"
done

echo
echo "Haptic scene (SI, dt = 1 ms), 1 and 2 threads:"
for t in 1 2; do
  cargo bench -q --bench step -- --scene haptic --meshes liver_1k6,liver_4k,liver_10k,liver_31k,three_organs --steps "$STEPS" --threads "$t" --csv "$TMP/h$t.csv" --times "$TMP/times$t.csv"
done
{ cat "$TMP/h1.csv"; tail -n +2 "$TMP/h2.csv"; } > "$OUT/bench_haptic.csv"
echo
echo "Haptic scene, two threads against one (same run; medians). Serial share s from Amdahl's law"
echo "(speed-up S on 2 threads = 1/(s + (1-s)/2), so s = 2/S - 1) and what it projects to 4, 8, 16 threads:"
awk -F, 'NR == FNR { if (FNR > 1) one[$3 "," $4] = $8; next }
  FNR > 1 { k = $3 "," $4; if (k in one) {
    S = one[k] / $8; s = 2 / S - 1; if (s < 0) s = 0; if (s > 1) s = 1
    printf "%-13s probe %-5s  1t %7.3f ms  2t %7.3f ms  speed-up %.2fx  serial %4.1f%%  ->  4t %.1fx  8t %.1fx  16t %.1fx\n",
      $3, $4, one[k], $8, S, 100 * s, 1 / (s + (1 - s) / 4), 1 / (s + (1 - s) / 8), 1 / (s + (1 - s) / 16) } }' \
  "$TMP/h1.csv" "$TMP/h2.csv" | tee "$OUT/speedup_haptic.txt"
echo
echo "Haptic scene, the distribution of the step times (scripts/step_times.py):"
python3 scripts/step_times.py "$TMP/times1.csv" "$TMP/times2.csv" | tee "$OUT/step_times_haptic.txt"
