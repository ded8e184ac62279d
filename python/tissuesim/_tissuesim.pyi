"""Type stubs of the compiled module ``tissuesim._tissuesim`` (the Rust scene API).

Units are SI throughout: m, kg, s, N, Pa. Per-particle arrays are float64 numpy arrays of
shape (n, 3) in the mesh's node order (row k is the mesh's node k, as in the C API); index
arrays are uint32. Inputs accept any array-like (lists, tuples, arrays of any real dtype).
"""

import enum
import os
from collections.abc import Sequence
from typing import Any, Final

import numpy as np
import numpy.typing as npt

__version__: Final[str]

MIN_POISSON_RATIO: Final[float]
"""Smallest Poisson ratio a body accepts (0)."""
MAX_POISSON_RATIO: Final[float]
"""Largest Poisson ratio a body accepts (0.499)."""
YOUNGS_MODULUS_RANGE: Final[tuple[float, float]]
"""Accepted Young's moduli (Pa)."""
DENSITY_RANGE: Final[tuple[float, float]]
"""Accepted densities (kg/m³)."""
PARTICLE_RADIUS_RANGE: Final[tuple[float, float]]
"""Accepted particle radii, in mean tetrahedron edge lengths."""
SUPPORT_RADIUS_RANGE: Final[tuple[float, float]]
"""Accepted support radii, in mean tetrahedron edge lengths."""
STATE_POSITION_LIMIT: Final[float]
"""Largest distance of a set particle from the rest centre, in body sizes."""
STATE_SPEED_LIMIT: Final[float]
"""Largest speed of a set particle, in body sizes per second."""
TOOL_SIZE_RANGE: Final[tuple[float, float]]
"""Accepted tool radii, half-heights and half-extents (m)."""
MIN_QUATERNION_NORM: Final[float]
"""Quaternions of a smaller norm are rejected as zero."""
CONVEX_HULL_FLATNESS: Final[float]
"""Relative flatness below which convex-hull points count as coplanar."""
MAX_NEIGHBOURS: Final[int]
"""Most neighbours a particle may have."""
TOOL_JUMP_FRACTION: Final[float]
"""Fraction of the divergence speed bound above which a tool motion is a jump."""
SUBSTEP_HOLD_STEPS: Final[int]
"""Steps a raised substep count is kept after the rules ask for less."""
SETTLE_TOLERANCE: Final[float]
"""Relative residual at which settle's Newton iterations stop."""
SETTLE_MAX_ITERATIONS: Final[int]
"""Newton iterations per body in settle."""
SETTLE_SPEED: Final[float]
"""Speed (m/s) below which settle's relaxation stops."""
SETTLE_MAX_STEPS: Final[int]
"""Most relaxation steps in settle."""

ArrayLike = npt.ArrayLike
Vec3Like = Sequence[float] | npt.NDArray[np.floating[Any]]
Float2D = npt.NDArray[np.float64]
Float1D = npt.NDArray[np.float64]
Index2D = npt.NDArray[np.uint32]
PathLike = str | os.PathLike[str]

class MeshError(OSError):
    """A mesh file could not be read or is malformed (the message names the file and line)."""

class DivergedError(RuntimeError):
    """A step diverged; the world was rolled back to its state before the step."""

# --- settings -------------------------------------------------------------------------------

class ContactMode(enum.Enum):
    """How tool–tissue contact is detected."""

    ExactShape = 0
    """The tool's exact shape against the deformed boundary triangles (the default)."""
    SampledPoints = 1
    """The paper's mode: tool surface samples push particles out."""

class VolumeScheme(enum.Enum):
    """What one volume constraint keeps."""

    Tetrahedra = 0
    """One constraint per tetrahedron (the paper's): locks like linear tetrahedra as ν → 0.5."""
    DualCells = 1
    """One constraint per particle on its dual cell (the default): does not lock as ν → 0.5."""

class ElasticScheme(enum.Enum):
    """What carries the elasticity."""

    PointBased = 0
    """The paper's point-based particles (MLS deformation gradient)."""
    Tetrahedra = 1
    """Corotated linear tetrahedra (the default); with DualCells they do not lock as ν → 0.5."""

