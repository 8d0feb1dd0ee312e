# SPDX-License-Identifier: MIT
"""verdant.VectorHarvestEnv: N harvest episodes stepped in native threads inside one call, with
Gymnasium's vector API (reset(seed=...) -> (observations, infos), step(actions) ->
(observations, rewards, terminations, truncations, infos), arrays (num_envs, ...)).

    envs = verdant.VectorHarvestEnv("data/scenes/mini_pick.json", num_envs=8, threads=2)
    obs, infos = envs.reset(seed=0)                  # environment i: seed 0 + i
    for _ in range(100):
        obs, rewards, terminated, truncated, infos = envs.step(envs.action_space.sample())

The environments are HarvestEnv's (the same reward, ending rules and state observation, one
piece of C shared by both: python/src/py_harvest.c), stepped by verdant._verdant.VectorHarvest
(py_vector.c) on `threads` POSIX threads without the GIL: no Python runs per environment per
step. Autoreset follows Gymnasium's "next step" mode: the step after an environment's episode
ended starts its next episode (its observation is the reset's, reward 0, neither terminated nor
truncated, infos["autoreset"] true). Environment i runs episodes 0, 1, 2, ... of its own seed,
the same episodes as HarvestEnv.reset(seed=s) then reset() (each reset draws plants until a
fruit is reachable, as HarvestEnv's does). Pictures and clouds are not batched: the state
observation only.
"""
import numpy as np

from . import _verdant
from .env import REWARD_WEIGHTS, Box, Dict, _action_space, _gym, _state_spaces

_VecBase = _gym.vector.VectorEnv if _gym is not None else object


def _batched(space, n):
    """Box (n, *shape) of a Box, or a Dict of those."""
    if isinstance(space, Dict):
        return Dict({k: _batched(s, n) for k, s in space.spaces.items()})
    return Box(np.broadcast_to(space.low, (n,) + space.shape),
               np.broadcast_to(space.high, (n,) + space.shape), (n,) + space.shape, space.dtype)


class VectorHarvestEnv(_VecBase):
    """VectorHarvestEnv(scene, num_envs=1, threads=1, *, max_lin_vel=0.1, max_ang_vel=1.0,
    reward_weights=None, max_episode_steps=None, randomize=True, terminate_on_detach=True)

    num_envs episodes of scene (HarvestEnv's keywords) stepped on `threads` native threads.
    single_action_space / single_observation_space are one environment's (HarvestEnv's state
    observation); action_space and observation_space the batched ones (num_envs, ...).
    reset(seed=s) seeds environment i with s + i (a list gives each its own seed; None draws
    them from np_random). infos: episode, seed, target_instance, draws, time, autoreset,
    reward_terms (num_envs, 7: detach, grasp, distance, pull_force, fracture, drop, hit), and
    reason with its mask _reason where an episode ended.
    """

    metadata = {"autoreset_mode": "NextStep", "render_modes": []}

    def __init__(self, scene, num_envs=1, threads=1, *, max_lin_vel=0.1, max_ang_vel=1.0,
                 reward_weights=None, max_episode_steps=None, randomize=True,
                 terminate_on_detach=True):
        unknown = set(reward_weights or {}) - set(REWARD_WEIGHTS)
        if unknown:
            raise _verdant.ArgumentError(f"reward_weights: unknown terms {sorted(unknown)}")
        weights = {**REWARD_WEIGHTS, **(reward_weights or {})}
        self._v = _verdant.VectorHarvest(
            scene, num_envs, threads, tuple(float(weights[k]) for k in REWARD_WEIGHTS),
            terminate_on_detach=terminate_on_detach, max_steps=max_episode_steps,
            randomize=randomize)
        self.scene = scene
        self.render_mode = None
        self.num_envs, self.threads = int(num_envs), int(threads)
        self.control_dt = self._v.control_dt
        self.single_action_space = _action_space(max_lin_vel, max_ang_vel)
        self.action_space = _batched(self.single_action_space, self.num_envs)
        self.single_observation_space = Dict(_state_spaces(self._v.nq))
        self.observation_space = _batched(self.single_observation_space, self.num_envs)
        self._np_random = None
        self._np_random_seed = None
        self._closed, self._started = False, False

    @property
    def np_random(self):
        """The generator behind seed=None resets (seeded by reset(seed=...))."""
        if self._np_random is None:
            self._np_random = np.random.default_rng()
        return self._np_random

    @property
    def unwrapped(self):
        """The environment itself (no wrappers)."""
        return self

    def reset(self, *, seed=None, options=None):
        """Episode 0 of each environment's seed: s + i for seed=s, seed[i] for a list, drawn
        from np_random for None. Returns (observations, infos)."""
        if self._closed:
            raise _closed_error()
        n = self.num_envs
        if seed is None:
            seeds = [int(s) for s in self.np_random.integers(2 ** 31, size=n)]
        elif isinstance(seed, (list, tuple, np.ndarray)):
            seeds = [int(s) for s in seed]
        else:
            seeds = [int(seed) + i for i in range(n)]
            self._np_random, self._np_random_seed = np.random.default_rng(int(seed)), int(seed)
            self.action_space.seed(int(seed))
            self.single_action_space.seed(int(seed))
        self._started = False
        out = self._v.reset(seeds)
        self._started = True
        return out

    def step(self, actions):
        """One step of every environment under actions (num_envs, 7), clipped to the action
        space. Returns (observations, rewards, terminations, truncations, infos)."""
        if self._closed:
            raise _closed_error()
        if not self._started:
            from .env import ResetNeeded

            raise ResetNeeded("step() before a successful reset(): call reset() first")
        a = np.asarray(actions, dtype=np.float64)
        if a.shape != (self.num_envs, 7):
            raise _verdant.ArgumentError(f"actions: shape ({self.num_envs}, 7), got {a.shape}")
        a = np.clip(a, self.single_action_space.low, self.single_action_space.high)
        return self._v.step(a)

    def render(self):
        """Nothing: the vector environment draws no pictures (render_mode None)."""
        return None

    def close(self, **kwargs):
        """Free every episode; calling it again is fine."""
        if not self._closed:
            self._v.close()
        self._closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __repr__(self):
        return (f"<verdant.VectorHarvestEnv {self.scene}: {self.num_envs} envs on "
                f"{self.threads} threads>")


def _closed_error():
    from .env import ResetNeeded

    return ResetNeeded("a closed VectorHarvestEnv: make a new one")
