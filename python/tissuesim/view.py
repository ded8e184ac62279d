"""A live viewer of a tissuesim scene, on pyvista (VTK).

    python -m tissuesim.view [--scenario press|grasp|cut|probe] [--screenshot PATH]
                             [--gif PATH] [--every K] [--size W H] [--no-settle]

Shows the organ's render surface, the tools and the force on the active tool as an arrow.
``--scenario probe`` (the default when a window is shown) gives a probe driven by the mouse:
drag the sphere widget into the organ and watch the arrow. The scripted scenarios (press,
grasp, cut) run the README's main scenario (``tissuesim.scenarios``). ``--screenshot`` and
``--gif`` render off-screen (no window) and write the last frame / every K-th step.

Needs ``pip install pyvista imageio`` (the ``view`` extra).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence

import numpy as np

from . import scenarios
from ._tissuesim import Pose, ToolShape, World

ORGAN_COLOUR = (0.80, 0.33, 0.29)
"""The organ's colour (RGB in [0, 1]): liver red."""
TOOL_COLOUR = (0.75, 0.77, 0.80)
ARROW_COLOUR = (0.15, 0.45, 0.95)
BACKGROUND = (1.0, 1.0, 1.0)
ARROW_METRES_PER_NEWTON = 0.1
"""Arrow length per newton of tool force (m/N), capped at 8 cm."""


def _pyvista():
    try:
        import pyvista as pv
    except ImportError as e:  # pragma: no cover - exercised only without the extra
        raise SystemExit("tissuesim.view needs pyvista: pip install 'pyvista>=0.43' imageio") from e
    return pv


def faces(triangles: np.ndarray) -> np.ndarray:
    """VTK's flat face array [3, a, b, c, 3, ...] of (k, 3) triangles."""
    t = np.asarray(triangles, dtype=np.int64)
    return np.hstack([np.full((len(t), 1), 3, dtype=np.int64), t]).ravel()


def tool_mesh(shape: ToolShape):
    """A pyvista mesh of a tool's shape in its own frame (m)."""
    pv = _pyvista()
    p = shape.parameters()
    kind = shape.kind
    if kind == "Sphere":
        return pv.Sphere(radius=p["radius"], theta_resolution=24, phi_resolution=24)
    if kind in ("Capsule", "Cylinder"):
        h, r = p["half_height"], p["radius"]
        body = pv.Cylinder(radius=r, height=2 * h, direction=(0, 1, 0), resolution=24)
        if kind == "Cylinder":
            return body.triangulate()
        ends = [pv.Sphere(radius=r, center=(0, s * h, 0)) for s in (-1, 1)]
        return body.triangulate().merge(ends)
    if kind == "Cuboid":
        e = p["half_extents"]
        return pv.Box(bounds=(-e[0], e[0], -e[1], e[1], -e[2], e[2]))
    if kind == "ConvexHull":
        return pv.PolyData(p["points"]).delaunay_3d().extract_surface()
    return pv.PolyData(p["vertices"], faces(p["triangles"]))


