"""Calibration on Dask (tissuesim.calibrate): a LocalCluster of 2 workers recovers a known
Young's modulus from a curve recorded here (the documented command), and from the curve with
noise, also when a worker is killed mid-run; bad input is refused with the line or option
named.

The scene is the default organ and probe without gravity (nothing to settle) pressed 5 mm past
first contact: the same fit as the default scene's, at a fraction of its cost.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from tissuesim import calibrate as cal
from tissuesim import indentation as ind
from tissuesim import mesh
from tissuesim.cluster import open_client

TRUE_E = 6810.0
"""The modulus the curves are recorded with (Pa)."""
RANGE = "youngs_modulus=1000:20000"


def quick_scene_toml(directory: Path) -> Path:
    """A scene file: the default scene without gravity (the organ starts at rest)."""
    path = directory / "quick.toml"
    path.write_text("[world]\ngravity = [0.0, 0.0, 0.0]\n")
    return path


def quick_depth(scene: ind.Scene) -> float:
    """Probe travel (m) to 5 mm past first contact with the organ at rest."""
    return ind.first_contact(scene, mesh.default_organ().nodes, scene.probe_radius) + 0.005


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory) -> Path:
    return quick_scene_toml(tmp_path_factory.mktemp("scene"))


@pytest.fixture(scope="module")
def scene(scene_file: Path) -> ind.Scene:
    return ind.load_scene(scene_file)


@pytest.fixture(scope="module")
def curve(scene: ind.Scene) -> ind.Curve:
    """The scene's curve at TRUE_E, every 5th step (0.05 mm)."""
    c = ind.press(scene.with_parameters({"youngs_modulus": TRUE_E}), quick_depth(scene))
    return ind.Curve(c.depth[::5], c.force[::5])


@pytest.fixture(scope="module")
def client():
    with open_client(workers=2) as c:
        yield c


@pytest.fixture(scope="module")
def noisy(curve: ind.Curve) -> ind.Curve:
    """The curve with 2 % Gaussian noise on every force (seeded)."""
    rng = np.random.default_rng(38)
    return ind.Curve(curve.depth, curve.force * (1 + 0.02 * rng.standard_normal(len(curve.force))))


@pytest.fixture(scope="module")
def noisy_fit(client, scene, noisy) -> cal.Fit:
    return cal.calibrate(
        noisy, [cal.parse_range(RANGE)], cal.DaskEvaluator(client, scene, noisy.depth)
    )


def test_the_recorded_curve_presses_and_grows_with_depth(curve):
    touching = curve.force > 0
    assert touching.sum() > 50, "the probe must press for most of the last 5 mm"
    first = np.argmax(touching)
    assert np.all(curve.force[:first] == 0.0)
    assert curve.force[-1] > 0.05 and curve.force[-1] == pytest.approx(curve.force.max(), rel=0.05)


def test_two_workers_recover_the_modulus_from_a_noisy_curve_within_5_percent(noisy_fit, noisy):
    e = noisy_fit.values["youngs_modulus"]
    assert abs(e / TRUE_E - 1) < 0.05, e
    assert noisy_fit.rms < 0.05 * np.abs(noisy.force).max()
    assert not noisy_fit.at_bound


def test_a_worker_killed_mid_run_costs_a_retry_not_the_result(client, scene, noisy, noisy_fit):
    pids = client.run(os.getpid)  # worker address -> process id
    started = threading.Event()
    killed: list[int] = []

    def kill_one_busy_worker() -> None:
        started.wait(60)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            busy = [a for a, keys in client.processing().items() if keys and a in pids]
            if busy:
                time.sleep(0.2)  # inside a simulation
                os.kill(pids[busy[0]], signal.SIGKILL)
                killed.append(pids[busy[0]])
                return
            time.sleep(0.02)

    evaluator = cal.DaskEvaluator(client, scene, noisy.depth)

    def evaluate(candidates):
        started.set()
        return evaluator(candidates)

    killer = threading.Thread(target=kill_one_busy_worker)
    killer.start()
    fit = cal.calibrate(noisy, [cal.parse_range(RANGE)], evaluate)
    killer.join()
    assert killed, "no worker was busy to be killed"
    # Dask ran the lost tasks again on a live worker: the same fit, bit for bit.
    assert fit.values == noisy_fit.values
    assert evaluator.simulations == 13
    client.wait_for_workers(2, timeout=60)
    assert killed[0] not in client.run(os.getpid).values()  # the nanny started a new one


