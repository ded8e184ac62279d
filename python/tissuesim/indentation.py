"""An indentation experiment: a probe pushed at constant speed into an organ that starts at
rest, and the force–indentation curve it records.

The default ``Scene`` is the FMU's default scene (docs/FMU.md) started settled: the default
organ hanging from the fixed box [-0.2, 0.043, -0.2]–[0.2, 0.2, 0.2] m, a 1 cm sphere probe
(friction 0.2 static, 0.1 kinetic) starting at (0.035, 0, 0.095) m and moving along −z at
1 cm/s, dt 1 ms, gravity −9.81 m/s² along y. A TOML file (``load_scene``) names another mesh,
scale, fixed box, probe, motion, material or world settings.

A curve is ``depth_m`` (the probe's displacement from its start along its motion, m) against
``force_N`` (the tissue's force on the probe against that motion, N): ``read_curve`` and
``write_curve`` handle its CSV form, and ``press`` simulates it.

``press`` runs in Dask workers: each process keeps the meshes, body models and settled states
it built (keyed by the scene), so a worker builds the model once and settles once per
material, whatever the number of candidates it is given.
"""

from __future__ import annotations

import csv
import math
import sys
from collections import OrderedDict
from dataclasses import dataclass, fields, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from . import mesh as _mesh
from ._tissuesim import (
    MAX_POISSON_RATIO,
    YOUNGS_MODULUS_RANGE,
    BodyModel,
    BodyOptions,
    DivergedError,
    Material,
    Pose,
    Settings,
    TetMesh,
    ToolOptions,
    ToolShape,
    World,
)

FloatArray = npt.NDArray[np.float64]
Vec3 = tuple[float, float, float]

PROBE_SHAPES = ("sphere", "capsule", "cylinder", "box")
"""Probe shapes a scene may name (the FMU's ``tool_shape`` items)."""

LEAD_IN = 0.002
"""Travel (m) simulated before the probe's first possible contact; the approach before it is
skipped (the organ is at rest and untouched there)."""


@dataclass(frozen=True)
class Parameter:
    """A scene quantity that calibration and sweeps may vary."""

    name: str
    unit: str
    """Unit as printed after the value ("" for dimensionless)."""
    lo: float
    """Smallest accepted value."""
    hi: float
    """Largest accepted value."""
    log: bool
    """Searched on a logarithmic scale (a modulus) rather than a linear one."""


PARAMETERS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter("youngs_modulus", "Pa", YOUNGS_MODULUS_RANGE[0], YOUNGS_MODULUS_RANGE[1], True),
        Parameter("poisson_ratio", "", 0.0, MAX_POISSON_RATIO, False),
        Parameter("density", "kg/m³", 1e-6, 1e5, True),
        Parameter("friction_static", "", 0.0, 10.0, False),
        Parameter("friction_kinetic", "", 0.0, 10.0, False),
    )
}
"""The parameters by name: the organ's material and the probe's friction."""


