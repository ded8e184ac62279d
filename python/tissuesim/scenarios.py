"""The main scenario of the README, scripted: the default organ hanging from its top 15 %,
at rest, then pressed by a probe, grasped and retracted, or cut by a blade.

Used by the viewer (``python -m tissuesim.view --scenario press``), the README's pictures and
the tests. Each scenario is a generator: it adds its tools to a ``Scene``, then yields after
every step (the step's index), so a caller can draw or check between steps.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from . import mesh
from ._tissuesim import (
    Pose,
    Settings,
    ToolId,
    ToolShape,
    World,
)
from .render import RenderMesh


class Scene:
    """The default organ (2,243 nodes, ~0.21 m) hanging from its top 15 % under gravity.

    ``settle=True`` starts it at rest in its equilibrium (``World.settle``, ~5 s);
    ``state`` (bytes from ``World.save_state`` of an identical scene) starts it there at once.
    """

    def __init__(
        self,
        settings: Settings | None = None,
        settle: bool = True,
        state: bytes | None = None,
    ) -> None:
        self.world = World(settings or Settings())
        self.organ = self.world.add_body(mesh.default_organ())
        body = self.world.body(self.organ)
        x = body.positions()
        self.lo, self.hi = x.min(axis=0), x.max(axis=0)
        top = self.hi[1] - 0.15 * (self.hi[1] - self.lo[1])
        self.world.fix_box(self.organ, [self.lo[0] - 1, top, self.lo[2] - 1], self.hi + 1.0)
        if state is not None:
            self.world.restore_state(state)
        elif settle:
            self.world.settle()
        self.surface = self.world.add_render_surface(
            self.organ,
            RenderMesh.from_boundary(body.rest_positions(), body.boundary_triangles()),
        )
        # The tool that scenarios report the force of (the probe, the grasper).
        self.active_tool: ToolId | None = None

    def body(self):
        """The organ's ``Body`` view."""
        return self.world.body(self.organ)

    def front_face_z(self, x: float, y: float, within: float = 0.01) -> float:
        """Largest z (m) of the organ's particles within ``within`` of (x, y): its front."""
        p = self.body().positions()
        near = np.hypot(p[:, 0] - x, p[:, 1] - y) < within
        return float(p[near, 2].max()) if near.any() else float(self.hi[2])


def press(scene: Scene, depth: float = 0.02, steps: int = 600) -> Iterator[int]:
    """A 10 mm sphere on the organ's front face at (x, y) = (0, 0), moved in by ``depth`` (m)
    over two thirds of ``steps`` (1 ms each), then held."""
    radius = 0.01
    face = scene.front_face_z(0.0, 0.0)
    start = np.array([0.0, 0.0, face + radius + 0.002])
    probe = scene.world.add_tool(ToolShape.Sphere(radius), Pose.at(start))
    scene.active_tool = probe
    moving = (2 * steps) // 3
    for k in range(steps):
        s = min(1.0, (k + 1) / moving)
        scene.world.set_tool_pose(probe, start - [0.0, 0.0, (0.002 + depth) * s])
        scene.world.step()
        yield k


def grasp(scene: Scene, pull: float = 0.03, steps: int = 1200) -> Iterator[int]:
    """A 5 mm grasper touching the front face at (0.035, 0) grasps (``World.grasp``), pulls
    the tissue out by ``pull`` (m) over two thirds of ``steps`` and holds it."""
    radius = 0.005
    face = scene.front_face_z(0.035, 0.0)
    r = scene.body().particle_radius()
    start = np.array([0.035, 0.0, face + r + 0.004])
    jaws = scene.world.add_tool(ToolShape.Sphere(radius), Pose.at(start))
    scene.active_tool = jaws
    scene.world.grasp(jaws)
    moving = (2 * steps) // 3
    for k in range(steps):
        s = min(1.0, (k + 1) / moving)
        scene.world.set_tool_pose(jaws, start + [0.0, 0.0, pull * s])
        scene.world.step()
        yield k


def cut(scene: Scene, height: float = 0.03, stroke: int = 40, steps: int = 400) -> Iterator[int]:
    """A blade (a thin capsule made a blade, its edge along x) swept along -z through the
    organ ``height`` (m) above its lowest point in ``stroke`` steps; then the part below falls
    for the rest of ``steps``."""
    p = scene.body().positions()
    low = float(p[:, 1].min())
    y = low + height
    half = 0.5 * (scene.hi[0] - scene.lo[0]) + 0.05
    # A capsule's edge is its local y axis: a quarter turn about z lays it along x.
    q = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))
    x0 = 0.5 * (scene.lo[0] + scene.hi[0])
    z0 = float(scene.hi[2]) + 0.03
    sweep = float(scene.hi[2] - scene.lo[2]) + 0.06
    blade = scene.world.add_tool(ToolShape.Capsule(half, 0.0005), Pose([x0, y, z0], q))
    scene.world.make_blade(blade)
    for k in range(steps):
        if k < stroke:
            z = z0 - sweep * (k + 1) / stroke
            scene.world.set_tool_pose(blade, Pose([x0, y, z], q))
        scene.world.step()
        yield k


SCENARIOS = {"press": press, "grasp": grasp, "cut": cut}
"""The scripted scenarios by name."""
