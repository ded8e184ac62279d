"""A parameter grid of indentations, on a Dask cluster: how the probe's force varies with the
organ's parameters.

    python -m tissuesim.sweep --param youngs_modulus=3000:9000:4 [--param NAME=LO:HI:N ...]
        [--scene SCENE.toml] [--depth M] [--fmu TissueSim.fmu]
        [--workers N | --scheduler ADDRESS] [--csv OUT.csv] [--plot OUT.png]

Each grid point is one Dask task: the scene (``tissuesim.indentation``; default: the FMU's
default scene started settled) pressed to ``--depth`` (m of probe travel), by the Python
package or, with ``--fmu``, by the FMU through fmpy (FMPy's parameter-variation pattern: each
worker process extracts the FMU and instantiates it once, then resets the instance between
parameter sets). The CSV has one row per grid point and depth: the parameters, ``depth_m`` and
``force_N``; the plot shows every curve.
"""

from __future__ import annotations

import argparse
import csv
import itertools
import math
import sys
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .indentation import (
    PARAMETERS,
    FloatArray,
    Scene,
    SceneError,
    check_organ,
    load_scene,
    press_at,
)

if TYPE_CHECKING:
    from distributed import Client
    from tqdm import tqdm

Point = dict[str, float]
"""Parameter name -> value (SI units) of one grid point."""


class UsageError(ValueError):
    """A command-line option is invalid (the message names it)."""


def parse_axis(text: str) -> tuple[str, list[float]]:
    """``NAME=LO:HI:N`` (N values evenly spaced, ends included) or ``NAME=V1,V2,...`` as the
    parameter's name and values; ``UsageError`` names the option at fault."""
    where = f"--param {text}"
    name, eq, spec = text.partition("=")
    name = name.strip()
    if not eq:
        raise UsageError(f"{where}: expected NAME=LO:HI:N or NAME=V1,V2,...")
    if name not in PARAMETERS:
        raise UsageError(f"{where}: unknown parameter {name!r} (known: {', '.join(PARAMETERS)})")
    try:
        if ":" in spec:
            lo_text, hi_text, n_text = spec.split(":")
            lo, hi, n = float(lo_text), float(hi_text), int(n_text)
            if n < 1 or (n > 1 and lo >= hi):
                raise UsageError(f"{where}: needs LO < HI and N >= 1 (N = 1 takes LO)")
            values = list(np.linspace(lo, hi, n)) if n > 1 else [lo]
        else:
            values = [float(v) for v in spec.split(",")]
    except ValueError as e:
        if isinstance(e, UsageError):
            raise
        raise UsageError(f"{where}: expected NAME=LO:HI:N or NAME=V1,V2,... (numbers)") from None
    p = PARAMETERS[name]
    for v in values:
        if not (math.isfinite(v) and p.lo <= v <= p.hi):
            raise UsageError(f"{where}: {name} must be in [{p.lo:g}, {p.hi:g}], got {v:g}")
    return name, [float(v) for v in values]


def grid(axes: Sequence[tuple[str, list[float]]]) -> list[Point]:
    """Every combination of the axes' values (the last axis varies fastest)."""
    names = [n for n, _ in axes]
    if len(set(names)) != len(names):
        raise UsageError("each --param may be given once")
    return [dict(zip(names, combo)) for combo in itertools.product(*(v for _, v in axes))]


# --- the FMU backend (runs in the workers) --------------------------------------------------

_SHAPES = {"sphere": 0, "capsule": 1, "cylinder": 2, "box": 3}
"""Scene probe shapes as the FMU's ``tool_shape`` items."""