@dataclass(frozen=True)
class Scene:
    """An indentation scene (SI units). Hashable: workers key their caches by it."""

    mesh: str = ""
    """Organ mesh file (.msh, .node/.ele, .vtk), an absolute path; "" = the default organ."""
    mesh_scale: float = 1.0
    """Factor from mesh units to m."""
    fixed_min: Vec3 = (-0.2, 0.043, -0.2)
    """Lower corner of the box whose nodes are fixed (m)."""
    fixed_max: Vec3 = (0.2, 0.2, 0.2)
    """Upper corner of the fixed box (m)."""
    probe_shape: str = "sphere"
    """One of ``PROBE_SHAPES``; capsules and cylinders lie along the probe's local y."""
    probe_radius: float = 0.01
    """Radius of a sphere, capsule or cylinder, half width of a box (m)."""
    probe_half_length: float = 0.03
    """Half length of a capsule, cylinder or box along the probe's local y (m)."""
    probe_start: Vec3 = (0.035, 0.0, 0.095)
    """The probe's start position (m)."""
    probe_orientation: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    """The probe's orientation quaternion (w, x, y, z), local to world."""
    direction: Vec3 = (0.0, 0.0, -1.0)
    """Direction of the probe's motion (normalised on use)."""
    speed: float = 0.01
    """Speed of the probe (m/s)."""
    friction_static: float = 0.2
    """Static friction coefficient between probe and tissue."""
    friction_kinetic: float = 0.1
    """Kinetic friction coefficient (used as min(kinetic, static))."""
    youngs_modulus: float = 5000.0
    """Young's modulus E of the organ (Pa)."""
    poisson_ratio: float = 0.45
    """Poisson ratio ν of the organ."""
    density: float = 1060.0
    """Mass density of the organ (kg/m³)."""
    gravity: Vec3 = (0.0, -9.81, 0.0)
    """Gravity acceleration (m/s²)."""
    dt: float = 0.001
    """Time step (s)."""
    settle: bool = True
    """Start the organ at rest in its static equilibrium (``World.settle``)."""

    def with_parameters(self, values: dict[str, float]) -> Scene:
        """This scene with the ``PARAMETERS`` in ``values`` replaced."""
        unknown = set(values) - set(PARAMETERS)
        if unknown:
            raise ValueError(f"unknown parameter(s): {', '.join(sorted(unknown))}")
        return replace(self, **{k: float(v) for k, v in values.items()})

    def step_length(self) -> float:
        """Probe travel per step (m)."""
        return self.speed * self.dt


class SceneError(ValueError):
    """A scene file or scene value is invalid (the message names the file and key)."""


class CurveError(ValueError):
    """A curve file is invalid (the message names the file and line)."""


# --- scene files ----------------------------------------------------------------------------

_SCENE_KEYS: dict[str, dict[str, str]] = {
    "mesh": {"path": "mesh", "scale": "mesh_scale"},
    "fixed": {"min": "fixed_min", "max": "fixed_max"},
    "probe": {
        "shape": "probe_shape",
        "radius": "probe_radius",
        "half_length": "probe_half_length",
        "start": "probe_start",
        "orientation": "probe_orientation",
        "direction": "direction",
        "speed": "speed",
        "friction_static": "friction_static",
        "friction_kinetic": "friction_kinetic",
    },
    "material": {
        "youngs_modulus": "youngs_modulus",
        "poisson_ratio": "poisson_ratio",
        "density": "density",
    },
    "world": {"gravity": "gravity", "dt": "dt", "settle": "settle"},
}
"""TOML section -> key -> ``Scene`` field."""


def _toml_loads(text: str) -> dict[str, Any]:
    if sys.version_info >= (3, 11):
        import tomllib

        return tomllib.loads(text)
    import tomli  # Python 3.9 and 3.10

    return tomli.loads(text)


def load_scene(path: str | Path) -> Scene:
    """Read a scene TOML file: sections ``[mesh]`` (path relative to the file, scale),
    ``[fixed]`` (min, max), ``[probe]`` (shape, radius, half_length, start, orientation,
    direction, speed, friction_static, friction_kinetic), ``[material]`` (youngs_modulus,
    poisson_ratio, density) and ``[world]`` (gravity, dt, settle). What is not named keeps the
    default scene's value. ``SceneError`` names the file and the key at fault."""
    path = Path(path)
    try:
        data = _toml_loads(path.read_text(encoding="utf-8"))
    except OSError as e:
        raise SceneError(f"{path}: cannot read: {e.strerror or e}") from None
    except ValueError as e:  # tomllib.TOMLDecodeError
        raise SceneError(f"{path}: not valid TOML: {e}") from None
    values: dict[str, Any] = {}
    types = {f.name: f.type for f in fields(Scene)}
    for section, table in data.items():
        keys = _SCENE_KEYS.get(section)
        if keys is None or not isinstance(table, dict):
            known = ", ".join(f"[{s}]" for s in _SCENE_KEYS)
            raise SceneError(f"{path}: unknown section [{section}] (known: {known})")
        for key, value in table.items():
            name = keys.get(key)
            if name is None:
                raise SceneError(
                    f"{path}: unknown key {key} in [{section}] (known: {', '.join(keys)})"
                )
            values[name] = _convert(path, f"[{section}] {key}", value, str(types[name]))
    if values.get("mesh"):
        values["mesh"] = str((path.parent / values["mesh"]).resolve())
    scene = Scene(**values)
    check_scene(scene, str(path))
    return scene


