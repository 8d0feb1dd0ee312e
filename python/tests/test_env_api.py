# SPDX-License-Identifier: MIT
"""HarvestEnv against Gymnasium's API: every reset succeeds or says why (bounded plant draws, an
impossible scene refused at construction), step() refused before a reset, after the end and
after close(), and a reproduction of the checks of Gymnasium's utils/env_checker.py (and the
passive checker it calls) on every bundled scene, warnings included as failures. Gymnasium
itself is optional (Debian has no package): the checks are written out here."""
import glob
import inspect
import json
import os
from copy import deepcopy

import numpy as np
import pytest

import verdant
from verdant.env import Box, Dict
from conftest import SRC

SCENES = sorted(glob.glob(os.path.join(SRC, "data", "scenes", "*.json")))
PICK = os.path.join(SRC, "data", "scenes", "mini_pick.json")
PULL = os.path.join(SRC, "data", "scenes", "tomato_pull.json")


def scene_text(path, **changes):
    """A scene's JSON text with its relative paths made absolute and top-level keys changed."""
    with open(path) as f:
        s = json.load(f)
    here = os.path.dirname(path)
    s["plant"]["file"] = os.path.join(here, s["plant"]["file"])
    s["robot"]["mjcf"] = os.path.join(here, s["robot"]["mjcf"])
    for k, v in changes.items():
        s[k] = {**s.get(k, {}), **v} if isinstance(v, dict) else v
    return json.dumps(s, indent=1)


# ---- every reset succeeds or says why ------------------------------------------------------

def test_tomato_pull_resets_draw_until_possible():
    # seeds whose first plant draw has no reachable fruit (before bounded draws: BadValueError)
    env = verdant.HarvestEnv(PULL)
    for seed, draws in ((0, 4), (3, 1), (7, 7)):
        obs, info = env.reset(seed=seed)
        assert info["draws"] == draws and obs in env.observation_space
        assert info["target_instance"] > 0
        obs, *_ = env.step(np.zeros(7, np.float32))
        assert obs in env.observation_space
    # the same seed, the same draws and target
    assert env.reset(seed=7)[1]["target_instance"] == info["target_instance"]


def test_impossible_scene_raises_at_construction(tmp_path):
    far = {"base": {"pos": [3.0, 0.0, 0.05], "yaw_deg": 180}}
    robot = json.loads(scene_text(PICK))["robot"]
    # a fixed plant: one draw, then the reason
    text = scene_text(PICK, robot={**robot, **far}, episodes={"plant_seed": False})
    with pytest.raises(verdant.BadValueError, match="no reachable") as e:
        verdant.HarvestEnv(text)
    assert "1 draw " in str(e.value) and "plant_seed" in str(e.value)
    assert "scene (JSON text)" in str(e.value)
    # a new plant per episode: all 32 draws, and the scene file named
    named = tmp_path / "far.json"
    named.write_text(scene_text(PICK, robot={**robot, **far}))
    with pytest.raises(verdant.BadValueError, match="32 draws .* no reachable target fruit") as e:
        verdant.HarvestEnv(named)
    assert e.value.file == str(named) and str(named) in str(e.value)


def test_step_refused_out_of_order():
    env = verdant.HarvestEnv(PICK, max_episode_steps=2)
    a = np.zeros(7, np.float32)
    with pytest.raises(verdant.env.ResetNeeded, match="before a successful reset"):
        env.step(a)
    env.reset(seed=1)
    env.step(a)
    *_, terminated, truncated, info = env.step(a)
    assert truncated and not terminated and info["reason"] == "max_episode_steps"
    with pytest.raises(verdant.env.ResetNeeded, match="after the episode ended"):
        env.step(a)
    env.reset()
    env.step(a)
    env.close()
    with pytest.raises(verdant.env.ResetNeeded, match="closed"):
        env.step(a)
    with pytest.raises(verdant.env.ResetNeeded):
        env.reset(seed=0)
    env.close()                                   # closing twice is fine
    assert isinstance(verdant.env.ResetNeeded("x"), verdant.Error)


def test_spaces():
    b = Box(-1.0, 1.0, (3,), np.float32)
    assert [0, 0.5, -1] in b and [0, 2, 0] not in b and [0, 0] not in b and "x" not in b
    assert np.zeros(3, np.float64) not in b        # does not cast safely to float32
    b.seed(4)
    x = [b.sample() for _ in range(3)]
    b.seed(4)
    assert all(np.array_equal(u, b.sample()) for u in x) and all(u in b for u in x)
    half = Box(0, np.inf, (1000,), np.float64, seed=1).sample()
    assert half.min() >= 0 and half.dtype == np.float64
    ints = Box(0, 1, (1000,), np.int8, seed=2).sample()
    assert set(np.unique(ints)) == {0, 1} and ints.dtype == np.int8
    d = Dict({"a": b, "n": Box(0, 1, (2,), np.int8)}, seed=3)
    s = d.sample()
    assert s in d and d.contains(s) and {"a": s["a"]} not in d and s["a"] not in d
    assert list(d) == ["a", "n"] and d["a"] is b


