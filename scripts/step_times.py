#!/usr/bin/env python3
"""Summarise the per-step times that `cargo bench --bench step -- --times PATH` writes.

For each scene, thread count, mesh and probe setting: the fastest step, the median, p90 and
p99 (ms), the share of steps slower than 1.2 times the median, and the longest run of such
consecutive steps. A long run means a slow phase of the machine (or of the scene), not
isolated interruptions.

    python3 scripts/step_times.py times.csv [more.csv ...]
"""

import csv
import math
import sys


def percentile(sorted_ms, q):
    """The same nearest-rank percentile as benches/step.rs (halves rounded up, as Rust's
    `round` does for positive numbers; Python's `round` would take the even neighbour)."""
    return sorted_ms[math.floor((len(sorted_ms) - 1) * q + 0.5)]


def summarise(ms):
    s = sorted(ms)
    median = percentile(s, 0.5)
    slow = [t > 1.2 * median for t in ms]
    longest = run = 0
    for is_slow in slow:
        run = run + 1 if is_slow else 0
        longest = max(longest, run)
    return (s[0], median, percentile(s, 0.9), percentile(s, 0.99),
            sum(slow) / len(ms), longest)


def main(paths):
    series = {}
    for path in paths:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                key = (row["scene"], row["threads"], row["mesh"], row["probe"])
                series.setdefault(key, []).append(float(row["ms"]))
    print(f"{'scene':<7} {'thr':>3} {'mesh':<10} {'probe':<5} {'steps':>6} {'min':>7} "
          f"{'median':>7} {'p90':>7} {'p99':>7} {'>1.2x':>6} {'run':>5}")
    for (scene, threads, mesh, probe), ms in series.items():
        lo, med, p90, p99, share, run = summarise(ms)
        print(f"{scene:<7} {threads:>3} {mesh:<10} {probe:<5} {len(ms):>6} {lo:>7.3f} "
              f"{med:>7.3f} {p90:>7.3f} {p99:>7.3f} {share:>6.1%} {run:>5}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