class DivergenceLimits:
    """Bounds beyond which a step is rolled back (relative to the body's rest size, the
    diagonal of its rest bounding box; ``float('inf')`` switches a check off)."""

    max_speed: float
    """Largest particle speed, body sizes per second (1/s). Default 250."""
    max_extent_ratio: float
    """Largest deformed extent over the rest size (dimensionless). Default 10."""
    volume_ratio: tuple[float, float]
    """Accepted range of volume / rest volume (dimensionless). Default (0.1, 10)."""
    def __init__(
        self,
        *,
        max_speed: float = ...,
        max_extent_ratio: float = ...,
        volume_ratio: tuple[float, float] = ...,
    ) -> None: ...

class Settings:
    """Time integration and constraint projection parameters; every field as in Rust's
    ``tissuesim::Settings``, defaults from ``Settings::default()``.

    Fields read and written by value: ``s.divergence`` returns a copy, so set it whole
    (``s.divergence = DivergenceLimits(max_speed=100)``).
    """

    dt: float
    """Time step of one ``World.step`` (s). Default 0.001."""
    gravity: list[float]
    """Gravity acceleration (m/s²), 3 values. Default [0, -9.81, 0]."""
    min_substeps: int
    """Smallest number of substeps per step (≥ 1). Default 1."""
    crushed_substeps: int
    """Smallest number of substeps of a step that starts with the tissue at a tool compressed (a
    tetrahedron touching it below half its rest volume, now or two steps ahead). Default 1 (none
    added); 2 for deep presses (docs/SETTINGS.md)."""
    max_substeps: int
    """Largest number of substeps per step (a step needing more is clamped). Default 64."""
    stability_margin: float
    """Fraction (0, 1] of the explicit stability limit 2/ω_max a substep may use. Default 0.9."""
    mass_scaling: bool
    """Selective mass scaling of particles whose own stable step is too short. Default True."""
    damping_mass: float
    """Mass-proportional damping rate α (1/s). Default 2."""
    damping_stiffness: float
    """Stiffness-proportional damping time β (s): dashpots on the mesh edges, implicit (adds no
    substeps). Default 0.0003 (0: none)."""
    hourglass_stiffness: float
    """Hourglass-control stiffness (dimensionless, times the shear modulus). Default 0.25."""
    volume_constraints: bool
    """XPBD per-tetrahedron volume constraints. Default True."""
    volumetric_split: bool
    """With volume constraints: λ carried by them (compliance 1/λ). Default True."""
    volume_scheme: VolumeScheme
    """What each volume constraint keeps. Default VolumeScheme.DualCells."""
    elastic_scheme: ElasticScheme
    """What carries the elasticity. Default ElasticScheme.Tetrahedra."""
    volume_compliance: float
    """Extra compliance of the volume constraints (1/Pa, per unit volume). Default 0."""
    iterations: int
    """Gauss–Seidel iterations over all constraints per substep. Default 1."""
    contact_mode: ContactMode
    """How tool–tissue contact is detected. Default ContactMode.ExactShape."""
    max_depenetration_speed: float
    """Largest speed (m/s) at which contact removes a penetration already there. Default 1."""
    self_contact: bool
    """Surface self-contact: a body's boundary kept off its own triangles. Default False."""
    threads: int
    """Threads a step runs on (1..=64); bit-identical results for any count. Default 1."""
    divergence: DivergenceLimits
    """Physical bounds checked after every step (a copy on read)."""
    def __init__(self, **fields: Any) -> None:
        """The defaults, with any field given by keyword (``TypeError`` for unknown names)."""
    def validate(self) -> None:
        """Check every field (``ValueError`` naming the first bad one)."""

# --- bodies ---------------------------------------------------------------------------------

class Material:
    """An isotropic linear-elastic material."""

    youngs_modulus: float
    """Young's modulus E (Pa), in [1e-6, 1e12]. Default 5000."""
    poisson_ratio: float
    """Poisson ratio ν (dimensionless), in [0, 0.499]. Default 0.45."""
    density: float
    """Mass density ρ (kg/m³), in [1e-6, 1e5]. Default 1060."""
    def __init__(
        self, *, youngs_modulus: float = ..., poisson_ratio: float = ..., density: float = ...
    ) -> None: ...
    def validate(self) -> None:
        """Check the ranges (``ValueError`` naming the field)."""
    def lame_lambda(self) -> float:
        """First Lamé parameter λ = Eν/((1+ν)(1−2ν)) (Pa)."""
    def shear_modulus(self) -> float:
        """Shear modulus μ = E/(2(1+ν)) (Pa)."""

