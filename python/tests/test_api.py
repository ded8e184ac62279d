"""The API contract: node order, arrays, every tool shape, settings, render surfaces, errors
(the right exception, the core's message, the world unchanged)."""

from __future__ import annotations

import numpy as np
import pytest

import tissuesim as ts
from conftest import MESHES


def small_block(world: ts.World) -> ts.BodyId:
    return world.add_body(ts.mesh.lattice_box([0, 0, 0], [0.04, 0.02, 0.02], [4, 2, 2]))


def test_body_arrays_are_in_the_files_node_order():
    path = MESHES / "liver_4k.node"
    rows = np.loadtxt(path, skiprows=1, comments="#")
    file_nodes = rows[:, 1:4] * 0.03
    ele = np.loadtxt(MESHES / "liver_4k.ele", skiprows=1, comments="#", dtype=np.int64)
    mesh, report = ts.mesh.load(path, 0.03)
    np.testing.assert_array_equal(report.original_node_index, np.arange(len(rows)))
    np.testing.assert_array_equal(mesh.nodes, file_nodes)
    world = ts.World()
    body = world.body(world.add_body(mesh))
    assert body.particle_count() == len(rows)
    # Rest positions, positions and tetrahedra come back in the file's order, not the
    # solver's internal (Morton) order.
    assert not np.array_equal(body.particle_order(), np.arange(len(rows)))
    np.testing.assert_array_equal(body.rest_positions(), file_nodes)
    np.testing.assert_array_equal(body.positions(), file_nodes)
    tets = body.tets()
    assert tets.dtype == np.uint32 and tets.shape == (len(ele), 4)
    np.testing.assert_array_equal(np.sort(tets, axis=1), np.sort(ele[:, 1:5], axis=1))


def test_state_and_fixing_round_trip_in_node_order():
    world = ts.World(ts.Settings(gravity=[0.0, 0.0, 0.0]))
    b = small_block(world)
    body = world.body(b)
    n = body.particle_count()
    rng = np.random.default_rng(1)
    x = body.rest_positions() + rng.normal(scale=1e-4, size=(n, 3))
    v = rng.normal(scale=1e-3, size=(n, 3))
    world.set_body_state(b, x, v)
    np.testing.assert_array_equal(body.positions(), x)
    np.testing.assert_array_equal(body.velocities(), v)
    world.fix_particles(b, [0, 7])
    flags = body.fixed_flags()
    assert flags.tolist() == [k in (0, 7) for k in range(n)]
    assert body.is_fixed(7) and not body.is_fixed(1)
    # Node 0 is (0, 0, 0) of the lattice; it stays there.
    for _ in range(20):
        world.step()
    np.testing.assert_array_equal(body.positions()[[0, 7]], x[[0, 7]])
    # fix_box counts the nodes inside.
    assert world.fix_box(b, [-1, -1, -1], [0.005, 1, 1]) == 9


def test_meshes_from_arrays_are_cleaned_and_reported():
    nodes = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [9, 9, 9], [1, 1, 1]]
    tets = [[0, 2, 1, 3], [1, 2, 3, 5]]  # the first inverted; node 4 unreferenced
    mesh, report = ts.mesh.TetMesh.from_raw(np.array(nodes) * 0.01, tets)
    assert report.reoriented_tets == 1
    assert report.unreferenced_nodes_removed == 1
    assert report.original_node_index.tolist() == [0, 1, 2, 3, 5]
    assert mesh.node_count() == 5 and mesh.tet_count() == 2
    assert mesh.volume() > 0
    # A lattice with an extra node at index 3 that no tetrahedron uses: the body's rows are
    # the cleaned mesh's, which the report maps back to the arrays given.
    lattice = ts.mesh.lattice_box([0, 0, 0], [0.04, 0.02, 0.02], [4, 2, 2])
    raw_nodes = np.insert(lattice.nodes, 3, [1.0, 1.0, 1.0], axis=0)
    raw_tets = lattice.tets.astype(np.int64)
    raw_tets[raw_tets >= 3] += 1
    mesh, report = ts.mesh.TetMesh.from_raw(raw_nodes, raw_tets)
    assert report.unreferenced_nodes_removed == 1
    kept = report.original_node_index
    assert 3 not in kept.tolist() and len(kept) == lattice.node_count()
    world = ts.World()
    body = world.body(world.add_body(mesh))
    np.testing.assert_array_equal(body.rest_positions(), raw_nodes[kept])


