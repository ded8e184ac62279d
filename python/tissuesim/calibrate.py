"""Fit the organ's parameters to a measured force–indentation curve, on a Dask cluster.

    python -m tissuesim.calibrate CURVE.csv --param youngs_modulus=LO:HI
        [--param poisson_ratio=LO:HI ...] [--scene SCENE.toml]
        [--workers N | --scheduler ADDRESS] [--plot PNG]

CURVE.csv has the columns ``depth_m`` (the probe's displacement from its start along its
motion, m) and ``force_N`` (the tissue's force on the probe against that motion, N). The scene
(``tissuesim.indentation``; default: the FMU's default scene started settled) is simulated for
a batch of candidate parameters per round, in parallel on Dask; the last lines printed are one
per fitted parameter, ``youngs_modulus = VALUE Pa``.

The optimiser (docs/CALIBRATION.md):

- Young's modulus alone: at each candidate E the least-squares scale s = <F, S>/<S, S> of the
  simulated curve S onto the measured one F says how much stiffer the tissue is (force grows
  with E: ~linearly at fixed geometry, faster where a stiffer organ sags less towards the
  probe). The fit is the root of log s(E) in log E, bracketed: each round simulates a batch of
  log-spaced candidates, interpolates the root between the two that bracket it, and narrows the
  bracket around it to half a candidate spacing.
- Several parameters: successive refinement of a box over the parameters other than E: each
  round simulates a grid (a batch along one parameter, 3 points per parameter for more), fits a
  quadratic to the sum of squared force errors, moves the box's centre to its minimum (or the
  best candidate) and halves the box. E is profiled out meanwhile: each candidate's curve is
  compared after its least-squares scaling, and the candidates' E follows the best one's scale.
  One bracket round on E (±20 %) at the other parameters found ends the search.
- A last simulation at the fitted parameters gives the fitted curve of the plot.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .indentation import (
    PARAMETERS,
    Curve,
    CurveError,
    FloatArray,
    Scene,
    SceneError,
    check_organ,
    load_scene,
    press_at,
    read_curve,
)

if TYPE_CHECKING:
    from distributed import Client
    from tqdm import tqdm

Candidate = dict[str, float]
"""Parameter name -> value (SI units) of one simulation."""
Evaluate = Callable[[Sequence[Candidate]], list[FloatArray]]
"""Simulates candidates (in parallel) and returns each one's force (N) at the measured depths
(NaN where the simulation failed)."""


class UsageError(ValueError):
    """A command-line option is invalid (the message names it)."""


@dataclass(frozen=True)
class Range:
    """The search range of one parameter (SI units, LO < HI)."""

    name: str
    lo: float
    hi: float

    def to_search(self, v: float) -> float:
        """The value on the search scale (log for a modulus)."""
        return math.log(v) if PARAMETERS[self.name].log else v

    def from_search(self, x: float) -> float:
        """The value from the search scale."""
        return math.exp(x) if PARAMETERS[self.name].log else float(x)


def parse_range(text: str) -> Range:
    """``NAME=LO:HI`` as a ``Range``; ``UsageError`` names the option at fault."""
    where = f"--param {text}"
    name, eq, bounds = text.partition("=")
    name = name.strip()
    if not eq or bounds.count(":") != 1:
        raise UsageError(f"{where}: expected NAME=LO:HI, e.g. youngs_modulus=1000:20000")
    if name not in PARAMETERS:
        raise UsageError(f"{where}: unknown parameter {name!r} (known: {', '.join(PARAMETERS)})")
    p = PARAMETERS[name]
    try:
        lo, hi = (float(b) for b in bounds.split(":"))
    except ValueError:
        raise UsageError(f"{where}: LO and HI must be numbers") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise UsageError(f"{where}: LO and HI must be finite")
    if lo >= hi:
        raise UsageError(f"{where}: LO ({lo:g}) must be less than HI ({hi:g})")
    if lo < p.lo or hi > p.hi:
        raise UsageError(f"{where}: {name} must stay within [{p.lo:g}, {p.hi:g}]")
    if p.log and lo <= 0.0:
        raise UsageError(f"{where}: LO must be > 0")
    return Range(name, lo, hi)


@dataclass
class Fit:
    """The result of a calibration."""

    values: Candidate
    """Fitted parameters (SI units)."""
    force: FloatArray
    """The fitted scene's force (N) at the measured depths."""
    rms: float
    """Root-mean-square force error of the fitted curve (N)."""
    at_bound: list[str] = field(default_factory=list)
    """Parameters whose fit lies on a bound of their range."""
    simulations: int = 0
    """Simulations run."""


