"""Tetrahedral meshes (the Rust ``tissuesim::mesh`` module): readers, writers, the default organ.

Node positions are in metres after ``scale`` (mesh units to m) is applied.
"""

from ._tissuesim import MeshReport, SurfaceMesh, TetMesh
from ._tissuesim import mesh_default_organ as default_organ
from ._tissuesim import mesh_lattice_box as lattice_box
from ._tissuesim import mesh_load as load
from ._tissuesim import mesh_organ_with_cell as organ_with_cell
from ._tissuesim import mesh_read_obj as read_obj
from ._tissuesim import mesh_write_vtk as write_vtk
from ._tissuesim import mesh_write_vtu as write_vtu
from ._tissuesim import mesh_write_vtu_surface as write_vtu_surface

__all__ = [
    "MeshReport",
    "SurfaceMesh",
    "TetMesh",
    "default_organ",
    "lattice_box",
    "load",
    "organ_with_cell",
    "read_obj",
    "write_vtk",
    "write_vtu",
    "write_vtu_surface",
]
