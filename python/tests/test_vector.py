# SPDX-License-Identifier: MIT
"""VectorHarvestEnv: N environments stepped in native threads are the same N HarvestEnvs stepped
one by one (observations, rewards and endings bit for bit, autoreset included), whatever the
thread count; batched spaces; errors."""
import os

import numpy as np
import pytest

import verdant
from conftest import SRC

PICK = os.path.join(SRC, "data", "scenes", "mini_pick.json")


def run_vector(n, threads, seeds, actions, steps):
    envs = verdant.VectorHarvestEnv(PICK, num_envs=n, threads=threads, max_episode_steps=4)
    obs, info = envs.reset(seed=list(seeds))
    assert obs in envs.observation_space and info["episode"].tolist() == [0] * n
    out = [obs]
    for t in range(steps):
        o, r, term, trunc, info = envs.step(actions[t])
        assert o in envs.observation_space and r.shape == (n,) and term.dtype == bool
        out.append((o, r, term, trunc, info["autoreset"].copy(), info["episode"].copy()))
    envs.close()
    return out


def test_vector_equals_single_envs():
    n, steps, seeds = 3, 6, (5, 6, 7)
    rng = np.random.default_rng(0)
    single = verdant.HarvestEnv(PICK, max_episode_steps=4).action_space
    actions = [np.stack([single.low + (single.high - single.low) * rng.random(7)
                         for _ in range(n)]) for _ in range(steps)]
    vec = run_vector(n, 2, seeds, actions, steps)
    for i, seed in enumerate(seeds):
        env = verdant.HarvestEnv(PICK, max_episode_steps=4)
        obs, _ = env.reset(seed=seed)
        assert all(np.array_equal(obs[k], vec[0][k][i]) for k in obs)
        ended = False
        for t in range(steps):
            o, r, term, trunc, reset, episode = vec[t + 1]
            if ended:          # next-step autoreset: the next episode's first observation
                obs, _ = env.reset()
                assert reset[i] and r[i] == 0 and not term[i] and not trunc[i] and episode[i] == 1
                ended = False
            else:
                obs, reward, terminated, truncated, _ = env.step(actions[t][i])
                assert not reset[i] and r[i] == reward
                assert term[i] == terminated and trunc[i] == truncated
                ended = terminated or truncated
            assert all(np.array_equal(obs[k], o[k][i]) for k in obs), (i, t)
        assert any(vec[t + 1][3][i] for t in range(steps))      # max_episode_steps ended one


def test_threads_do_not_change_results():
    actions = [np.tile([0.05, 0, -0.02, 0, 0, 0.1, 0.5], (4, 1)) for _ in range(3)]
    a = run_vector(4, 1, range(4), actions, 3)
    b = run_vector(4, 3, range(4), actions, 3)
    for x, y in zip(a[1:], b[1:]):
        assert all(np.array_equal(x[0][k], y[0][k]) for k in x[0]) and np.array_equal(x[1], y[1])


def test_vector_api_and_errors():
    envs = verdant.VectorHarvestEnv(PICK, num_envs=2, threads=2)
    assert envs.action_space.shape == (2, 7) and envs.single_action_space.shape == (7,)
    assert envs.observation_space["q"].shape == (2, envs.single_observation_space["q"].shape[0])
    assert envs.metadata["autoreset_mode"] == "NextStep"
    with pytest.raises(verdant.env.ResetNeeded):
        envs.step(np.zeros((2, 7)))
    obs, info = envs.reset(seed=3)
    assert info["seed"].tolist() == [3, 4] and info["draws"].min() >= 1
    a = envs.action_space.sample()
    assert a in envs.action_space and a.shape == (2, 7)
    for bad in (np.zeros((3, 7)), np.zeros(7), np.full((2, 7), np.nan)):
        with pytest.raises(verdant.ArgumentError):
            envs.step(bad)
    obs, r, term, trunc, info = envs.step(a)
    assert info["reward_terms"].shape == (2, 7)
    assert np.allclose(info["reward_terms"].sum(axis=1), r)
    envs.close()
    envs.close()
    with pytest.raises(verdant.env.ResetNeeded):
        envs.step(a)
    with pytest.raises(verdant.ArgumentError):
        verdant.VectorHarvestEnv(PICK, num_envs=0)
