"""The Python loop's overhead over the Rust step on the haptic scene (DESIGN §7).

    python python/bench/overhead.py [--blocks 10] [--steps 500] [--threads 1] [--mesh PATH]

The scene of ``benches/step.rs --scene haptic``: liver_4k (data/meshes) scaled by 0.03
(~0.2 m) and centred, E 5 kPa, ν 0.45, ρ 1060 kg/m³, dt 1 ms, the top 10 % of its height
fixed, a sphere probe (radius 5 % of the organ's size) pressed 15 % of the size into its +z
side over 0.5 s, then 0.5 s to settle. Then, alternating in blocks on the same world, the same
haptic loop — set the probe's pose (a small wobble about the pressed pose), step, read the
wrench — run from Python (``world.set_tool_pose`` + ``world.step`` + ``world.tool(p).wrench()
.force``) and in Rust (``tissuesim._tissuesim._bench_rust_loop``, the same three calls on the
same world with the GIL released). Each step of both loops is timed the same way, from
before the pose is set to after the force is read. Prints the median, p99 and mean (ms) of
each and the ratio Python / Rust.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import tissuesim as ts
from tissuesim._tissuesim import _bench_rust_loop

ROOT = Path(__file__).resolve().parents[2]


def haptic_scene(mesh_path: Path, threads: int):
    """The world, the probe and its pressed position (m)."""
    organ, _ = ts.mesh.load(mesh_path, 0.03)
    lo, hi = organ.bounding_box()
    organ = organ.translated(-(lo + hi) / 2)
    lo, hi = organ.bounding_box()
    world = ts.World(ts.Settings(threads=threads))
    material = ts.Material(youngs_modulus=5e3, poisson_ratio=0.45, density=1060.0)
    body = world.add_body(organ, ts.BodyOptions(material=material))
    top = hi[1] - 0.1 * (hi[1] - lo[1])
    far = 10 * float((hi - lo).max())
    world.fix_box(body, [-far, top, -far], [far, far, far])
    size = float((hi - lo).max())
    radius, press = 0.05 * size, 0.15 * size
    y_mid = 0.5 * (lo[1] + top)
    nodes = organ.nodes
    near = np.hypot(nodes[:, 0], nodes[:, 1] - y_mid) < radius
    surface_z = max(float(lo[2]), float(nodes[near, 2].max()))
    start = np.array([0.0, y_mid, surface_z + radius + 0.05 * size])
    pressed = start - [0.0, 0.0, 0.05 * size + press]
    probe = world.add_tool(ts.ToolShape.Sphere(radius), ts.Pose.at(start))
    for k in range(1, 1001):
        s = min(1.0, k / 500)
        world.set_tool_pose(probe, start + s * (pressed - start))
        world.step()
    return world, probe, pressed, size


def percentile(sorted_values: list[float], q: float) -> float:
    """The benches' percentile: rank (n - 1) q rounded half up."""
    k = int(math.floor((len(sorted_values) - 1) * q + 0.5))
    return sorted_values[k]


def summary(times: list[float]) -> dict[str, float]:
    s = sorted(times)
    return {
        "median_ms": 1e3 * percentile(s, 0.5),
        "p99_ms": 1e3 * percentile(s, 0.99),
        "mean_ms": 1e3 * statistics.fmean(s),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--blocks", type=int, default=10, help="blocks of each loop (10)")
    parser.add_argument("--steps", type=int, default=500, help="steps per block (500)")
    parser.add_argument("--threads", type=int, default=1, help="Settings.threads (1)")
    parser.add_argument("--mesh", type=Path, default=ROOT / "data/meshes/liver_4k.node")
    parser.add_argument("--json", type=Path, help="write the figures as JSON")
    args = parser.parse_args(argv)

    world, probe, pressed, size = haptic_scene(args.mesh, args.threads)
    k = 0
    python_times: list[float] = []
    python_calls: list[float] = []
    rust_times: list[float] = []
    clock = time.perf_counter
    for block in range(2 * args.blocks):
        path = np.array(
            [
                pressed + [0.0, 0.0, 0.01 * size * math.sin((k + i) * 0.01)]
                for i in range(args.steps)
            ]
        )
        k += args.steps
        if block % 2 == 0:
            for p in path:
                t0 = clock()
                world.set_tool_pose(probe, p)
                t1 = clock()
                world.step()
                t2 = clock()
                force = world.tool(probe).wrench().force
                t3 = clock()
                python_times.append(t3 - t0)
                python_calls.append((t1 - t0) + (t3 - t2))
            assert force[2] > 0.0, "the probe must be pressed in"
        else:
            rust_times.extend(_bench_rust_loop(world, probe, path).tolist())

    py, rs = summary(python_times), summary(rust_times)
    ratio = {key: py[key] / rs[key] for key in py}
    print(
        f"haptic scene, {args.mesh.name}, threads {args.threads}, "
        f"{args.blocks} x {args.steps} steps per loop, alternating"
    )
    print(f"{'loop':<8} {'median ms':>10} {'p99 ms':>10} {'mean ms':>10}")
    for name, s in (("Rust", rs), ("Python", py)):
        print(f"{name:<8} {s['median_ms']:>10.4f} {s['p99_ms']:>10.4f} {s['mean_ms']:>10.4f}")
    print(
        f"{'ratio':<8} {ratio['median_ms']:>10.4f} {ratio['p99_ms']:>10.4f} "
        f"{ratio['mean_ms']:>10.4f}   (Python / Rust; overhead "
        f"{100 * (ratio['median_ms'] - 1):+.1f}% at the median, "
        f"{1e6 * (py['median_ms'] - rs['median_ms']) / 1e3:+.1f} us)"
    )
    calls_us = 1e6 * statistics.median(python_calls)
    print(
        f"set_tool_pose + tool(p).wrench().force from Python: {calls_us:.2f} us a step "
        f"(median), {100 * calls_us / (1e3 * rs['median_ms']):.2f}% of the Rust step's median"
    )
    if args.json:
        figures = {"python": py, "rust": rs, "ratio": ratio, "python_calls_us": calls_us}
        args.json.write_text(json.dumps(figures, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