class BodyOptions:
    """Options for building a body (a copy on read for ``material``)."""

    material: Material
    """The material. Default ``Material()`` (liver-like)."""
    support_radius: float | None
    """Support radius of every particle (m); None chooses one per particle. Default None."""
    target_neighbours: int
    """Target neighbours when the support radius is automatic. Default 20."""
    particle_radius: float | None
    """Contact radius of the particles (m); None: half the mean edge. Default None."""
    consistent_gradients: bool
    """Variationally consistent MLS gradients. Default True."""
    def __init__(
        self,
        *,
        material: Material = ...,
        support_radius: float | None = ...,
        target_neighbours: int = ...,
        particle_radius: float | None = ...,
        consistent_gradients: bool = ...,
    ) -> None: ...
    def validate(self) -> None:
        """Check the options (``ValueError`` naming the field)."""

class Body:
    """A body of a world: a view that reads the world's current state at every call.

    Per-particle arrays are in the mesh's node order; index arrays hold node indices.
    """

    @property
    def id(self) -> BodyId: ...
    def particle_count(self) -> int:
        """Number of particles (= mesh nodes, unreferenced nodes dropped)."""
    def positions(self) -> Float2D:
        """Positions (n, 3), m."""
    def velocities(self) -> Float2D:
        """Velocities (n, 3), m/s."""
    def rest_positions(self) -> Float2D:
        """Rest positions (n, 3), m."""
    def masses(self) -> Float1D:
        """Physical masses (n,), kg."""
    def inertial_masses(self) -> Float1D:
        """Inertial masses (n,), kg: physical plus mass scaling."""
    def added_mass(self) -> float:
        """Inertial mass added by mass scaling (kg)."""
    def mass(self) -> float:
        """Total physical mass (kg)."""
    def tets(self) -> Index2D:
        """Tetrahedra (m, 4), node indices (removed ones left out after a cut)."""
    def boundary_triangles(self) -> Index2D:
        """Boundary triangles (k, 3), node indices, counter-clockwise seen from outside."""
    def volume(self) -> float:
        """Current volume (m³)."""
    def rest_volume(self) -> float:
        """Rest volume (m³)."""
    def volume_ratio(self) -> float:
        """Volume over rest volume (dimensionless)."""
    def max_displacement(self) -> float:
        """Largest distance of a particle from its rest position (m)."""
    def is_fixed(self, k: int) -> bool:
        """Whether mesh node ``k`` is fixed (``IndexError`` out of range)."""
    def fixed_flags(self) -> npt.NDArray[np.bool_]:
        """Fixed flags (n,)."""
    def particle_radius(self) -> float:
        """Contact radius of the particles (m)."""
    def contact_skin(self) -> float:
        """Contact skin of the exact-shape mode (m)."""
    def material(self) -> Material:
        """The material (a copy)."""
    def max_angular_frequency(self) -> float:
        """Largest angular frequency of the linearised system at rest (rad/s)."""
    def contains(self, point: Vec3Like) -> bool:
        """Whether ``point`` (m) is inside the deformed body."""
    def deformation_gradient_at(self, positions: ArrayLike, k: int) -> Float2D:
        """Deformation gradient F (3, 3) of node ``k`` if the nodes were at ``positions``
        (n, 3), m (an analysis helper)."""
    def elastic_forces_at(self, positions: ArrayLike) -> Float2D:
        """Elastic and hourglass forces (n, 3), N, if the nodes were at ``positions`` (n, 3),
        m, at rest (an analysis helper)."""
    def cut_counts(self) -> tuple[int, int]:
        """(neighbour pairs cut, tetrahedra removed) so far."""
    def model(self) -> BodyModel:
        """The body's model (a cut body's own copy)."""
    def load_time_model(self) -> BodyModel:
        """The uncut model it was built on."""
    def particle_order(self) -> npt.NDArray[np.uint32]:
        """For each particle in internal storage order, its mesh node index (n,)."""

