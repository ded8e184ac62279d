"""A Gymnasium-style environment: retract tissue with a grasper.

The README's main scene (the default organ hanging from its top 15 %, at rest): a 5 mm
grasper holds the organ's front face (``World.grasp``) and must pull the grasped tissue
``RETRACTION`` (3 cm) out along +z without tearing it loose (the grasp slips beyond
``MAX_FORCE``).

- observation (6,), float32: the grasped point's displacement from where it was grasped (m,
  3 values) and the force of the tissue on the grasper (N, 3 values);
- action (3,), float32: the grasper's velocity (m/s), each component in [-0.05, 0.05];
- reward: minus the distance (m) of the grasped point to its target, times 100, minus 0.01
  per newton of pull; -10 and the end when the tissue slips out;
- an env step is 10 solver steps (10 ms); an episode ends at the target (within 2 mm) or
  after 200 steps (truncated).

    python python/examples/retract_env.py     # one episode with a proportional controller

Uses gymnasium's ``Env`` and spaces when gymnasium is installed (``pip install gymnasium``),
and works the same without it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

import tissuesim as ts
from tissuesim.scenarios import Scene

try:
    import gymnasium as gym
    from gymnasium import spaces

    _Base = gym.Env
except ImportError:  # pragma: no cover - the env works without gymnasium
    gym = None
    spaces = None
    _Base = object

RETRACTION = 0.03
"""How far (m) the grasped tissue must be pulled out along +z."""
MAX_SPEED = 0.05
"""Largest grasper speed per axis (m/s)."""
MAX_FORCE = 4.0
"""The grasp slips beyond this pull (N)."""
SOLVER_STEPS = 10
"""Solver steps (1 ms each) per env step."""
MAX_EPISODE_STEPS = 200


class RetractEnv(_Base):
    """Retract the organ's front face with a grasper (see the module docstring)."""

    metadata = {"render_modes": []}
    _rest_state: bytes | None = None

    def __init__(self) -> None:
        if spaces is not None:
            # Displacements within ±1 m, forces within ±100 N (the grasp slips at 4 N).
            high = np.array([1.0, 1.0, 1.0, 100.0, 100.0, 100.0], dtype=np.float32)
            self.observation_space = spaces.Box(-high, high, dtype=np.float32)
            self.action_space = spaces.Box(-MAX_SPEED, MAX_SPEED, shape=(3,), dtype=np.float32)
        # Settle once per process: every episode starts from the same hanging organ.
        if RetractEnv._rest_state is None:
            RetractEnv._rest_state = Scene(settle=True).world.save_state()
        self.scene: Scene | None = None

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        if gym is not None:
            super().reset(seed=seed)
        scene = Scene(state=RetractEnv._rest_state)
        world = scene.world
        face = scene.front_face_z(0.035, 0.0)
        r = scene.body().particle_radius()
        self.start = np.array([0.035, 0.0, face + r + 0.004])
        self.jaws = world.add_tool(ts.ToolShape.Sphere(0.005), ts.Pose.at(self.start))
        options_ = ts.GraspOptions(max_force=MAX_FORCE)
        world.grasp(self.jaws, options_)
        # The grasped nodes: those within the grasp's reach (1.5 particle radii) of the
        # jaws' surface, as World.grasp chooses them (the Rust API does not list them).
        x = scene.body().positions()
        reach = 1.5 * r
        self.held = np.flatnonzero(np.linalg.norm(x - self.start, axis=1) - 0.005 <= reach)
        self.grasped_at = x[self.held].mean(axis=0)
        self.target = self.grasped_at + [0.0, 0.0, RETRACTION]
        self.scene = scene
        self.steps = 0
        return self._observation(), {"held": int(world.grasped_count(self.jaws))}

    def _grasped_point(self) -> np.ndarray:
        return self.scene.body().positions()[self.held].mean(axis=0)

    def _observation(self) -> np.ndarray:
        force = self.scene.world.tool(self.jaws).wrench().force
        offset = self._grasped_point() - self.grasped_at
        return np.concatenate([offset, force]).astype(np.float32)

    def step(self, action):
        world = self.scene.world
        v = np.clip(np.asarray(action, dtype=float), -MAX_SPEED, MAX_SPEED)
        for _ in range(SOLVER_STEPS):
            here = world.tool(self.jaws).target_pose().position
            world.set_tool_pose(self.jaws, here + v * world.settings().dt)
            world.step()
        self.steps += 1
        obs = self._observation()
        held = world.grasped_count(self.jaws)
        distance = float(np.linalg.norm(self._grasped_point() - self.target))
        pull = float(np.linalg.norm(obs[3:]))
        reward = -100.0 * distance - 0.01 * pull
        terminated = False
        if held == 0:
            reward, terminated = -10.0, True
        elif distance < 0.002:
            terminated = True
        truncated = not terminated and self.steps >= MAX_EPISODE_STEPS
        info = {"held": int(held), "distance": distance}
        return obs, float(reward), terminated, truncated, info


def proportional_policy(env: RetractEnv, obs: np.ndarray) -> np.ndarray:
    """Move the grasper towards where the grasped point should go (gain 5/s)."""
    error = (env.target - env.grasped_at) - obs[:3]
    return np.clip(5.0 * error, -MAX_SPEED, MAX_SPEED).astype(np.float32)


if __name__ == "__main__":
    env = RetractEnv()
    obs, info = env.reset(seed=0)
    print(f"grasped {info['held']} particles")
    total, done = 0.0, False
    while not done:
        obs, reward, terminated, truncated, info = env.step(proportional_policy(env, obs))
        total += reward
        done = terminated or truncated
    print(
        f"{env.steps} steps, return {total:.2f}, distance to target {1e3 * info['distance']:.1f}"
        f" mm, pull {np.linalg.norm(obs[3:]):.3f} N, still held: {info['held'] > 0}"
    )