def _convert(path: Path, where: str, value: Any, type_name: str) -> Any:
    """A TOML value as the ``Scene`` field type named ``type_name``."""

    def fail(expected: str) -> SceneError:
        return SceneError(f"{path}: {where} must be {expected}, got {value!r}")

    if type_name == "str":
        if not isinstance(value, str):
            raise fail("a string")
        return value
    if type_name == "bool":
        if not isinstance(value, bool):
            raise fail("true or false")
        return value
    if type_name == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise fail("a number")
        return float(value)
    n = 4 if "float, float, float, float" in type_name else 3
    if (
        not isinstance(value, list)
        or len(value) != n
        or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)
    ):
        raise fail(f"an array of {n} numbers")
    return tuple(float(v) for v in value)


def check_scene(scene: Scene, origin: str = "scene") -> None:
    """Check the values of ``scene`` (``SceneError`` naming ``origin`` and the field)."""

    def fail(message: str) -> SceneError:
        return SceneError(f"{origin}: {message}")

    for f in fields(Scene):
        v = getattr(scene, f.name)
        items = v if isinstance(v, tuple) else (v,)
        if any(isinstance(x, float) and not math.isfinite(x) for x in items):
            raise fail(f"{f.name} must be finite, got {v}")
    if scene.probe_shape not in PROBE_SHAPES:
        raise fail(
            f"probe shape must be one of {', '.join(PROBE_SHAPES)}, got {scene.probe_shape!r}"
        )
    for name in ("mesh_scale", "probe_radius", "speed", "dt"):
        if getattr(scene, name) <= 0.0:
            raise fail(f"{name} must be > 0, got {getattr(scene, name)}")
    if scene.probe_half_length < 0.0:
        raise fail(f"probe_half_length must be >= 0, got {scene.probe_half_length}")
    if np.linalg.norm(scene.direction) == 0.0:
        raise fail("direction must not be zero")
    if np.linalg.norm(scene.probe_orientation) == 0.0:
        raise fail("probe orientation must not be a zero quaternion")
    for p in PARAMETERS.values():
        v = getattr(scene, p.name)
        if not p.lo <= v <= p.hi:
            raise fail(f"{p.name} must be in [{p.lo:g}, {p.hi:g}], got {v:g}")


# --- curves ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Curve:
    """A force–indentation curve: ``depth`` (k,) m, increasing, and ``force`` (k,) N."""

    depth: FloatArray
    force: FloatArray


