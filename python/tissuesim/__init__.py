"""tissuesim: a real-time soft-tissue solver for surgical simulation, from Python.

The Rust scene API with the same names: ``World``, ``Settings``, ``BodyOptions``,
``ToolShape``, ``Pose``, ... All quantities are SI (m, kg, s, N, Pa). Per-particle arrays are
numpy arrays of shape (n, 3), float64, in the mesh's node order (row k is the mesh's node k).

>>> import tissuesim as ts
>>> world = ts.World(ts.Settings())
>>> organ = world.add_body(ts.mesh.default_organ())
"""

from . import mesh, render
from ._tissuesim import (
    Blade,
    Body,
    BodyId,
    BodyModel,
    BodyOptions,
    ContactMode,
    CutReport,
    DivergedError,
    DivergenceLimits,
    GraspOptions,
    Material,
    MeshError,
    NeedleOptions,
    NeedleState,
    Pose,
    RenderSurface,
    RenderSurfaceId,
    Settings,
    SettleReport,
    StepReport,
    Tool,
    ToolId,
    ToolOptions,
    ToolShape,
    World,
    WorldState,
    Wrench,
    __version__,
)

__all__ = [
    "Blade",
    "Body",
    "BodyId",
    "BodyModel",
    "BodyOptions",
    "ContactMode",
    "CutReport",
    "DivergedError",
    "DivergenceLimits",
    "GraspOptions",
    "Material",
    "MeshError",
    "NeedleOptions",
    "NeedleState",
    "Pose",
    "RenderSurface",
    "RenderSurfaceId",
    "Settings",
    "SettleReport",
    "StepReport",
    "Tool",
    "ToolId",
    "ToolOptions",
    "ToolShape",
    "World",
    "WorldState",
    "Wrench",
    "__version__",
    "mesh",
    "render",
]