def test_the_default_organ_is_the_documented_one():
    organ = ts.mesh.default_organ()
    assert (organ.node_count(), organ.tet_count()) == (2243, 9918)
    lo, hi = organ.bounding_box()
    assert 0.2 < np.linalg.norm(hi - lo) < 0.3
    assert organ.nodes.dtype == np.float64 and organ.nodes.shape == (2243, 3)


@pytest.mark.parametrize(
    "shape",
    [
        ts.ToolShape.Sphere(0.01),
        ts.ToolShape.Capsule(0.02, 0.005),
        ts.ToolShape.Cylinder(0.02, 0.005),
        ts.ToolShape.Cuboid([0.01, 0.02, 0.005]),
        ts.ToolShape.ConvexHull([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]]),
        ts.ToolShape.TriMesh(
            [[0, 0, 0], [0.02, 0, 0], [0, 0.02, 0], [0, 0, 0.02]],
            [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        ),
        ts.ToolShape.from_obj(MESHES / "liver-smooth.obj", 0.003),
    ],
    ids=lambda s: s.kind,
)
def test_every_tool_shape_presses_the_tissue(shape):
    world = ts.World(ts.Settings(gravity=[0.0, 0.0, 0.0]))
    b = world.add_body(ts.mesh.lattice_box([-0.03, -0.03, -0.03], [0.03, 0, 0.03], [6, 3, 6]))
    world.fix_box(b, [-1, -1, -1], [1, -0.029, 1])
    lo = shape_bottom(shape)
    start = ts.Pose([0.0, 0.003 - lo, 0.0], (1.0, 0.0, 0.0, 0.0))
    tool = world.add_tool(shape, start, ts.ToolOptions(friction_static=0.3, friction_kinetic=0.2))
    assert world.tool(tool).shape().kind == shape.kind
    for k in range(300):
        world.set_tool_pose(tool, start.position - [0.0, 0.008 * min(1.0, k / 150), 0.0])
        world.step()
    w = world.tool(tool).wrench()
    assert w.force[1] > 0.0 and w.contact_count > 0, w
    np.testing.assert_allclose(world.tool(tool).pose().position, start.position - [0, 0.008, 0])
    assert world.tool(tool).options().friction_static == 0.3


def shape_bottom(shape: ts.ToolShape) -> float:
    """Lowest local y of a shape (m)."""
    p = shape.parameters()
    if shape.kind == "Sphere":
        return -p["radius"]
    if shape.kind == "Capsule":
        return -p["half_height"] - p["radius"]
    if shape.kind == "Cylinder":
        return -p["half_height"]
    if shape.kind == "Cuboid":
        return -p["half_extents"][1]
    pts = p.get("points", p.get("vertices"))
    return float(np.min(pts[:, 1]))


def test_settings_mirror_every_rust_field():
    fields = [
        "dt", "gravity", "min_substeps", "crushed_substeps", "max_substeps", "stability_margin",
        "mass_scaling", "damping_mass", "damping_stiffness", "hourglass_stiffness",
        "volume_constraints", "volumetric_split", "volume_scheme", "elastic_scheme",
        "volume_compliance", "iterations", "contact_mode",
        "max_depenetration_speed", "self_contact", "threads", "divergence",
    ]  # fmt: skip
    s = ts.Settings()
    for f in fields:
        assert f"{f}=" in repr(s)
    assert s.dt == 1e-3 and s.gravity == [0.0, -9.81, 0.0]
    assert s.contact_mode == ts.ContactMode.ExactShape
    assert s.volume_scheme == ts.VolumeScheme.DualCells
    assert s.elastic_scheme == ts.ElasticScheme.Tetrahedra
    custom = ts.Settings(
        dt=5e-4,
        threads=2,
        contact_mode=ts.ContactMode.SampledPoints,
        volume_scheme=ts.VolumeScheme.Tetrahedra,
        elastic_scheme=ts.ElasticScheme.PointBased,
        divergence=ts.DivergenceLimits(max_speed=100.0),
    )
    world = ts.World(custom)
    assert world.settings() == custom
    assert world.settings().divergence.max_speed == 100.0
    custom.iterations = 3
    world.set_settings(custom)
    assert world.settings().iterations == 3
    with pytest.raises(TypeError, match="unexpected keyword argument `dtt`"):
        ts.Settings(dtt=1.0)