class BodyModel:
    """A body's immutable load-time data, shared by every body built on it."""

    def __init__(self, mesh: TetMesh, options: BodyOptions | None = None) -> None:
        """Build the model (GIL released; ``ValueError`` for a bad mesh or options)."""
    def particle_count(self) -> int: ...
    def rest_positions(self) -> Float2D:
        """Rest positions (n, 3), m, node order."""
    def tets(self) -> Index2D:
        """Tetrahedra (m, 4), node indices."""
    def options(self) -> BodyOptions: ...
    def is_built_from(self, mesh: TetMesh, options: BodyOptions | None = None) -> bool: ...
    def heap_bytes(self) -> int:
        """Heap memory held (bytes)."""

# --- meshes ---------------------------------------------------------------------------------

class TetMesh:
    """A tetrahedral mesh: nodes (n, 3) m, tetrahedra (m, 4) node indices."""

    def __init__(self, nodes: ArrayLike, tets: ArrayLike) -> None:
        """As given, not cleaned (``World.add_body`` checks; ``from_raw`` cleans)."""
    @staticmethod
    def from_raw(nodes: ArrayLike, tets: ArrayLike) -> tuple[TetMesh, MeshReport]:
        """Clean raw arrays (re-orient, drop degenerate tets and unreferenced nodes);
        ``ValueError`` for bad indices."""
    @property
    def nodes(self) -> Float2D:
        """Node positions (n, 3), m."""
    @property
    def tets(self) -> Index2D:
        """Tetrahedra (m, 4)."""
    def node_count(self) -> int: ...
    def tet_count(self) -> int: ...
    def boundary_triangles(self) -> Index2D:
        """Boundary triangles (k, 3), outward."""
    def volume(self) -> float:
        """Sum of the tetrahedron volumes (m³)."""
    def bounding_box(self) -> tuple[Float1D, Float1D]:
        """(min, max), each (3,), m."""
    def mean_edge_length(self) -> float:
        """Mean edge length (m)."""
    def translated(self, offset: Vec3Like) -> TetMesh:
        """A copy moved by ``offset`` (m)."""

class MeshReport:
    """What cleaning a raw mesh changed."""

    @property
    def reoriented_tets(self) -> int: ...
    @property
    def degenerate_tets_removed(self) -> int: ...
    @property
    def unreferenced_nodes_removed(self) -> int: ...
    @property
    def skipped_elements(self) -> int: ...
    @property
    def original_node_index(self) -> npt.NDArray[np.uint32]:
        """For each node kept, its 0-based index in the file's node list (n,)."""

class SurfaceMesh:
    """A triangulated surface (an OBJ): vertices (n, 3) m, triangles (k, 3)."""

    @property
    def vertices(self) -> Float2D: ...
    @property
    def triangles(self) -> Index2D: ...

def mesh_load(path: PathLike, scale: float = 1.0) -> tuple[TetMesh, MeshReport]:
    """Load .msh (Gmsh), .node/.ele (TetGen) or .vtk, positions times ``scale`` (to m);
    ``MeshError`` (an ``OSError``) names the file and line."""

def mesh_default_organ() -> TetMesh:
    """The embedded default organ: 2,243 nodes, 9,918 tetrahedra, ~0.21 m across."""

def mesh_organ_with_cell(cell: float) -> TetMesh:
    """The default organ's shape on cubes of edge ``cell`` (m, clamped to [0.003, 0.05])."""

def mesh_lattice_box(min: Vec3Like, max: Vec3Like, cells: Sequence[int]) -> TetMesh:
    """A box [min, max] (m) of cells[0] × cells[1] × cells[2] cells, six tetrahedra each."""

def mesh_read_obj(path: PathLike, scale: float = 1.0) -> SurfaceMesh:
    """Read an OBJ surface, positions times ``scale``."""

def mesh_write_vtk(path: PathLike, mesh: TetMesh) -> None:
    """Write legacy VTK ASCII (readable by ``load``)."""