def _squared_error(measured: FloatArray, force: FloatArray) -> float:
    """Sum of squared force errors (N²); infinity for a failed simulation."""
    err = float(np.sum((measured - force) ** 2))
    return err if math.isfinite(err) else math.inf


def _log_scale(measured: FloatArray, force: FloatArray) -> float:
    """log of the least-squares scale of ``force`` onto ``measured``: > 0 if the tissue
    measured is stiffer. +inf if the simulated probe felt nothing, NaN if it failed."""
    ss = float(force @ force)
    if not math.isfinite(ss):
        return math.nan
    if ss == 0.0:
        return math.inf
    s = float(measured @ force) / ss
    return math.log(s) if s > 0.0 else math.nan


def _bracket_root(xs: FloatArray, hs: FloatArray, lo: float, hi: float) -> float:
    """Where h (decreasing in x, sampled as ``hs`` at increasing ``xs``) crosses 0, within
    [lo, hi]: interpolated between the two samples that bracket it, else extrapolated from the
    nearest sample with slope −1 (h = log s, x = log E, force ∝ E)."""
    ok = ~np.isnan(hs)
    xs, hs = xs[ok], hs[ok]
    if len(xs) == 0:
        raise RuntimeError("every simulation of the round failed (see the workers' log)")
    for i in range(len(xs) - 1):
        if hs[i] > 0.0 >= hs[i + 1]:
            if math.isinf(hs[i]):
                return float(np.clip(xs[i + 1] + hs[i + 1], xs[i], xs[i + 1]))
            return float(xs[i] + hs[i] * (xs[i + 1] - xs[i]) / (hs[i] - hs[i + 1]))
    if hs[-1] > 0.0:  # stiffer than every candidate
        return float(np.clip(xs[-1] + min(hs[-1], hi - xs[-1]), lo, hi))
    return float(np.clip(xs[0] + hs[0], lo, hi))  # softer than every candidate


def _narrow(centre: float, half: float, lo: float, hi: float) -> tuple[float, float]:
    """[centre − half, centre + half], shifted to lie within [lo, hi] (and cut to it)."""
    a = max(lo, centre - half)
    b = min(hi, a + 2 * half)
    return max(lo, b - 2 * half), b


def fit_modulus(
    measured: FloatArray,
    evaluate: Evaluate,
    bracket: Range,
    others: Candidate,
    batch: int,
    rounds: int,
    start: tuple[float, float] | None = None,
) -> float:
    """Young's modulus (Pa) whose simulated curve scales onto ``measured`` with factor 1, by
    ``rounds`` rounds of ``batch`` log-spaced candidates in a narrowing bracket (start:
    ``start`` in log Pa, else the whole range); ``others`` are the other parameters."""
    lo, hi = math.log(bracket.lo), math.log(bracket.hi)
    a, b = start if start is not None else (lo, hi)
    root = 0.5 * (a + b)
    for _ in range(rounds):
        xs = np.linspace(a, b, batch)
        forces = evaluate([{**others, bracket.name: math.exp(x)} for x in xs])
        hs = np.array([_log_scale(measured, f) for f in forces])
        root = _bracket_root(xs, hs, lo, hi)
        a, b = _narrow(root, 0.5 * (b - a) / (batch - 1), lo, hi)
    return math.exp(root)


def _quadratic_minimum(z: FloatArray, r: FloatArray) -> FloatArray | None:
    """The minimum of the quadratic least-squares fit of ``r`` (k,) over points ``z`` (k, d)
    in [−1, 1]^d, clipped to that cube; None if there are too few points or it is not convex."""
    k, d = z.shape
    pairs = [(i, j) for i in range(d) for j in range(i, d)]
    if k < 1 + d + len(pairs):
        return None
    design = np.column_stack([np.ones(k), z] + [z[:, i] * z[:, j] for i, j in pairs])
    coef = np.linalg.lstsq(design, r, rcond=None)[0]
    g = coef[1 : 1 + d]
    hess = np.zeros((d, d))
    for c, (i, j) in zip(coef[1 + d :], pairs):
        hess[i, j] += c if i != j else 2 * c
        hess[j, i] = hess[i, j]
    if np.any(np.linalg.eigvalsh(hess) <= 0.0):
        return None
    return np.clip(np.linalg.solve(hess, -g), -1.0, 1.0)


