"""The example environment (python/examples/retract_env.py) runs an episode."""

from __future__ import annotations

import importlib.util
import os

import numpy as np
import pytest

from conftest import ROOT

if os.environ.get("TISSUESIM_REQUIRE_VIEW") != "1":
    pytest.importorskip("gymnasium")
import gymnasium  # noqa: E402
from gymnasium.utils.env_checker import check_env  # noqa: E402

spec = importlib.util.spec_from_file_location(
    "retract_env", ROOT / "python" / "examples" / "retract_env.py"
)
retract_env = importlib.util.module_from_spec(spec)
spec.loader.exec_module(retract_env)


@pytest.fixture(scope="module")
def env():
    return retract_env.RetractEnv()


def test_it_is_a_gymnasium_env(env):
    assert isinstance(env, gymnasium.Env)
    check_env(env, skip_render_check=True)


def test_an_episode_retracts_the_tissue_to_the_target(env):
    obs, info = env.reset(seed=0)
    assert obs.shape == (6,) and obs.dtype == np.float32
    assert info["held"] == len(env.held) > 0, "the grasped nodes are the ones World.grasp held"
    assert np.allclose(obs[:3], 0.0, atol=1e-6)
    total, steps, done = 0.0, 0, False
    while not done:
        action = retract_env.proportional_policy(env, obs)
        assert env.action_space.contains(action)
        obs, reward, terminated, truncated, info = env.step(action)
        total += reward
        steps += 1
        done = terminated or truncated
    assert terminated and not truncated, info
    assert info["held"] > 0, "the tissue did not slip out"
    assert info["distance"] < 0.002
    assert obs[2] > 0.02, "the grasped point came out by 2-3 cm"
    assert obs[5] < 0.0, "the tissue pulls the grasper back"
    assert np.isfinite(total) and steps < retract_env.MAX_EPISODE_STEPS


def test_pulling_too_hard_tears_the_tissue_loose(env):
    obs, _ = env.reset(seed=1)
    for _ in range(retract_env.MAX_EPISODE_STEPS):
        obs, reward, terminated, truncated, info = env.step(np.array([0.05, 0, 0], np.float32))
        if terminated or truncated:
            break
    # Dragging the tissue sideways at full speed pulls beyond the grasp's 4 N: it slips.
    assert terminated and info["held"] == 0 and reward == -10.0