def mesh_write_vtu(
    path: PathLike,
    positions: ArrayLike,
    tets: ArrayLike,
    point_scalars: dict[str, ArrayLike] | None = None,
    point_vectors: dict[str, ArrayLike] | None = None,
) -> None:
    """Write a volume mesh for ParaView: positions (n, 3) m, tets (m, 4), point data."""

def mesh_write_vtu_surface(
    path: PathLike,
    positions: ArrayLike,
    triangles: ArrayLike,
    point_scalars: dict[str, ArrayLike] | None = None,
    point_vectors: dict[str, ArrayLike] | None = None,
) -> None:
    """Write a surface for ParaView: positions (n, 3) m, triangles (k, 3), point data."""

def statics_linear_gravity_sag(body: Body, g: Vec3Like) -> Float2D:
    """Linear static displacement (n, 3), m, from rest under gravity ``g`` (m/s²), node
    order (GIL released)."""

def statics_linear_response(body: Body, load: ArrayLike, prescribed: ArrayLike) -> Float2D:
    """Linear static displacement (n, 3), m: K u = ``load`` (n, 3), N, on free nodes,
    u = ``prescribed`` (n, 3), m, on fixed ones (node order)."""

# --- tools ----------------------------------------------------------------------------------

class ToolShape:
    """A tool's shape in its own frame (m). Build with the variant constructors."""

    @staticmethod
    def Sphere(radius: float) -> ToolShape:
        """A sphere of ``radius`` (m) on the tool origin."""
    @staticmethod
    def Capsule(half_height: float, radius: float) -> ToolShape:
        """A capsule along local y: segment half-length (m, ≥ 0) and radius (m)."""
    @staticmethod
    def Cylinder(half_height: float, radius: float) -> ToolShape:
        """A cylinder along local y: half-length (m) and radius (m)."""
    @staticmethod
    def Cuboid(half_extents: Vec3Like) -> ToolShape:
        """A box with half extents (3,) along local x, y, z (m)."""
    @staticmethod
    def ConvexHull(points: ArrayLike) -> ToolShape:
        """The convex hull of ``points`` (n, 3), m (≥ 4, not coplanar)."""
    @staticmethod
    def TriMesh(vertices: ArrayLike, triangles: ArrayLike) -> ToolShape:
        """A triangle mesh: vertices (n, 3) m, triangles (k, 3)."""
    @staticmethod
    def from_obj(path: PathLike, scale: float = 1.0) -> ToolShape:
        """A triangle mesh read from OBJ, positions times ``scale``."""
    @property
    def kind(self) -> str:
        """ "Sphere", "Capsule", "Cylinder", "Cuboid", "ConvexHull" or "TriMesh"."""
    def parameters(self) -> dict[str, Any]:
        """The variant's fields (m; arrays as numpy arrays)."""

class Pose:
    """A rigid pose: position (m) and orientation quaternion (w, x, y, z), local to world."""

    def __init__(
        self, position: Vec3Like, orientation: Sequence[float] = (1.0, 0.0, 0.0, 0.0)
    ) -> None:
        """Normalises the quaternion; ``ValueError`` for NaN/Inf or a zero quaternion."""
    @staticmethod
    def at(position: Vec3Like) -> Pose:
        """At ``position`` (m), identity orientation."""
    @staticmethod
    def interpolate(a: Pose, b: Pose, s: float) -> Pose:
        """Linear in position, slerp in orientation (s = 0: a, s = 1: b)."""
    @property
    def position(self) -> Float1D:
        """(3,), m, world frame."""
    @property
    def orientation(self) -> Float1D:
        """(4,): w, x, y, z."""
    def is_valid(self) -> bool: ...
    def transform_point(self, point: Vec3Like) -> Float1D:
        """A point of the tool's frame (m) in the world frame."""

PoseLike = Pose | Vec3Like

class ToolOptions:
    """Friction and sampling of a tool."""

    friction_static: float
    """Static friction coefficient μ_s (dimensionless). Default 0."""
    friction_kinetic: float
    """Kinetic friction coefficient μ_k ≤ μ_s (dimensionless). Default 0."""
    sample_spacing: float | None
    """Surface sample spacing (m) of the sampled contact mode; None: particle radius."""
    def __init__(
        self,
        *,
        friction_static: float = ...,
        friction_kinetic: float = ...,
        sample_spacing: float | None = ...,
    ) -> None: ...
    def validate(self) -> None: ...