def fit_box(
    measured: FloatArray,
    evaluate: Evaluate,
    ranges: Sequence[Range],
    points: int,
    rounds: int,
    modulus: Range | None,
) -> Candidate:
    """Parameters other than E (``ranges``) by successive refinement of a box: per round a
    grid of ``points`` values per parameter, the box moved to the minimum of a quadratic fit of
    the squared force error (or to the best grid point) and halved. With ``modulus``, E is
    profiled out: each candidate's error is that of its curve scaled by its least-squares
    factor, and E follows the best candidate's factor (damped: force grows faster than E). The
    E found is only a start for ``fit_modulus``."""
    lo = np.array([r.to_search(r.lo) for r in ranges])
    hi = np.array([r.to_search(r.hi) for r in ranges])
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    unit = np.linspace(-1.0, 1.0, points)
    e = math.sqrt(modulus.lo * modulus.hi) if modulus else math.nan
    for _ in range(rounds):
        z = np.array(list(itertools.product(unit, repeat=len(ranges))))
        xs = centre + z * half
        candidates = [{r.name: r.from_search(x) for r, x in zip(ranges, row)} for row in xs]
        if modulus:
            candidates = [{modulus.name: e, **c} for c in candidates]
        forces = evaluate(candidates)
        scales = np.array([math.exp(_log_scale(measured, f)) if modulus else 1.0 for f in forces])
        errors = np.array([_squared_error(measured, s * f) for s, f in zip(scales, forces)])
        ok = np.isfinite(errors)
        if not ok.any():
            raise RuntimeError("every simulation of the round failed (see the workers' log)")
        best = int(np.argmin(np.where(ok, errors, np.inf)))
        if modulus:
            e = float(np.clip(e * scales[best] ** 0.6, modulus.lo, modulus.hi))
        step = _quadratic_minimum(z[ok], errors[ok])
        centre = centre + half * (step if step is not None else z[best])
        half = 0.5 * half
        centre = np.clip(centre, lo + half, hi - half)
    values = {r.name: r.from_search(x) for r, x in zip(ranges, centre)}
    return {modulus.name: e, **values} if modulus else values


def check_search(ranges: Sequence[Range], batch: int, rounds: int | None) -> None:
    """``UsageError`` naming the option if the search is not well defined."""
    names = [r.name for r in ranges]
    if not names:
        raise UsageError("give at least one --param NAME=LO:HI")
    for name in set(names):
        if names.count(name) > 1:
            raise UsageError(f"--param {name} is given {names.count(name)} times")
    if batch < 2:
        raise UsageError(f"--batch must be at least 2, got {batch}")
    if rounds is not None and rounds < 1:
        raise UsageError(f"--rounds must be at least 1, got {rounds}")


def calibrate(
    curve: Curve,
    ranges: Sequence[Range],
    evaluate: Evaluate,
    batch: int = 4,
    rounds: int | None = None,
) -> Fit:
    """Fit the parameters of ``ranges`` to ``curve``; ``evaluate`` runs the simulations. A
    batch of ``batch`` candidates (E alone) or a grid of 3 per parameter per round;
    ``rounds`` rounds (default 3 for E alone, 4 for several parameters)."""
    check_search(ranges, batch, rounds)
    measured = curve.force
    modulus = next((r for r in ranges if r.name == "youngs_modulus"), None)
    if len(ranges) == 1 and modulus is not None:
        n = rounds or 3
        values = {modulus.name: fit_modulus(measured, evaluate, modulus, {}, batch, n)}
    else:
        others = [r for r in ranges if r is not modulus]
        points = 3 if len(others) > 1 else batch
        values = fit_box(measured, evaluate, others, points, rounds or 4, modulus)
        if modulus is not None:  # one bracket round on E, ±20 %, at the others found
            x = math.log(values.pop(modulus.name))
            bounds = math.log(modulus.lo), math.log(modulus.hi)
            start = _narrow(x, math.log(1.2), *bounds)
            e = fit_modulus(measured, evaluate, modulus, values, batch, 1, start)
            values = {modulus.name: e, **values}
    force = evaluate([values])[0]
    at_bound = [
        r.name
        for r in ranges
        if math.isclose(values[r.name], r.lo, rel_tol=1e-6)
        or math.isclose(values[r.name], r.hi, rel_tol=1e-6)
    ]
    rms = float(np.sqrt(np.mean((measured - force) ** 2)))
    return Fit(values, force, rms, at_bound)


def planned_simulations(ranges: Sequence[Range], batch: int, rounds: int | None) -> int:
    """How many simulations ``calibrate`` runs (for the progress bar)."""
    if len(ranges) == 1 and ranges[0].name == "youngs_modulus":
        return (rounds or 3) * batch + 1
    others = [r for r in ranges if r.name != "youngs_modulus"]
    points = 3 if len(others) > 1 else batch
    extra = batch if len(others) < len(ranges) else 0
    return (rounds or 4) * points ** len(others) + extra + 1