def pose_matrix(pose: Pose) -> np.ndarray:
    """The 4×4 homogeneous matrix of a pose (local to world)."""
    w, x, y, z = pose.orientation
    m = np.eye(4)
    m[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    m[:3, 3] = pose.position
    return m


class View:
    """The organ's render surface, the tools and the force arrow of a ``Scene`` in a pyvista
    plotter; ``update()`` redraws them from the world."""

    def __init__(self, scene: scenarios.Scene, off_screen: bool, size: Sequence[int]) -> None:
        pv = _pyvista()
        self.scene = scene
        self.plotter = pv.Plotter(off_screen=off_screen, window_size=list(size))
        self.plotter.set_background(BACKGROUND)
        surface = scene.world.update_render_surface(scene.surface)
        self.organ = pv.PolyData(surface.positions(), faces(surface.triangles()))
        self.plotter.add_mesh(self.organ, color=ORGAN_COLOUR, smooth_shading=True, specular=0.3)
        self.tools: dict[int, object] = {}
        self.arrow = pv.Arrow()
        self.arrow_actor = self.plotter.add_mesh(self.arrow, color=ARROW_COLOUR)
        self.arrow_actor.visibility = False
        self.text = self.plotter.add_text("", position="upper_left", font_size=10, color="black")
        # From the right, in front and a little above: the front face (+z), where the tools
        # work, in profile.
        self.plotter.camera_position = [(0.42, 0.10, 0.26), (0.0, -0.02, 0.02), (0.0, 1.0, 0.0)]

    def update(self) -> None:
        """Redraw the organ, the tools and the arrow from the world's current state."""
        pv = _pyvista()
        world: World = self.scene.world
        body = world.body(self.scene.organ)
        if body.cut_counts()[1] > 0:
            # A render surface is bound once and does not follow a cut: draw the body's own
            # boundary, rebuilt by the cut, instead.
            self.organ.copy_from(pv.PolyData(body.positions(), faces(body.boundary_triangles())))
        else:
            self.organ.points = world.update_render_surface(self.scene.surface).positions()
        live = set()
        for tid in world.tool_ids():
            tool = world.tool(tid)
            live.add(tid.index)
            if tid.index not in self.tools:
                self.tools[tid.index] = self.plotter.add_mesh(
                    tool_mesh(tool.shape()), color=TOOL_COLOUR, smooth_shading=True
                )
            self.tools[tid.index].user_matrix = pose_matrix(tool.pose())
        for index in list(self.tools):
            if index not in live:
                self.plotter.remove_actor(self.tools.pop(index))
        label = f"t = {world.time():.3f} s"
        shown = False
        active = self.scene.active_tool
        if active is not None and active.index in live:
            tool = world.tool(active)
            force = tool.wrench().force
            norm = float(np.linalg.norm(force))
            label += f"   force on the tool {norm:.3f} N"
            if norm > 1e-6:
                self.arrow.copy_from(
                    pv.Arrow(
                        start=tool.pose().position,
                        direction=force / norm,
                        scale=min(0.08, ARROW_METRES_PER_NEWTON * norm),
                        tip_length=0.3,
                        tip_radius=0.12,
                        shaft_radius=0.04,
                    )
                )
                shown = True
        self.arrow_actor.visibility = shown
        self.text.SetText(2, label)  # 2: the upper-left corner


def run(argv: Sequence[str] | None = None) -> int:
    """The command line (see the module docstring)."""
    parser = argparse.ArgumentParser(prog="python -m tissuesim.view", description=__doc__)
    parser.add_argument(
        "--scenario",
        choices=[*scenarios.SCENARIOS, "probe"],
        default=None,
        help="scripted scenario, or probe (mouse); default: probe in a window, press off-screen",
    )
    parser.add_argument("--screenshot", metavar="PATH", help="write the last frame as PNG")
    parser.add_argument("--gif", metavar="PATH", help="write an animated GIF")
    parser.add_argument("--every", type=int, default=20, help="steps between frames (20)")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 600), metavar=("W", "H"))
    parser.add_argument("--steps", type=int, default=None, help="steps of the scenario")
    parser.add_argument(
        "--no-settle", action="store_true", help="start from the rest shape (no settle)"
    )
    parser.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="S",
        help="close the window after S seconds of wall time (default: when closed)",
    )
    args = parser.parse_args(argv)
    off_screen = bool(args.screenshot or args.gif)
    name = args.scenario or ("press" if off_screen else "probe")
    if name == "probe" and off_screen:
        parser.error("--scenario probe needs a window (the mouse); use press, grasp or cut")

    scene = scenarios.Scene(settle=not args.no_settle)
    view = View(scene, off_screen=off_screen, size=args.size)
    if name == "probe":
        return _interactive_probe(scene, view, args.duration)

    kwargs = {} if args.steps is None else {"steps": args.steps}
    script = scenarios.SCENARIOS[name](scene, **kwargs)
    if args.gif:
        view.plotter.open_gif(args.gif, fps=15)
    if not off_screen:
        view.plotter.show(interactive_update=True, auto_close=False)
    for k in script:
        if (k + 1) % args.every == 0:
            view.update()
            if args.gif:
                view.plotter.write_frame()
            if not off_screen:
                view.plotter.update()
    view.update()
    if args.screenshot:
        view.plotter.screenshot(args.screenshot)
        print(f"wrote {args.screenshot}")
    if args.gif:
        view.plotter.write_frame()
        print(f"wrote {args.gif}")
    if not off_screen and args.duration is None:
        view.plotter.show()
    view.plotter.close()
    return 0


def _interactive_probe(scene: scenarios.Scene, view: View, duration: float | None) -> int:
    """A 10 mm probe that follows a sphere widget dragged with the mouse."""
    start = np.array([0.0, 0.0, scene.front_face_z(0.0, 0.0) + 0.03])
    probe = scene.world.add_tool(ToolShape.Sphere(0.01), Pose.at(start))
    scene.active_tool = probe
    target = {"position": start}

    def moved(centre) -> None:
        target["position"] = np.asarray(centre, dtype=float)

    view.plotter.add_sphere_widget(moved, center=start, radius=0.006, color="yellow")
    view.plotter.show(interactive_update=True, auto_close=False)
    end = time.monotonic() + (duration if duration is not None else float("inf"))
    while time.monotonic() < end and not getattr(view.plotter, "_closed", False):
        # Towards the widget by at most 5 mm a frame of 10 steps (0.5 m/s: a hand, not a
        # teleport).
        here = scene.world.tool(probe).pose().position
        delta = target["position"] - here
        step = min(1.0, 0.005 / max(float(np.linalg.norm(delta)), 1e-12))
        scene.world.set_tool_pose(probe, here + step * delta)
        for _ in range(10):
            scene.world.step()
        view.update()
        view.plotter.update()
    view.plotter.close()
    return 0


if __name__ == "__main__":
    sys.exit(run())