def run_cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "tissuesim.calibrate", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_the_command_on_two_workers_recovers_the_modulus_within_2_percent(
    tmp_path, scene_file, curve
):
    csv = tmp_path / "press.csv"
    ind.write_curve(csv, curve)
    out = run_cli(
        str(csv), "--param", RANGE, "--scene", str(scene_file), "--workers", "2", cwd=tmp_path
    )
    assert out.returncode == 0, out.stderr
    last = out.stdout.strip().splitlines()[-1]
    name, _, rest = last.partition(" = ")
    value, unit = rest.split()
    assert name == "youngs_modulus" and unit == "Pa"
    assert abs(float(value) / TRUE_E - 1) < 0.02
    assert "13/13" in out.stderr  # the progress bar
    png = tmp_path / "press_fit.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("depth_m,force\n0,0\n0.001,0.1\n", r"bad\.csv:1: missing column force_N"),
        ("depth_m,force_N\n0,0\n0.001,nan\n0.002,0.2\n", r"bad\.csv:3: force_N is nan"),
        ("depth_m,force_N\n0,0\n0.002,0.1\n0.001,0.2\n", r"bad\.csv:4: depth_m 0\.001 does not"),
        ("depth_m,force_N\n0,0\n0.001,abc\n", r"bad\.csv:3: force_N is not a number"),
    ],
)
def test_a_bad_curve_is_refused_naming_its_line(tmp_path, capsys, content, message):
    csv = write(tmp_path / "bad.csv", content)
    assert cal.main([str(csv), "--param", RANGE]) == 2
    err = capsys.readouterr().err
    assert err.startswith("calibrate: error: ")
    assert re.search(message, err), err


@pytest.mark.parametrize(
    ("param", "message"),
    [
        ("youngs_modulus=8000:3000", r"--param youngs_modulus=8000:3000: LO \(8000\) must be less"),
        ("youngs_modulus=5000:5000", r"LO \(5000\) must be less than HI \(5000\)"),
        ("stiffness=1:2", r"unknown parameter 'stiffness'"),
        ("youngs_modulus=1000", r"expected NAME=LO:HI"),
        ("poisson_ratio=0.2:0.7", r"poisson_ratio must stay within \[0, 0\.49"),
    ],
)
def test_a_bad_range_is_refused_naming_the_option(tmp_path, capsys, curve, param, message):
    csv = tmp_path / "ok.csv"
    ind.write_curve(csv, curve)
    assert cal.main([str(csv), "--param", param]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err), err


def test_the_command_exits_non_zero_without_a_traceback(tmp_path):
    csv = write(tmp_path / "bad.csv", "depth_m,force_N\n0,0\n0,0.1\n")
    out = run_cli(str(csv), "--param", RANGE, cwd=tmp_path)
    assert out.returncode == 2
    assert "bad.csv:3: depth_m 0 does not increase" in out.stderr
    assert "Traceback" not in out.stderr


def test_a_bad_scene_file_names_the_key(tmp_path, capsys, curve):
    csv = tmp_path / "ok.csv"
    ind.write_curve(csv, curve)
    toml = write(tmp_path / "s.toml", '[probe]\nshape = "sphere"\nradius = -0.01\n')
    assert cal.main([str(csv), "--param", RANGE, "--scene", str(toml)]) == 2
    assert "probe_radius must be > 0" in capsys.readouterr().err
    write(toml, "[probe]\nspeeed = 0.01\n")
    assert cal.main([str(csv), "--param", RANGE, "--scene", str(toml)]) == 2
    assert "unknown key speeed in [probe]" in capsys.readouterr().err


def test_several_parameters_are_found_by_the_box_refinement():
    """The optimiser alone, on curves that depend on E (a scale) and on a shape parameter
    (an exponent standing for ν): both come back, in rounds of a batch along ν (E profiled
    out), then one bracket round on E and the fitted curve."""
    depths = np.linspace(0.0, 0.01, 101)

    def model(c: cal.Candidate) -> np.ndarray:
        return c["youngs_modulus"] / 5000.0 * (depths / 0.01) ** (1.2 + c["poisson_ratio"])

    truth = {"youngs_modulus": 7300.0, "poisson_ratio": 0.31}
    curve = ind.Curve(depths, model(truth))
    ranges = [cal.parse_range("youngs_modulus=1000:20000"), cal.parse_range("poisson_ratio=0:0.45")]
    calls: list[int] = []

    def evaluate(candidates):
        calls.append(len(candidates))
        return [model(c) for c in candidates]

    fit = cal.calibrate(curve, ranges, evaluate)
    assert fit.values["youngs_modulus"] == pytest.approx(7300.0, rel=0.001)
    assert fit.values["poisson_ratio"] == pytest.approx(0.31, abs=0.002)
    assert sum(calls) == cal.planned_simulations(ranges, 4, None)
    assert calls == [4, 4, 4, 4, 4, 1]


def test_a_worker_builds_a_model_and_settles_once_per_material(scene):
    """What each worker process keeps between tasks (tissuesim.indentation's caches)."""
    ind._SETTLED.clear()
    ind._model.cache_clear()
    depth = quick_depth(scene) - 0.004
    soft = scene.with_parameters({"youngs_modulus": 3100.0})
    a = ind.press(soft, depth)
    b = ind.press(soft.with_parameters({"friction_static": 0.5, "friction_kinetic": 0.3}), depth)
    assert (ind._model.cache_info().misses, len(ind._SETTLED)) == (1, 1)  # reused
    assert not np.array_equal(a.force, b.force)  # the friction did change the press
    ind.press(scene.with_parameters({"youngs_modulus": 3200.0}), depth)
    assert (ind._model.cache_info().misses, len(ind._SETTLED)) == (2, 2)  # a new material
    assert np.array_equal(ind.press(soft, depth).force, a.force)  # the same bits from the cache