def test_render_surfaces_follow_the_body(tmp_path):
    world = ts.World()
    b = small_block(world)
    body = world.body(b)
    rm = ts.render.RenderMesh.from_boundary(body.rest_positions(), body.boundary_triangles())
    sid = world.add_render_surface(b, rm)
    surface = world.render_surface(sid)
    assert surface.body() == b
    assert surface.bind_report().outside == 0
    for _ in range(100):
        world.step()
    surface = world.update_render_surface(sid)
    # A boundary surface's vertices are the boundary nodes, in order of first appearance in
    # the triangles: they move exactly with them.
    flat = body.boundary_triangles().ravel()
    _, first = np.unique(flat, return_index=True)
    nodes = flat[np.sort(first)]
    np.testing.assert_allclose(surface.positions(), body.positions()[nodes], atol=1e-12)
    normals = surface.normals()
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-9)
    surface.write_obj(tmp_path / "s.obj")
    surface.write_vtu(tmp_path / "s.vtu")
    back = ts.render.read_obj(tmp_path / "s.obj")
    np.testing.assert_array_equal(back.positions, surface.positions())
    np.testing.assert_array_equal(back.triangles, surface.triangles())


def test_a_shared_model_builds_the_same_body():
    world = ts.World()
    b = small_block(world)
    model = world.body(b).load_time_model()
    other = ts.World()
    c = other.add_body_model(model)
    np.testing.assert_array_equal(other.body(c).rest_positions(), world.body(b).rest_positions())
    built = ts.BodyModel(ts.mesh.lattice_box([0, 0, 0], [0.04, 0.02, 0.02], [4, 2, 2]))
    assert built.particle_count() == model.particle_count()


# --- errors ---------------------------------------------------------------------------------


def test_a_missing_mesh_file_is_an_oserror_naming_it():
    with pytest.raises(OSError, match="no_such_liver.msh") as e:
        ts.mesh.load("/nonexistent/no_such_liver.msh")
    assert isinstance(e.value, ts.MeshError)


def test_a_malformed_mesh_names_the_file_and_line(tmp_path):
    bad = tmp_path / "bad.node"
    bad.write_text("5 3 0 0\n0 0 0 0\n1 1 0 zero\n")
    (tmp_path / "bad.ele").write_text("1 4 0\n0 0 1 2 3\n")
    with pytest.raises(ts.MeshError, match=r"bad.node:3"):
        ts.mesh.load(bad)


def test_bad_arrays_raise_valueerror_with_the_cores_message():
    with pytest.raises(ValueError, match="<arrays>: tetrahedron 0 references node 9"):
        ts.mesh.TetMesh.from_raw([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 1, 2, 9]])
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        ts.mesh.TetMesh([[0, 0], [1, 0]], [[0, 1, 2, 3]])
    with pytest.raises(ValueError, match="integers"):
        ts.mesh.TetMesh([[0, 0, 0]], [[0.5, 1, 2, 3]])