class Wrench:
    """What the tissue exerts on a tool, averaged over the substeps of the last step."""

    @property
    def force(self) -> Float1D:
        """Force on the tool (3,), N, world frame."""
    @property
    def torque(self) -> Float1D:
        """Torque about the tool origin (3,), N·m, world frame."""
    @property
    def contact_count(self) -> int:
        """Contacts at the last substep."""
    @property
    def max_penetration(self) -> float:
        """Largest contact violation before projection in the last step (m)."""

class Tool:
    """A tool of a world: a view that reads the world's current state at every call."""

    @property
    def id(self) -> ToolId: ...
    def pose(self) -> Pose:
        """Pose at the end of the last step."""
    def target_pose(self) -> Pose:
        """Pose to reach at the end of the next step."""
    def shape(self) -> ToolShape: ...
    def options(self) -> ToolOptions: ...
    def linear_velocity(self) -> Float1D:
        """Velocity of the origin over the last step (3,), m/s."""
    def wrench(self) -> Wrench:
        """The wrench of the last step."""
    def sample_count(self) -> int: ...
    def signed_distance(self, pose: Pose, point: Vec3Like) -> float:
        """Signed distance (m) of ``point`` to the tool's surface at ``pose`` (< 0 inside)."""

# --- grasping, needles, cutting -------------------------------------------------------------

class GraspOptions:
    """How a tool grasps."""

    reach: float | None
    """Particles within this distance (m) of the tool are held; None: 1.5 particle radii."""
    compliance: float | None
    """Compliance of each attachment (m/N); None: that of the tissue around it."""
    max_force: float
    """Largest total pull (N) before the tissue slips; infinity never slips."""
    def __init__(
        self,
        *,
        reach: float | None = ...,
        compliance: float | None = ...,
        max_force: float = ...,
    ) -> None: ...
    def validate(self) -> None: ...

class NeedleOptions:
    """How a needle punctures and holds the tissue."""

    puncture_force: float
    """Axial force (N) on the tip that punctures the tissue. Default 1."""
    friction_per_length: float
    """Axial friction per inserted length (N/m). Default 20."""
    reach: float | None
    """Hold radius around the shaft (m); None: radius + 1.5 particle radii."""
    def __init__(
        self,
        *,
        puncture_force: float = ...,
        friction_per_length: float = ...,
        reach: float | None = ...,
    ) -> None: ...
    def validate(self) -> None: ...

class NeedleState:
    """Where a needle is."""

    @property
    def punctured(self) -> bool: ...
    @property
    def inserted_length(self) -> float:
        """Tip past the entry point along the shaft (m)."""
    @property
    def held(self) -> int:
        """Particles held on the shaft."""

class Blade:
    """A blade's edge at the start and at the end of its motion (m, world frame)."""

    def __init__(self, from_: tuple[Vec3Like, Vec3Like], to: tuple[Vec3Like, Vec3Like]) -> None: ...
    @property
    def from_(self) -> Float2D:
        """The edge's ends at the start (2, 3), m."""
    @property
    def to(self) -> Float2D:
        """The edge's ends at the end (2, 3), m."""

class CutReport:
    """What a cut removed."""

    @property
    def pairs(self) -> int:
        """Neighbour pairs cut."""
    @property
    def tets(self) -> int:
        """Tetrahedra removed."""
    @property
    def isolated(self) -> int:
        """Particles left without elasticity."""

# --- render surfaces ------------------------------------------------------------------------

class RenderMesh:
    """A visual mesh: one vertex per distinct OBJ v/vt/vn triple, rest positions in m."""

    @staticmethod
    def from_boundary(nodes: ArrayLike, boundary: ArrayLike) -> RenderMesh:
        """A body's boundary: nodes (n, 3) m, boundary (k, 3) node indices."""
    def vertex_count(self) -> int: ...
    @property
    def positions(self) -> Float2D:
        """Rest positions (n, 3), m."""
    @property
    def texcoords(self) -> Float2D:
        """Texture coordinates (n, 2)."""
    @property
    def normals(self) -> Float2D:
        """File normals (n, 3), zero where none."""
    @property
    def triangles(self) -> Index2D: ...
    @property
    def has_texcoords(self) -> bool: ...

