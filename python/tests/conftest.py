"""Shared fixtures: the repository root, and the README's hanging organ at rest (settled once
per session, ~5 s, then restored from its saved state)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tissuesim.scenarios import Scene

ROOT = Path(__file__).resolve().parents[2]
MESHES = ROOT / "data" / "meshes"


@pytest.fixture(scope="session")
def rest_state() -> bytes:
    """``World.save_state`` of the settled scene."""
    return Scene(settle=True).world.save_state()


@pytest.fixture
def scene(rest_state: bytes) -> Scene:
    """A fresh scene at rest in its equilibrium."""
    return Scene(state=rest_state)
