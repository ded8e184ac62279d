"""The viewer renders off-screen (under Xvfb, Mesa): the image is not blank and shows the
organ; a GIF has frames."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT

REQUIRED = os.environ.get("TISSUESIM_REQUIRE_VIEW") == "1"
if not REQUIRED:
    pytest.importorskip("pyvista")
imageio = pytest.importorskip("imageio.v3") if not REQUIRED else __import__("imageio.v3").v3


def view(*args: str) -> subprocess.CompletedProcess:
    run = subprocess.run(
        [sys.executable, "-m", "tissuesim.view", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    return run


def organ_pixels(image: np.ndarray) -> float:
    """Share of the pixels in the organ's colour (liver red, shaded)."""
    rgb = image[..., :3].astype(float) / 255.0
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return float(((r > 0.25) & (r > 1.6 * g) & (r > 1.6 * b)).mean())


def test_a_screenshot_shows_the_organ_and_the_probe(tmp_path):
    path = tmp_path / "press.png"
    view("--scenario", "press", "--steps", "300", "--size", "400", "300",
         "--screenshot", str(path))  # fmt: skip
    image = imageio.imread(path)
    assert image.shape[:2] == (300, 400)
    background = (image[..., :3] == 255).all(axis=-1).mean()
    assert background < 0.9, "not blank"
    share = organ_pixels(image)
    assert 0.05 < share < 0.8, f"organ-coloured pixels: {share:.1%}"
    grey = image[..., :3].astype(int)
    tool = (abs(grey[..., 0] - grey[..., 1]) < 12) & (grey[..., 0] > 120) & (grey[..., 0] < 230)
    assert tool.mean() > 0.001, "the probe (grey) is visible"


def test_a_gif_has_one_frame_per_k_steps(tmp_path):
    path = tmp_path / "cut.gif"
    view("--scenario", "cut", "--steps", "100", "--every", "25", "--no-settle",
         "--size", "320", "240", "--gif", str(path))  # fmt: skip
    frames = imageio.imread(path, index=None)
    assert len(frames) >= 4
    assert organ_pixels(frames[-1]) > 0.03


def test_the_live_window_with_the_mouse_probe_runs_and_closes():
    run = view("--scenario", "probe", "--no-settle", "--duration", "2", "--size", "320", "240")
    assert run.stderr.count("Traceback") == 0