def read_curve(path: str | Path) -> Curve:
    """Read a CSV with the columns ``depth_m`` and ``force_N`` (others ignored). ``CurveError``
    names the file and line of a missing column, a value that is not a finite number, a
    negative depth or a depth that does not increase."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise CurveError(f"{path}: cannot read: {e.strerror or e}") from None
    rows = [(n, r) for n, r in enumerate(csv.reader(text.splitlines()), start=1) if r]
    if not rows:
        raise CurveError(f"{path}: empty file (expected a header depth_m,force_N)")
    header_line, header = rows[0]
    header = [h.strip() for h in header]
    columns = {}
    for name in ("depth_m", "force_N"):
        if name not in header:
            raise CurveError(
                f"{path}:{header_line}: missing column {name} (the header has: {', '.join(header)})"
            )
        columns[name] = header.index(name)
    depth: list[float] = []
    force: list[float] = []
    previous_line = 0
    for line, row in rows[1:]:
        values = {}
        for name, i in columns.items():
            if i >= len(row):
                raise CurveError(f"{path}:{line}: no {name} value ({len(row)} columns)")
            try:
                v = float(row[i])
            except ValueError:
                raise CurveError(f"{path}:{line}: {name} is not a number: {row[i]!r}") from None
            if not math.isfinite(v):
                raise CurveError(f"{path}:{line}: {name} is {row[i].strip()} (not finite)")
            values[name] = v
        d = values["depth_m"]
        if d < 0.0:
            raise CurveError(f"{path}:{line}: depth_m {d:g} is negative")
        if depth and d <= depth[-1]:
            raise CurveError(
                f"{path}:{line}: depth_m {d:g} does not increase (line {previous_line} has "
                f"{depth[-1]:g})"
            )
        depth.append(d)
        force.append(values["force_N"])
        previous_line = line
    if len(depth) < 2:
        raise CurveError(f"{path}: needs at least 2 rows of data, has {len(depth)}")
    if not any(force):
        raise CurveError(f"{path}: every force_N is zero (the probe never touches)")
    return Curve(np.asarray(depth), np.asarray(force))


def write_curve(path: str | Path, curve: Curve) -> None:
    """Write ``curve`` as CSV (``depth_m,force_N``, full precision)."""
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["depth_m", "force_N"])
        for d, fz in zip(curve.depth, curve.force):
            w.writerow([repr(float(d)), repr(float(fz))])


# --- simulation (runs in the workers) -------------------------------------------------------


@lru_cache(maxsize=4)
def _organ(path: str, scale: float) -> TetMesh:
    """The scene's mesh in m (loaded once per process)."""
    if not path:
        organ = _mesh.default_organ()
        return organ if scale == 1.0 else _mesh.TetMesh(organ.nodes * scale, organ.tets)
    return _mesh.load(path, scale)[0]


@lru_cache(maxsize=8)
def _model(path: str, scale: float, material: tuple[float, float, float]) -> BodyModel:
    """The body model of the scene's mesh and material (E Pa, ν, ρ kg/m³), built once per
    process (the model holds the material: another E is another model)."""
    e, nu, rho = material
    options = BodyOptions(material=Material(youngs_modulus=e, poisson_ratio=nu, density=rho))
    return BodyModel(_organ(path, scale), options)


_SETTLED: OrderedDict[tuple[Any, ...], bytes] = OrderedDict()
"""Settled world states per process, keyed by the scene's organ, fixed box, material, gravity
and dt (most recent last)."""
_SETTLED_KEEP = 16


def _at_rest(scene: Scene) -> tuple[World, int]:
    """A world holding the scene's organ at rest (settled if the scene says so), no probe."""
    world = World(Settings(dt=scene.dt, gravity=list(scene.gravity)))
    material = (scene.youngs_modulus, scene.poisson_ratio, scene.density)
    organ = world.add_body_model(_model(scene.mesh, scene.mesh_scale, material))
    world.fix_box(organ, scene.fixed_min, scene.fixed_max)
    if not scene.settle:
        return world, int(organ)
    # The organ's rest state does not depend on the probe.
    key = (scene.mesh, scene.mesh_scale, scene.fixed_min, scene.fixed_max, material)
    key += (scene.gravity, scene.dt)
    state = _SETTLED.get(key)
    if state is None:
        report = world.settle()
        if not report.converged:
            raise RuntimeError(f"the organ did not settle (speed {report.max_speed:.2e} m/s)")
        state = world.save_state()
        _SETTLED[key] = state
        while len(_SETTLED) > _SETTLED_KEEP:
            _SETTLED.popitem(last=False)
    else:
        _SETTLED.move_to_end(key)
        world.restore_state(state)
    return world, int(organ)