def render_read_obj(path: PathLike, scale: float = 1.0) -> RenderMesh:
    """Read an OBJ render surface (v/vt/vn/f), positions times ``scale`` (to m)."""

class BindReport:
    """How a render surface was bound to its body's rest tetrahedra."""

    @property
    def inside(self) -> int: ...
    @property
    def outside(self) -> int: ...
    @property
    def max_outside_distance(self) -> float:
        """Largest distance of an outside vertex to its tetrahedron (m)."""

class RenderSurface:
    """A render surface of a world as of its last update (a view)."""

    @property
    def id(self) -> RenderSurfaceId: ...
    def body(self) -> BodyId: ...
    def vertex_count(self) -> int: ...
    def triangles(self) -> Index2D: ...
    def texcoords(self) -> Float2D: ...
    def positions(self) -> Float2D:
        """Deformed vertex positions (n, 3), m."""
    def normals(self) -> Float2D:
        """Unit vertex normals (n, 3)."""
    def mesh(self) -> RenderMesh: ...
    def bind_report(self) -> BindReport: ...
    def write_obj(self, path: PathLike) -> None: ...
    def write_vtu(self, path: PathLike) -> None: ...

# --- the world ------------------------------------------------------------------------------

class BodyId:
    """Identifies a body in its world (insertion order, never reused)."""

    def __init__(self, index: int) -> None: ...
    @property
    def index(self) -> int: ...
    def __int__(self) -> int: ...
    def __index__(self) -> int: ...
    def __hash__(self) -> int: ...

class ToolId:
    """Identifies a tool in its world (insertion order, never reused)."""

    def __init__(self, index: int) -> None: ...
    @property
    def index(self) -> int: ...
    def __int__(self) -> int: ...
    def __index__(self) -> int: ...
    def __hash__(self) -> int: ...

class RenderSurfaceId:
    """Identifies a render surface in its world."""

    def __init__(self, index: int) -> None: ...
    @property
    def index(self) -> int: ...
    def __int__(self) -> int: ...
    def __index__(self) -> int: ...
    def __hash__(self) -> int: ...

BodyIdLike = BodyId | int
ToolIdLike = ToolId | int
RenderSurfaceIdLike = RenderSurfaceId | int

class StepReport:
    """What one step did."""

    @property
    def substeps(self) -> int: ...
    @property
    def substeps_clamped(self) -> bool: ...
    @property
    def cut(self) -> CutReport:
        """What blades cut at the end of the step."""

class SettleReport:
    """What ``World.settle`` did."""

    @property
    def newton_iterations(self) -> int: ...
    @property
    def relative_residual(self) -> float: ...
    @property
    def relaxation_steps(self) -> int: ...
    @property
    def max_speed(self) -> float:
        """Largest particle speed at the end (m/s)."""
    @property
    def converged(self) -> bool: ...

class WorldState:
    """The dynamic state of a world (time, particles, fixed flags, cuts, tools)."""

    def time(self) -> float:
        """Simulated time (s)."""
    def body_count(self) -> int: ...
    def tool_count(self) -> int: ...
    def to_bytes(self) -> bytes:
        """Checksummed bytes (the format of ``World.save_state``)."""
    def byte_size(self) -> int: ...
    @staticmethod
    def from_bytes(data: bytes) -> WorldState:
        """``ValueError`` for a bad version, size or checksum."""

