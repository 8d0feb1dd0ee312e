# SPDX-License-Identifier: MIT
"""State you can keep: Sim.get_state()/set_state() resume exactly (the same future as not
stopping, in the same Sim or a new one), HarvestEnv.get_state()/set_state() and pickling of
environments, plants and clouds (for multiprocessing and Ray/Dask-style workers)."""
import os
import pickle

import numpy as np
import pytest

import verdant
from conftest import SRC, data

PICK = os.path.join(SRC, "data", "scenes", "mini_pick.json")


@pytest.fixture(scope="module")
def tomato():
    return verdant.grow(data("tomato.lpy"), seed=3)


def sim_with_things(plant):
    s = verdant.Sim(plant, fracture=True)
    ball = s.add_collider("sphere", 0.03, pos=(0.25, 0.0, 0.3))
    n = s.find_organ("fruit")
    s.add_tie(n, tuple(s.node_pos[n] + [0.0, 0.0, -0.01]), compliance=1e-3)
    return s, ball


def state_arrays(s):
    return [s.node_pos.copy(), s.node_vel.copy(), s.seg_quat.copy(), s.seg_omega.copy(),
            s.seg_broken.copy(), np.array([s.time, s.nstep])]


def test_sim_state_resumes_exactly(tomato):
    s, ball = sim_with_things(tomato)
    s.step(30)
    st = s.get_state()
    assert isinstance(st, bytes)
    for k in range(20):
        s.move_collider(ball, (0.25 - 0.002 * k, 0.0, 0.3))
        s.step(2)
    ref = state_arrays(s)
    # the same Sim, back in time
    s.set_state(st)
    for k in range(20):
        s.move_collider(ball, (0.25 - 0.002 * k, 0.0, 0.3))
        s.step(2)
    assert all(np.array_equal(a, b) for a, b in zip(ref, state_arrays(s)))
    # a new Sim of the same plant and options
    t, _ = sim_with_things(tomato)
    t.set_state(st)
    for k in range(20):
        t.move_collider(ball, (0.25 - 0.002 * k, 0.0, 0.3))
        t.step(2)
    assert all(np.array_equal(a, b) for a, b in zip(ref, state_arrays(t)))
    assert t.get_state() == s.get_state()


def test_sim_state_refuses_others(tomato):
    s = verdant.Sim(tomato)
    st = s.get_state()
    other = verdant.Sim(verdant.grow(data("tomato.lpy"), seed=4))
    for bad, why in ((st[:-8], "wrong length"), (b"junk" * 40, "not a Sim state"), (b"", "too short")):
        with pytest.raises(verdant.ArgumentError, match=why):
            s.set_state(bad)
    if len(other.node_pos) != len(s.node_pos):
        with pytest.raises(verdant.ArgumentError, match="another rod model"):
            other.set_state(st)


def test_plant_and_cloud_pickle(tomato):
    p = pickle.loads(pickle.dumps(tomato))
    assert isinstance(p, verdant.Plant) and p.seed == tomato.seed
    for name in ("nodes", "segments", "radii", "labels", "instances", "spheres", "vertices",
                 "triangles", "mesh_labels"):
        assert np.array_equal(getattr(p, name), getattr(tomato, name)), name
    assert p.label_names == tomato.label_names
    c = tomato.cloud(points=3000, seed=2, threads=1)
    d = pickle.loads(pickle.dumps(c))
    assert isinstance(d, verdant.Cloud) and len(d) == len(c)
    for name in ("pos", "normals", "label", "instance", "view"):
        assert np.array_equal(getattr(d, name), getattr(c, name)), name


def test_env_state_and_pickle():
    env = verdant.HarvestEnv(PICK)
    env.reset(seed=2)
    rng = np.random.default_rng(0)
    acts = [env.action_space.low + (env.action_space.high - env.action_space.low) * rng.random(7)
            for _ in range(40)]
    for a in acts[:25]:
        env.step(a)
    st = env.get_state()
    blob = pickle.dumps(env)
    ref = [env.step(a) for a in acts[25:]]
    for other in (verdant.HarvestEnv(PICK), pickle.loads(blob)):
        if other._state == "new":
            other.set_state(st)
        for a, (obs, r, term, trunc, _) in zip(acts[25:], ref):
            o, r2, term2, trunc2, _ = other.step(a)
            assert r2 == r and term2 == term and trunc2 == trunc
            assert all(np.array_equal(o[k], obs[k]) for k in obs)
    with pytest.raises(verdant.ArgumentError):
        env.set_state({"format": "something"})