@lru_cache(maxsize=2)
def _fmu_instance(fmu: str) -> tuple[Any, dict[str, int]]:
    """This process's instance of ``fmu`` (extracted and instantiated once) and its value
    references by name."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(fmu)
    instance = FMU2Slave(
        guid=md.guid,
        unzipDirectory=extract(fmu),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName="sweep",
    )
    instance.instantiate()
    return instance, {v.name: v.valueReference for v in md.modelVariables}


def fmu_press_at(fmu: str, scene: Scene, depths: FloatArray, step: float) -> FloatArray:
    """The scene's indentation by the FMU (communication step ``step``, s), its force (N, the
    mean over each communication step, against the motion) at ``depths`` (m, increasing),
    interpolated linearly. The instance is reset first, so it serves every task of the worker."""
    instance, vr = _fmu_instance(fmu)
    instance.reset()
    u = np.asarray(scene.direction, dtype=float)
    u /= np.linalg.norm(u)
    start = np.asarray(scene.probe_start, dtype=float)
    reals = {
        "youngs_modulus": scene.youngs_modulus,
        "poisson_ratio": scene.poisson_ratio,
        "density": scene.density,
        "friction_static": scene.friction_static,
        "friction_kinetic": min(scene.friction_kinetic, scene.friction_static),
        "tool_radius": scene.probe_radius,
        "tool_half_length": scene.probe_half_length,
        "internal_step": scene.dt,
        "mesh_scale": scene.mesh_scale,
        **{f"fixed_min_{a}": v for a, v in zip("xyz", scene.fixed_min)},
        **{f"fixed_max_{a}": v for a, v in zip("xyz", scene.fixed_max)},
        **{f"gravity_{a}": v for a, v in zip("xyz", scene.gravity)},
        **{f"tool_p{a}": v for a, v in zip("xyz", start)},
        **{f"tool_q{a}": v for a, v in zip("wxyz", scene.probe_orientation)},
    }
    instance.setupExperiment(startTime=0.0)
    instance.setReal([vr[k] for k in reals], list(reals.values()))
    instance.setInteger([vr["tool_shape"]], [_SHAPES[scene.probe_shape]])
    instance.setBoolean([vr["settle"]], [scene.settle])
    if scene.mesh:
        instance.setString([vr["mesh"]], [scene.mesh])
    instance.enterInitializationMode()
    instance.exitInitializationMode()
    n = math.ceil(float(depths[-1]) / (scene.speed * step) - 1e-9)
    force = np.zeros(n + 1)
    position = [vr["tool_px"], vr["tool_py"], vr["tool_pz"]]
    out = [vr["force_x"], vr["force_y"], vr["force_z"]]
    for k in range(1, n + 1):
        instance.setReal(position, list(start + scene.speed * step * k * u))
        instance.doStep(currentCommunicationPoint=(k - 1) * step, communicationStepSize=step)
        force[k] = -float(np.dot(instance.getReal(out), u))
    instance.terminate()
    return np.interp(depths, scene.speed * step * np.arange(n + 1), force)


# --- running, writing, plotting -------------------------------------------------------------


def run(
    client: Client,
    scene: Scene,
    points: Sequence[Point],
    depths: FloatArray,
    fmu: str | None = None,
    step: float = 0.01,
    progress: tqdm | None = None,
) -> list[FloatArray]:
    """The force (N) at ``depths`` (m) of every grid point, one Dask task each (the package,
    or the FMU at ``fmu`` with communication step ``step``, s)."""
    from distributed import as_completed

    scenes = [scene.with_parameters(p) for p in points]
    if fmu:
        futures = client.map(fmu_press_at, [fmu] * len(scenes), scenes, depths=depths, step=step)
    else:
        futures = client.map(press_at, scenes, depths=depths, pure=False)
    for _ in as_completed(futures):
        if progress is not None:
            progress.update(1)
    return [np.asarray(f.result(), dtype=float) for f in futures]


def write_csv(
    path: str | Path, points: Sequence[Point], depths: FloatArray, forces: Sequence[FloatArray]
) -> None:
    """One row per grid point and depth: the parameters, ``depth_m`` (m), ``force_N`` (N)."""
    names = list(points[0])
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow([*names, "depth_m", "force_N"])
        for point, force in zip(points, forces):
            for d, fz in zip(depths, force):
                w.writerow([*(repr(point[n]) for n in names), repr(float(d)), repr(float(fz))])


def plot(
    path: str | Path, points: Sequence[Point], depths: FloatArray, forces: Sequence[FloatArray]
) -> None:
    """A PNG of every grid point's force–indentation curve (mm, N)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=120)
    colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.9, len(points)))
    for point, force, colour in zip(points, forces, colours):
        label = ", ".join(f"{k} {v:.4g}" for k, v in point.items())
        ax.plot(1e3 * depths, force, color=colour, lw=1.5, label=label)
    ax.set_xlabel("indentation depth (mm)")
    ax.set_ylabel("force on the probe (N)")
    ax.grid(alpha=0.3)
    if len(points) <= 12:
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def _parser() -> argparse.ArgumentParser:
    from .cluster import add_cluster_options

    p = argparse.ArgumentParser(
        prog="python -m tissuesim.sweep",
        description="Indentation curves over a parameter grid, on Dask.",
    )
    p.add_argument(
        "--param",
        action="append",
        required=True,
        metavar="NAME=LO:HI:N",
        help=f"a grid axis (or NAME=V1,V2,...; SI units); names: {', '.join(PARAMETERS)}",
    )
    p.add_argument("--scene", metavar="SCENE.toml", help="default: the FMU's default scene")
    p.add_argument(
        "--depth", type=float, default=0.03, help="probe travel from its start (m, default 0.03)"
    )
    p.add_argument(
        "--sample", type=float, default=1e-4, help="depth between CSV rows (m, default 1e-4)"
    )
    p.add_argument("--fmu", metavar="TissueSim.fmu", help="simulate with the FMU (fmpy)")
    p.add_argument(
        "--step", type=float, default=0.01, help="the FMU's communication step (s, default 0.01)"
    )
    add_cluster_options(p)
    p.add_argument("--csv", default="sweep.csv", help="output CSV (default sweep.csv)")
    p.add_argument("--plot", default="sweep.png", help="output PNG (default sweep.png)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit code (2 for bad input, without a traceback)."""
    from tqdm import tqdm

    from .cluster import open_client

    args = _parser().parse_args(argv)
    try:
        points = grid([parse_axis(t) for t in args.param])
        for name, value in (("--depth", args.depth), ("--sample", args.sample)):
            if not (math.isfinite(value) and value > 0.0):
                raise UsageError(f"{name} must be > 0, got {value}")
        if args.fmu and not (math.isfinite(args.step) and args.step > 0.0):
            raise UsageError(f"--step must be > 0, got {args.step}")
        if args.fmu and not Path(args.fmu).is_file():
            raise UsageError(f"--fmu {args.fmu}: no such file")
        scene = load_scene(args.scene) if args.scene else Scene()
        check_organ(scene, args.scene or "default scene")
        for p in points:
            scene.with_parameters(p)
    except (UsageError, SceneError, OSError) as e:
        print(f"sweep: error: {e}", file=sys.stderr)
        return 2
    n = max(1, round(args.depth / args.sample))
    depths = np.linspace(0.0, args.depth, n + 1)
    fmu = str(Path(args.fmu).resolve()) if args.fmu else None
    with open_client(args.workers, args.scheduler) as client:
        with tqdm(total=len(points), unit="sim", desc="sweep", disable=args.no_progress) as bar:
            forces = run(client, scene, points, depths, fmu, args.step, bar)
    write_csv(args.csv, points, depths, forces)
    plot(args.plot, points, depths, forces)
    for point, force in zip(points, forces):
        values = ", ".join(f"{k} = {v:.6g}" for k, v in point.items())
        print(f"{values}: force {force[-1]:.4g} N at {1e3 * depths[-1]:.4g} mm")
    print(f"{len(points)} simulations; {args.csv}, {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
