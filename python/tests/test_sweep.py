"""Parameter sweeps on Dask (tissuesim.sweep): the command writes a CSV and a plot of a grid
whose forces grow with E; the FMU (through fmpy) and the package give the same curves; a bad
axis is refused naming the option.

The scene is the default organ and probe without gravity, pressed 4 mm past first contact.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT
from tissuesim import indentation as ind
from tissuesim import mesh, sweep
from tissuesim.cluster import open_client


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("scene") / "quick.toml"
    path.write_text("[world]\ngravity = [0.0, 0.0, 0.0]\n")
    return path


@pytest.fixture(scope="module")
def depth(scene_file: Path) -> float:
    """Probe travel (m) to 4 mm past first contact."""
    scene = ind.load_scene(scene_file)
    return ind.first_contact(scene, mesh.default_organ().nodes, scene.probe_radius) + 0.004


def fmu_file() -> Path:
    """The FMU that fmu/test.sh builds (run before this suite by scripts/test_all.sh)."""
    if os.environ.get("TISSUESIM_FMU"):
        return Path(os.environ["TISSUESIM_FMU"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return (target if target.is_absolute() else ROOT / target) / "fmu" / "TissueSim.fmu"


def test_the_command_writes_the_grid_as_csv_and_png(tmp_path, scene_file, depth):
    out_csv, out_png = tmp_path / "grid.csv", tmp_path / "grid.png"
    args = ["--param", "youngs_modulus=3000:9000:3", "--param", "friction_static=0.2,0.4"]
    args += ["--scene", str(scene_file), "--depth", repr(depth), "--workers", "2"]
    args += ["--csv", str(out_csv), "--plot", str(out_png), "--no-progress"]
    assert sweep.main(args) == 0
    with open(out_csv, newline="") as f:
        rows = list(csv.DictReader(f))
    samples = round(depth / 1e-4) + 1
    assert len(rows) == 6 * samples
    assert list(rows[0]) == ["youngs_modulus", "friction_static", "depth_m", "force_N"]
    last = {
        (float(r["youngs_modulus"]), float(r["friction_static"])): float(r["force_N"])
        for r in rows
        if float(r["depth_m"]) == pytest.approx(depth)
    }
    assert len(last) == 6
    for mu in (0.2, 0.4):
        forces = [last[(e, mu)] for e in (3000.0, 6000.0, 9000.0)]
        assert 0.0 < forces[0] < forces[1] < forces[2], forces  # stiffer pushes back harder
    assert out_png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_fmu_and_the_package_give_the_same_curves(scene_file, depth):
    fmu = fmu_file()
    if not fmu.is_file():
        pytest.skip(f"{fmu} not built (fmu/test.sh builds it; scripts/test_all.sh runs it first)")
    scene = ind.load_scene(scene_file)
    points = [{"youngs_modulus": 4000.0}, {"youngs_modulus": 8000.0}]
    depths = np.linspace(0.0, depth, 101)
    with open_client(workers=2) as client:
        by_fmu = sweep.run(client, scene, points, depths, fmu=str(fmu), step=scene.dt)
        by_package = sweep.run(client, scene, points, depths)
    for f, p in zip(by_fmu, by_package):
        assert p[-1] > 0.05
        # One internal step per communication step: the same world, stepped the same way.
        np.testing.assert_allclose(f, p, rtol=1e-6, atol=1e-9 * p[-1])


@pytest.mark.parametrize(
    ("param", "message"),
    [
        ("youngs_modulus=8000:3000:3", "--param youngs_modulus=8000:3000:3: needs LO < HI"),
        ("youngs_modulus=3000:8000", "expected NAME=LO:HI:N or NAME=V1,V2,..."),
        ("poisson_ratio=0.3,0.6", "poisson_ratio must be in [0, 0.49"),
        ("stiffness=1,2", "unknown parameter 'stiffness'"),
    ],
)
def test_a_bad_axis_is_refused_naming_the_option(capsys, param, message):
    assert sweep.main(["--param", param]) == 2
    err = capsys.readouterr().err
    assert err.startswith("sweep: error: ") and message in err, err