def test_invalid_input_raises_and_leaves_the_world_as_it_was():
    world = ts.World()
    b = small_block(world)
    tool = world.add_tool(ts.ToolShape.Sphere(0.005), [0.02, 0.05, 0.01])
    for _ in range(5):
        world.step()
    saved = world.save_state()

    with pytest.raises(ValueError, match=r"material\.poisson_ratio must be in \[0, 0\.499\]"):
        world.add_body(
            ts.mesh.default_organ(),
            ts.BodyOptions(material=ts.Material(poisson_ratio=0.6)),
        )
    assert world.body_count() == 1
    with pytest.raises(ValueError, match="non-finite input: tool pose"):
        world.set_tool_pose(tool, [np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match="zero quaternion"):
        ts.Pose([0, 0, 0], (0.0, 0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"particle index \d+ out of range"):
        world.fix_particles(b, [0, 10_000])
    assert not world.body(b).fixed_flags().any()
    with pytest.raises(ValueError, match="unknown body id 7"):
        world.body(7)
    with pytest.raises(ValueError, match="unknown tool id 3"):
        world.set_tool_pose(3, [0, 0, 0])
    with pytest.raises(ValueError, match="set_body_state needs"):
        world.set_body_state(b, np.zeros((3, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="cannot restore state"):
        world.restore_state(saved[:-1] + bytes([saved[-1] ^ 1]))
    with pytest.raises(ValueError, match=r"friction"):
        world.set_tool_friction(tool, 0.1, 0.5)
    with pytest.raises(ValueError, match="a blade is a capsule or a cylinder"):
        world.make_blade(tool)
    with pytest.raises(ValueError, match=r"settings\.dt"):
        ts.World(ts.Settings(dt=-1.0))
    with pytest.raises(ValueError, match=r"radius"):
        ts.ToolShape.Sphere(-1.0)
    with pytest.raises(TypeError, match="expected a ToolId"):
        world.tool("probe")
    assert world.save_state() == saved, "nothing changed"


def test_a_diverged_step_raises_and_is_rolled_back():
    world = ts.World(ts.Settings(gravity=[0.0, 0.0, 0.0]))
    b = small_block(world)
    body = world.body(b)
    for _ in range(3):
        world.step()
    x = body.positions()
    # 20 m/s on a 5 cm block: 400 body sizes per second, over the 250 of the speed bound.
    v = np.zeros_like(x)
    v[:, 0] = 20.0
    world.set_body_state(b, x, v)
    saved = world.save_state()
    with pytest.raises(ts.DivergedError, match="step diverged and was rolled back") as e:
        world.step()
    assert isinstance(e.value, RuntimeError)
    assert world.save_state() == saved
    assert world.diverged_steps() == 1


def test_profiling_times_the_stages_and_changes_no_result():
    plain, profiled = ts.World(), ts.World()
    a, b = small_block(plain), small_block(profiled)
    assert profiled.step_profile() is None
    profiled.set_profiling(True)
    for _ in range(5):
        plain.step()
        profiled.step()
    stages = profiled.step_profile()
    assert stages is not None and stages["prediction"] > 0.0 and stages["volume"] > 0.0
    total = stages.pop("total")
    assert sum(stages.values()) <= total * (1 + 1e-9)
    assert np.array_equal(plain.body(a).positions(), profiled.body(b).positions())
    profiled.set_profiling(False)
    assert profiled.step_profile() is None


def test_linear_statics_in_node_order_match_a_slow_settle():
    # The particles carry λ (no volume constraints): the discretisation the linear solve has.
    world = ts.World(ts.Settings(volume_constraints=False))
    b = world.add_body(
        ts.mesh.lattice_box([0, 0, 0], [0.08, 0.02, 0.02], [8, 2, 2]),
        ts.BodyOptions(material=ts.Material(youngs_modulus=2e5)),
    )
    body = world.body(b)
    world.fix_particles(b, np.flatnonzero(body.rest_positions()[:, 0] == 0.0))
    sag = ts.statics.linear_gravity_sag(body, [0.0, -9.81, 0.0])
    assert sag.shape == (body.particle_count(), 3)
    assert np.all(sag[body.fixed_flags()] == 0.0)
    tip = int(np.argmax(body.rest_positions()[:, 0]))
    assert sag[tip, 1] < 0.0, "the free end goes down"
    world.settle()
    u = body.positions() - body.rest_positions()
    # A small sag (stiff block): the nonlinear equilibrium's vertical displacement is close to
    # the linear one's, node for node (so both are in the same order; along x the rotation of
    # the bent block makes them differ).
    assert abs(u[tip, 1] - sag[tip, 1]) < 0.02 * abs(sag[tip, 1])
    assert np.abs(u[:, 1] - sag[:, 1]).max() < 0.02 * np.abs(sag[:, 1]).max()
    load = body.masses()[:, None] * np.array([0.0, -9.81, 0.0])
    same = ts.statics.linear_response(body, load, np.zeros_like(load))
    np.testing.assert_allclose(same, sag, rtol=1e-9, atol=1e-15)


def test_the_constants_are_the_libraries():
    assert ts.MAX_POISSON_RATIO == 0.499 and ts.MIN_POISSON_RATIO == 0.0
    assert ts.YOUNGS_MODULUS_RANGE == (1e-6, 1e12)
    assert ts.statics.SETTLE_SPEED > 0


def test_a_raised_substep_count_is_held_and_saved_with_the_state():
    """A 5 mm sphere on a 6 cm box flattened to 0.4 of its height (tetrahedra longer than the
    probe is wide, below half their volume): two substeps. Lifted away, the steps keep two for
    SUBSTEP_HOLD_STEPS more, then one; a state saved in the hold replays the same."""

    def build():
        world = ts.World(ts.Settings(gravity=[0.0, 0.0, 0.0]))
        b = world.add_body(ts.mesh.lattice_box([0, 0, 0], [0.06, 0.06, 0.06], [6, 6, 6]))
        x = world.body(b).rest_positions() * [1.0, 0.4, 1.0]
        world.set_body_state(b, x, np.zeros_like(x))
        tool = world.add_tool(ts.ToolShape.Sphere(0.005), [0.03, 0.024 + 0.005, 0.03])
        return world, b, tool

    world, b, tool = build()
    assert world.step().substeps == 2
    world.set_tool_pose(tool, [0.03, 1.0, 0.03])
    saved = world.save_state()

    def run(w):
        return [w.step().substeps for _ in range(ts.SUBSTEP_HOLD_STEPS + 4)]

    taken = run(world)
    held = 1 + ts.SUBSTEP_HOLD_STEPS
    assert taken[:held] == [2] * held and taken[held:] == [1] * 3, taken
    restored, _, _ = build()
    restored.restore_state(saved)
    assert run(restored) == taken
    np.testing.assert_array_equal(restored.body(b).positions(), world.body(b).positions())


def test_hostile_inputs_raise_python_errors_never_a_panic():
    """NaN, infinities, huge and negative numbers, wrong types and shapes everywhere: each
    call either works or raises an ordinary exception (a Rust panic would surface as
    ``pyo3_runtime.PanicException``, a ``BaseException``, and fail this test)."""
    world = ts.World()
    b = small_block(world)
    body = world.body(b)
    tool = world.add_tool(ts.ToolShape.Capsule(0.01, 0.002), [0.0, 0.1, 0.0])
    nan, inf = float("nan"), float("inf")
    calls = [
        lambda: world.fix_box(b, [nan, 0, 0], [1, 1, 1]),
        lambda: world.fix_particles(b, [-1]),
        lambda: world.fix_particles(b, [2**40]),
        lambda: world.fix_particles(b, [[0.5]]),
        lambda: world.set_body_state(b, np.full((body.particle_count(), 3), nan), np.zeros(3)),
        lambda: world.set_body_state(b, body.positions() * 1e9, body.velocities()),
        lambda: world.set_tool_pose(
            tool, ts.Pose.interpolate(ts.Pose.at([0, 0, 0]), ts.Pose.at([1, 1, 1]), nan)
        ),
        lambda: world.set_tool_pose(tool, [inf, 0, 0]),
        lambda: world.set_tool_pose(tool, [0, 0]),
        lambda: world.set_tool_pose(tool, "abc"),
        lambda: world.set_tool_friction(tool, nan, 0.0),
        lambda: world.set_body_pair_friction(b, 5, 0.1, 0.1),
        lambda: world.grasp(tool, ts.GraspOptions(reach=-1.0)),
        lambda: world.grasp(tool, ts.GraspOptions(max_force=nan)),
        lambda: world.make_needle(tool, ts.NeedleOptions(puncture_force=inf)),
        lambda: world.needle_state(tool),
        lambda: world.cut(b, ts.Blade(from_=([nan, 0, 0], [0, 0, 0]), to=([0, 0, 0], [1, 0, 0]))),
        lambda: world.tool(tool).signed_distance(ts.Pose.at([0, 0, 0]), [nan, 0, 0]),
        lambda: body.contains([nan, nan, nan]),
        lambda: body.is_fixed(10**6),
        lambda: world.restore_state(b""),
        lambda: world.restore_state(b"\x00" * 64),
        lambda: ts.WorldState.from_bytes(b"garbage"),
        lambda: world.add_render_surface(
            b, ts.render.RenderMesh.from_boundary([[0, 0, 0]], [[0, 0, 5]])
        ),
        lambda: world.render_surface(3),
        lambda: world.update_render_surface(-1),
        lambda: ts.ToolShape.ConvexHull([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]),
        lambda: ts.ToolShape.TriMesh([[0, 0, 0]], [[0, 0, 9]]),
        lambda: ts.ToolShape.Cuboid([1, 1, nan]),
        lambda: ts.ToolShape.Capsule(-1, 1),
        lambda: ts.mesh.lattice_box([0, 0, 0], [1, 1, 1], [10**6, 10**6, 10**6]),
        lambda: ts.mesh.lattice_box([1, 1, 1], [0, 0, 0], [1, 1, 1]),
        lambda: ts.mesh.organ_with_cell(nan),
        lambda: ts.mesh.load("data/meshes/liver_4k.node", -1.0),
        lambda: ts.mesh.load("data/meshes/liver_4k.node", nan),
        lambda: ts.mesh.TetMesh(np.zeros((4, 3)), [[0, 1, 2, 3]]).volume(),
        lambda: world.add_body(ts.mesh.TetMesh(np.zeros((5, 3)), [[0, 1, 2, 3]])),
        lambda: world.add_body(ts.mesh.TetMesh(np.full((5, 3), nan), [[0, 1, 2, 3]])),
        lambda: world.set_settings(ts.Settings(threads=0)),
        lambda: world.set_settings(ts.Settings(dt=inf)),
        lambda: ts.Settings(threads=-1),
        lambda: ts.Settings(gravity=[1, 2]),
        lambda: ts.statics.linear_response(body, np.zeros((2, 3)), np.zeros((2, 3))),
        lambda: ts.statics.linear_gravity_sag(body, [nan, 0, 0]),
        lambda: ts.mesh.write_vtu("/nonexistent/dir/x.vtu", [[0, 0, 0]], [[0, 0, 0, 1]]),
    ]
    for k, call in enumerate(calls):
        try:
            call()
        except (ValueError, TypeError, OSError, IndexError, OverflowError, RuntimeError):
            pass
        except BaseException as e:  # noqa: BLE001 - a panic is what this test looks for
            raise AssertionError(f"call {k} raised {type(e).__name__}: {e}") from e
    for _ in range(10):
        world.step()
    assert np.isfinite(body.positions()).all()


def test_deformation_gradients_and_elastic_forces_pass_the_patch_test():
    world = ts.World()
    b = world.add_body(ts.mesh.default_organ())
    body = world.body(b)
    rest = body.rest_positions()
    np.testing.assert_allclose(body.elastic_forces_at(rest), 0.0, atol=1e-9)
    a = np.array([[1.05, 0.02, 0.0], [0.01, 0.97, 0.03], [0.0, -0.02, 1.01]])
    deformed = rest @ a.T
    for k in (0, 100, 2242):
        np.testing.assert_allclose(body.deformation_gradient_at(deformed, k), a, atol=1e-9)
    forces = body.elastic_forces_at(deformed)
    assert np.abs(forces).max() > 1e-6, "a stretched body pulls back"
    np.testing.assert_allclose(forces.sum(axis=0), 0.0, atol=1e-9 * np.abs(forces).max() * 1e3)
    with pytest.raises(ValueError, match="positions: 2243 nodes, got 3"):
        body.elastic_forces_at(rest[:3])