class World:
    """A simulated scene. Every method is the Rust ``tissuesim::World`` method of that name.

    The GIL is released during ``step``, ``settle``, ``add_body``, ``add_render_surface`` and
    ``cut``; another thread calling into the same world meanwhile gets ``RuntimeError``.
    """

    def __init__(self, settings: Settings | None = None) -> None:
        """An empty world (``ValueError`` for invalid settings)."""
    def settings(self) -> Settings:
        """The settings in force (a copy)."""
    def set_settings(self, settings: Settings) -> None: ...
    def time(self) -> float:
        """Simulated time (s)."""
    def diverged_steps(self) -> int: ...
    def set_profiling(self, on: bool) -> None:
        """Measure each stage's wall time from the next step on (``False``: stop; the default)."""
    def step_profile(self) -> dict[str, float] | None:
        """The last step's stage wall times (s) by name, ``None`` while profiling is off."""
    def add_body(self, mesh: TetMesh, options: BodyOptions | None = None) -> BodyId:
        """Add a deformable body from ``mesh`` (m)."""
    def add_body_model(self, model: BodyModel) -> BodyId: ...
    def body_count(self) -> int: ...
    def body(self, id: BodyIdLike) -> Body: ...
    def set_body_state(self, body: BodyIdLike, positions: ArrayLike, velocities: ArrayLike) -> None:
        """Positions (n, 3) m and velocities (n, 3) m/s in node order; nothing changes on
        error."""
    def add_render_surface(self, body: BodyIdLike, mesh: RenderMesh) -> RenderSurfaceId: ...
    def render_surface_count(self) -> int: ...
    def render_surface(self, id: RenderSurfaceIdLike) -> RenderSurface: ...
    def update_render_surface(self, id: RenderSurfaceIdLike) -> RenderSurface: ...
    def fix_particles(self, body: BodyIdLike, indices: ArrayLike) -> None:
        """Fix mesh nodes ``indices``; nothing is fixed if one is out of range."""
    def fix_box(self, body: BodyIdLike, min: Vec3Like, max: Vec3Like) -> int:
        """Fix the particles inside [min, max] (m); returns how many."""
    def add_tool(
        self, shape: ToolShape, pose: PoseLike, options: ToolOptions | None = None
    ) -> ToolId: ...
    def remove_tool(self, tool: ToolIdLike) -> None: ...
    def cut(self, body: BodyIdLike, blade: Blade) -> CutReport: ...
    def make_blade(self, tool: ToolIdLike) -> None: ...
    def make_needle(self, tool: ToolIdLike, options: NeedleOptions | None = None) -> None: ...
    def needle_state(self, tool: ToolIdLike) -> NeedleState: ...
    def grasp(self, tool: ToolIdLike, options: GraspOptions | None = None) -> int:
        """Hold the tissue within reach; returns how many particles."""
    def release(self, tool: ToolIdLike) -> None: ...
    def grasped_count(self, tool: ToolIdLike) -> int: ...
    def tool_count(self) -> int: ...
    def tool_ids(self) -> list[ToolId]: ...
    def tool(self, id: ToolIdLike) -> Tool: ...
    def set_tool_pose(self, tool: ToolIdLike, pose: PoseLike) -> None:
        """The pose reached at the end of the next step (a position (3,) means identity
        orientation)."""
    def set_tool_friction(
        self, tool: ToolIdLike, friction_static: float, friction_kinetic: float
    ) -> None: ...
    def set_body_pair_friction(
        self, a: BodyIdLike, b: BodyIdLike, friction_static: float, friction_kinetic: float
    ) -> None: ...
    def tool_jump_speed(self) -> float:
        """Fastest swept tool motion (m/s); faster is a jump."""
    def substeps_needed(self) -> tuple[int, bool]:
        """Substeps the next step takes and whether ``max_substeps`` clamped them (a raised count
        is kept for ``SUBSTEP_HOLD_STEPS`` steps)."""
    def step(self) -> StepReport:
        """Advance by ``dt`` (GIL released); ``DivergedError`` when rolled back."""
    def settle(self) -> SettleReport:
        """Rest in equilibrium under gravity (GIL released); nothing changes on error."""
    def state(self) -> WorldState: ...
    def set_state(self, state: WorldState) -> None: ...
    def state_size(self) -> int:
        """Size of ``save_state()`` (bytes)."""
    def save_state(self) -> bytes: ...
    def restore_state(self, data: bytes) -> None:
        """``ValueError`` for bytes of another scene or corrupted; nothing changes then."""

def _bench_rust_loop(world: World, tool: ToolIdLike, positions: ArrayLike) -> Float1D:
    """The benchmark's Rust loop: per row of ``positions`` (k, 3), set_tool_pose + step +
    wrench in Rust; each step's time (s)."""
