"""Physical facts through the Python API: sag, volume, contact force, grasp, cut, needle,
save/restore bits, thread-count determinism."""

from __future__ import annotations

import math

import numpy as np

import tissuesim as ts
from tissuesim import scenarios


def hanging_world(settings: ts.Settings | None = None):
    world = ts.World(settings)
    organ = world.add_body(ts.mesh.default_organ())
    x = world.body(organ).positions()
    lo, hi = x.min(axis=0), x.max(axis=0)
    top = hi[1] - 0.15 * (hi[1] - lo[1])
    fixed = world.fix_box(organ, [lo[0] - 1, top, lo[2] - 1], hi + 1)
    return world, organ, fixed


def test_the_organ_sags_under_gravity_and_keeps_its_volume():
    world, organ, fixed = hanging_world()
    body = world.body(organ)
    assert 0 < fixed < body.particle_count()
    low0 = body.positions()[:, 1].min()
    for _ in range(300):
        world.step()
    x = body.positions()
    assert math.isclose(world.time(), 0.3, rel_tol=1e-9)
    assert np.isfinite(x).all()
    assert x[:, 1].min() < low0 - 0.005, "the lowest point falls by more than 5 mm"
    assert body.max_displacement() > 0.005
    assert abs(body.volume_ratio() - 1.0) < 0.02
    # Fixed nodes do not move.
    flags = body.fixed_flags()
    assert flags.sum() == fixed
    np.testing.assert_array_equal(x[flags], body.rest_positions()[flags])


def test_settle_brings_the_organ_to_rest_in_its_sag(scene):
    body = scene.body()
    assert np.abs(body.velocities()).max() == 0.0
    assert body.max_displacement() > 0.01
    assert abs(body.volume_ratio() - 1.0) < 0.02
    before = body.positions()
    for _ in range(50):
        scene.world.step()
    assert np.abs(body.positions() - before).max() < 1e-4, "it stays where settle left it"


def test_a_probe_pressed_in_is_pushed_back_harder_the_deeper(scene):
    forces = {}
    for k in scenarios.press(scene, depth=0.02, steps=600):
        if k in (299, 599):
            forces[k] = scene.world.tool(scene.active_tool).wrench()
    shallow, deep = forces[299], forces[599]
    # The probe moved in along -z: the tissue pushes it back along +z.
    assert deep.force[2] > 0.1
    assert deep.force[2] > shallow.force[2] > 0.0
    assert deep.contact_count > 0
    # Its centre never got inside the organ.
    centre = scene.world.tool(scene.active_tool).pose().position
    assert not scene.body().contains(centre)
    assert abs(scene.body().volume_ratio() - 1.0) < 0.02


def test_a_grasp_holds_and_lifts_the_tissue_and_lets_go(scene):
    body = scene.body()
    before = body.positions()
    steps = scenarios.grasp(scene, pull=0.02, steps=600)
    next(steps)
    jaws = scene.active_tool
    held = scene.world.grasped_count(jaws)
    assert held > 0
    for _ in steps:
        pass
    after = body.positions()
    moved = after[:, 2] - before[:, 2]
    # The held tissue came out with the jaws (2 cm), compliantly.
    assert moved.max() > 0.4 * 0.02
    # The tissue pulls the jaws back towards the organ.
    assert scene.world.tool(jaws).wrench().force[2] < -0.05
    assert scene.world.grasped_count(jaws) == held
    scene.world.release(jaws)
    assert scene.world.grasped_count(jaws) == 0
    for _ in range(300):
        scene.world.step()
    assert body.positions()[:, 2].max() < after[:, 2].max() - 0.005, "released, it springs back"


def test_a_grasped_cube_is_lifted_and_pulls_with_its_weight():
    world = ts.World(ts.Settings(damping_mass=20.0))
    cube = world.add_body(ts.mesh.lattice_box([-0.02, -0.02, -0.02], [0.02, 0.02, 0.02], [4, 4, 4]))
    body = world.body(cube)
    top = np.array([0.0, 0.02 + 0.004, 0.0])
    jaws = world.add_tool(ts.ToolShape.Sphere(0.006), ts.Pose.at(top))
    assert world.grasp(jaws, ts.GraspOptions(reach=0.006)) > 0
    y0 = body.positions()[:, 1].mean()
    for k in range(1500):
        world.set_tool_pose(jaws, top + [0.0, 0.02 * min(1.0, k / 500), 0.0])
        world.step()
    assert body.positions()[:, 1].mean() > y0 + 0.01, "lifted with the tool"
    weight = body.mass() * 9.81
    force = world.tool(jaws).wrench().force
    assert abs(-force[1] - weight) < 0.05 * weight, (force, weight)