# ---- Gymnasium's env_checker, reproduced ---------------------------------------------------

def equivalent(a, b):
    """Observations equal within 1e-5, of the same types, keys, shapes and dtypes."""
    if type(a) is not type(b):
        return False
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(equivalent(a[k], b[k]) for k in a)
    if isinstance(a, np.ndarray):
        return a.shape == b.shape and a.dtype == b.dtype and np.allclose(a, b, atol=1e-5)
    return a == b


def check_box(space, kind):
    assert space.low.shape == space.shape and space.high.shape == space.shape, kind
    assert not np.any(space.low == space.high), f"{kind}: a Box with low == high"
    assert not np.any(space.high < space.low), f"{kind}: a Box with low > high"


def check_obs(obs, space, where):
    assert isinstance(obs, dict) and obs.keys() == space.spaces.keys(), where
    for k, sub in space.spaces.items():
        assert isinstance(obs[k], np.ndarray), f"{where}: {k} is not an array"
        assert obs[k].dtype == sub.dtype, f"{where}: {k} is {obs[k].dtype}, not {sub.dtype}"
    assert obs in space, f"{where}: the observation is not in the observation space"


def check_env(env):
    """The checks of gymnasium.utils.env_checker.check_env with its passive checks, in its
    order; each of its warnings is a failure here."""
    assert env.unwrapped is env
    # spaces
    assert isinstance(env.action_space, Box) and isinstance(env.observation_space, Dict)
    check_box(env.action_space, "action")
    assert len(env.observation_space.spaces) > 0
    for sub in env.observation_space.spaces.values():
        check_box(sub, "observation")
    # the seed function is gone; reset takes seed=None and options
    assert not callable(getattr(env, "seed", None))
    sig = inspect.signature(env.reset)
    assert "seed" in sig.parameters and sig.parameters["seed"].default is None
    assert "options" in sig.parameters and "return_info" not in sig.parameters
    # reset's return type
    result = env.reset()
    assert isinstance(result, tuple) and len(result) == 2
    obs, info = result
    assert obs in env.observation_space and isinstance(info, dict)
    # reset with seeds: the same seed, the same observation and generator state
    obs1, _ = env.reset(seed=123)
    assert obs1 in env.observation_space and env.unwrapped._np_random is not None
    rng = deepcopy(env.unwrapped._np_random)
    obs2, _ = env.reset(seed=123)
    assert obs2 in env.observation_space
    if env.spec is not None and env.spec.nondeterministic is False:
        assert equivalent(obs1, obs2)
    assert env.unwrapped._np_random.bit_generator.state == rng.bit_generator.state
    obs3, _ = env.reset(seed=456)
    assert obs3 in env.observation_space
    assert env.unwrapped._np_random.bit_generator.state != rng.bit_generator.state
    env.reset(options={})
    # the passive checks of reset and step
    obs, info = env.reset()
    check_obs(obs, env.observation_space, "reset")
    assert isinstance(info, dict)
    result = env.step(env.action_space.sample())
    assert isinstance(result, tuple) and len(result) == 5
    obs, reward, terminated, truncated, info = result
    assert isinstance(terminated, (bool, np.bool_)) and isinstance(truncated, (bool, np.bool_))
    check_obs(obs, env.observation_space, "step")
    assert np.issubdtype(type(reward), np.floating) or np.issubdtype(type(reward), np.integer)
    assert np.isfinite(reward) and isinstance(info, dict)
    # render modes and fps
    modes = env.metadata.get("render_modes")
    assert isinstance(modes, (list, tuple)) and all(isinstance(m, str) for m in modes)
    fps = env.metadata.get("render_fps")
    assert (np.issubdtype(type(fps), np.integer) or np.issubdtype(type(fps), np.floating)) and fps > 0
    # every declared render mode through the spec, then a second close
    assert env.spec is not None
    for mode in modes:
        other = env.spec.make(render_mode=mode)
        other.reset()
        frame = other.render()
        assert isinstance(frame, np.ndarray) and frame.dtype == np.uint8
        assert frame.ndim == 3 and frame.shape[2] == 3
        other.close()
    other = env.spec.make()
    other.close()
    other.close()


@pytest.mark.parametrize("scene", SCENES, ids=[os.path.basename(s)[:-5] for s in SCENES])
def test_gymnasium_env_checker(scene):
    try:
        verdant.Renderer(size=(8, 8))
    except verdant.UnsupportedError as e:
        pytest.skip(f"no OpenGL context for render(): {e}")
    env = verdant.HarvestEnv(scene, max_episode_steps=5)
    check_env(env)
    assert env.spec.id == "verdant/Harvest-v0"
    env.close()