class DaskEvaluator:
    """Runs candidates of ``scene`` on a Dask client, one task each (``press_at``), and
    counts them on a progress bar."""

    def __init__(
        self, client: Client, scene: Scene, depths: FloatArray, progress: tqdm | None = None
    ) -> None:
        self.client = client
        self.scene = scene
        self.depths = depths
        self.progress = progress
        self.simulations = 0

    def __call__(self, candidates: Sequence[Candidate]) -> list[FloatArray]:
        from distributed import as_completed

        scenes = [self.scene.with_parameters(c) for c in candidates]
        futures = self.client.map(press_at, scenes, depths=self.depths, pure=False)
        for _ in as_completed(futures):
            if self.progress is not None:
                self.progress.update(1)
        self.simulations += len(futures)
        return [np.asarray(f.result(), dtype=float) for f in futures]


def plot_fit(path: str | Path, curve: Curve, fit: Fit, title: str) -> None:
    """A PNG of the measured curve and the fitted one (mm, N)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=120)
    ax.plot(1e3 * curve.depth, curve.force, ".", ms=3, color="0.35", label="measured")
    ax.plot(1e3 * curve.depth, fit.force, "-", lw=2, color="tab:red", label="fitted")
    ax.set_xlabel("indentation depth (mm)")
    ax.set_ylabel("force on the probe (N)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def format_value(name: str, value: float) -> str:
    """``name = VALUE unit`` (6 significant digits)."""
    unit = PARAMETERS[name].unit
    return f"{name} = {value:.6g}" + (f" {unit}" if unit else "")


def _parser() -> argparse.ArgumentParser:
    from .cluster import add_cluster_options

    p = argparse.ArgumentParser(
        prog="python -m tissuesim.calibrate",
        description="Fit the organ's parameters to a force-indentation curve, on Dask.",
    )
    p.add_argument("curve", metavar="CURVE.csv", help="columns depth_m (m), force_N (N)")
    p.add_argument(
        "--param",
        action="append",
        required=True,
        metavar="NAME=LO:HI",
        help=f"a parameter to fit and its range (SI units); names: {', '.join(PARAMETERS)}",
    )
    p.add_argument("--scene", metavar="SCENE.toml", help="default: the FMU's default scene")
    add_cluster_options(p)
    p.add_argument("--batch", type=int, default=4, help="candidates of E per round (default 4)")
    p.add_argument("--rounds", type=int, default=None, help="default 3 (E alone), 4 (several)")
    p.add_argument("--plot", metavar="PNG", help="default: CURVE_fit.png in the current directory")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit code (2 for bad input, without a traceback)."""
    from tqdm import tqdm

    from .cluster import open_client

    args = _parser().parse_args(argv)
    try:
        ranges = [parse_range(t) for t in args.param]
        check_search(ranges, args.batch, args.rounds)
        curve = read_curve(args.curve)
        scene = load_scene(args.scene) if args.scene else Scene()
        check_organ(scene, args.scene or "default scene")
        for r in ranges:  # the extremes of the ranges must be valid scenes
            scene.with_parameters({r.name: r.lo})
        plot = Path(args.plot or f"{Path(args.curve).stem}_fit.png")
    except (UsageError, CurveError, SceneError, OSError) as e:
        print(f"calibrate: error: {e}", file=sys.stderr)
        return 2
    total = planned_simulations(ranges, args.batch, args.rounds)
    with open_client(args.workers, args.scheduler) as client:
        with tqdm(total=total, unit="sim", desc="calibrate", disable=args.no_progress) as bar:
            evaluate = DaskEvaluator(client, scene, curve.depth, bar)
            try:
                fit = calibrate(curve, ranges, evaluate, args.batch, args.rounds)
            except RuntimeError as e:  # every candidate of a round failed
                print(f"calibrate: error: {e}", file=sys.stderr)
                return 1
        fit.simulations = evaluate.simulations
    title = ", ".join(format_value(k, v) for k, v in fit.values.items())
    plot_fit(plot, curve, fit, title)
    peak = float(np.max(np.abs(curve.force)))
    print(
        f"{fit.simulations} simulations; rms force error {fit.rms:.4g} N "
        f"({100 * fit.rms / peak:.2f} % of the peak force); plot: {plot}"
    )
    for name in fit.at_bound:
        print(f"warning: {name} is at a bound of its range: widen it", file=sys.stderr)
    for name, value in fit.values.items():
        print(format_value(name, value))
    return 0


if __name__ == "__main__":
    sys.exit(main())