def _probe_shape(scene: Scene) -> tuple[ToolShape, float]:
    """The probe's shape and the radius of a sphere around it (m)."""
    r, h = scene.probe_radius, scene.probe_half_length
    if scene.probe_shape == "sphere":
        return ToolShape.Sphere(r), r
    if scene.probe_shape == "capsule":
        return ToolShape.Capsule(h, r), h + r
    if scene.probe_shape == "cylinder":
        return ToolShape.Cylinder(h, r), math.hypot(h, r)
    return ToolShape.Cuboid([r, h, r]), math.sqrt(2 * r * r + h * h)


def first_contact(scene: Scene, positions: FloatArray, reach: float) -> float:
    """Travel (m) along the motion after which a sphere of radius ``reach`` (m) around the
    probe's origin first touches one of ``positions`` (n, 3), m; infinity if it never does."""
    u = np.asarray(scene.direction, dtype=float)
    u /= np.linalg.norm(u)
    d = positions - np.asarray(scene.probe_start)
    along = d @ u
    perp2 = np.einsum("ij,ij->i", d, d) - along * along
    hit = perp2 < reach * reach
    if not hit.any():
        return math.inf
    return float(max(0.0, (along[hit] - np.sqrt(reach * reach - perp2[hit])).min()))


def press(scene: Scene, depth: float) -> Curve:
    """Simulate the scene's indentation to ``depth`` (m of probe travel) and return its curve
    at every step: depth 0, one step length (``Scene.step_length``), ... up to the first step
    at or past ``depth``; force N against the motion, the step's mean. The approach before the
    probe could first touch the organ (less ``LEAD_IN``) is not simulated: its force is 0."""
    world, organ = _at_rest(scene)
    body = world.body(organ)
    shape, bound = _probe_shape(scene)
    u = np.asarray(scene.direction, dtype=float)
    u /= np.linalg.norm(u)
    h = scene.step_length()
    steps = math.ceil(depth / h - 1e-9)
    reach = bound + body.particle_radius() + body.contact_skin() + LEAD_IN
    skip = min(steps, math.floor(first_contact(scene, body.positions(), reach) / h))
    start = np.asarray(scene.probe_start, dtype=float)
    q = scene.probe_orientation
    options = ToolOptions(
        friction_static=scene.friction_static,
        friction_kinetic=min(scene.friction_kinetic, scene.friction_static),
    )
    probe = world.add_tool(shape, Pose(start + skip * h * u, q), options)
    force = np.zeros(steps + 1)
    for k in range(skip + 1, steps + 1):
        world.set_tool_pose(probe, Pose(start + k * h * u, q))
        world.step()
        force[k] = -float(world.tool(probe).wrench().force @ u)
    return Curve(h * np.arange(steps + 1), force)


def press_at(scene: Scene, depths: FloatArray) -> FloatArray:
    """The scene's simulated force (N) at each of ``depths`` (m, increasing), interpolated
    linearly between steps: the task a Dask worker runs for one candidate. NaN everywhere if
    the simulation diverged (these parameters cannot be simulated in this scene)."""
    try:
        curve = press(scene, float(depths[-1]))
    except DivergedError:
        return np.full(len(depths), np.nan)
    return np.interp(depths, curve.depth, curve.force)


def check_organ(scene: Scene, origin: str = "scene") -> None:
    """Load the scene's mesh (``MeshError`` names the file) and check that its fixed box
    holds a node when the organ must settle under gravity (``SceneError`` naming ``origin``)."""
    nodes = _organ(scene.mesh, scene.mesh_scale).nodes
    inside = np.all((nodes >= scene.fixed_min) & (nodes <= scene.fixed_max), axis=1)
    if scene.settle and any(scene.gravity) and not inside.any():
        raise SceneError(
            f"{origin}: no node of the mesh lies in the fixed box {scene.fixed_min}–"
            f"{scene.fixed_max} m: the organ cannot settle under gravity"
        )