def test_a_cut_changes_the_topology_and_the_piece_below_falls(scene):
    body = scene.body()
    tets0 = len(body.tets())
    boundary0 = len(body.boundary_triangles())
    mass0 = body.mass()
    x0 = body.positions()
    low = x0[:, 1].min()
    below = x0[:, 1] < low + 0.03
    steps = scenarios.cut(scene, height=0.03, stroke=40, steps=340)
    for _ in steps:
        pass
    pairs, removed = body.cut_counts()
    assert pairs > 0 and removed > 0
    assert len(body.tets()) == tets0 - removed
    assert len(body.boundary_triangles()) > boundary0, "the cut faces became boundary"
    assert body.mass() == mass0, "cutting removes no mass"
    x = body.positions()
    assert np.isfinite(x).all()
    fell = x0[below, 1].mean() - x[below, 1].mean()
    assert fell > 0.05, f"the piece below the cut fell {fell:.3f} m in 0.3 s"
    above = x0[:, 1] > low + 0.06
    assert np.abs(x[above] - x0[above]).max() < 0.02, "the organ above stays"


def test_a_needle_punctures_and_goes_in():
    world = ts.World()
    box = world.add_body(ts.mesh.lattice_box([-0.03, -0.03, -0.03], [0.03, 0.03, 0.03], [6, 6, 6]))
    world.fix_box(box, [-1, -1, -1], [1, -0.029, 1])
    world.set_settings(ts.Settings(gravity=[0.0, 0.0, 0.0]))
    # A capsule along local y, tip at +y: pointing down onto the top face.
    down = (0.0, 0.0, 0.0, 1.0)  # half a turn about z: local +y to world -y
    needle = world.add_tool(ts.ToolShape.Capsule(0.02, 0.001), ts.Pose([0.001, 0.055, 0.001], down))
    world.make_needle(needle, ts.NeedleOptions(puncture_force=0.2))
    assert not world.needle_state(needle).punctured
    for k in range(600):
        world.set_tool_pose(needle, ts.Pose([0.001, 0.055 - 0.04 * (k + 1) / 600, 0.001], down))
        world.step()
    state = world.needle_state(needle)
    assert state.punctured
    assert state.inserted_length > 0.005
    assert state.held > 0


def test_save_restore_reproduces_the_same_bits(scene):
    world = scene.world
    start = np.array([0.0, 0.0, scene.front_face_z(0.0, 0.0) + 0.012])
    probe = world.add_tool(ts.ToolShape.Sphere(0.01), ts.Pose.at(start))

    def press(k: int) -> None:
        world.set_tool_pose(probe, start - [0.0, 0.0, 0.02 * min(1.0, k / 200)])
        world.step()

    for k in range(100):
        press(k)
    saved, as_value = world.save_state(), world.state()
    assert len(saved) == world.state_size() == as_value.byte_size()
    assert as_value.to_bytes() == saved
    for k in range(100, 300):
        press(k)
    x1, v1 = scene.body().positions(), scene.body().velocities()
    f1 = world.tool(probe).wrench().force
    after1 = world.save_state()
    assert f1[2] > 0.0

    for restore in (lambda: world.restore_state(saved), lambda: world.set_state(as_value)):
        restore()
        assert world.save_state() == saved
        for k in range(100, 300):
            press(k)
        np.testing.assert_array_equal(scene.body().positions(), x1)
        np.testing.assert_array_equal(scene.body().velocities(), v1)
        np.testing.assert_array_equal(world.tool(probe).wrench().force, f1)
        assert world.save_state() == after1
    assert ts.WorldState.from_bytes(saved) == as_value


def test_any_thread_count_gives_the_same_bits():
    def run(threads: int) -> np.ndarray:
        world, organ, _ = hanging_world(ts.Settings(threads=threads))
        for _ in range(100):
            world.step()
        return world.body(organ).positions()

    np.testing.assert_array_equal(run(1), run(2))
