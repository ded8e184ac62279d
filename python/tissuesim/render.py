"""Render (visual) surfaces (the Rust ``tissuesim::render`` module).

A ``RenderMesh`` (an OBJ read with ``read_obj``, or a body's boundary with
``RenderMesh.from_boundary``) is bound to a body with ``World.add_render_surface``;
``World.update_render_surface`` recomputes its deformed positions and normals.
"""

from ._tissuesim import BindReport, RenderMesh, RenderSurface
from ._tissuesim import render_read_obj as read_obj

__all__ = ["BindReport", "RenderMesh", "RenderSurface", "read_obj"]
