# SPDX-License-Identifier: MIT
"""Simulation: the same final plant and events as `verdant sim`, colliders moved and forces set
between steps, state views, stress, the GIL released while stepping."""
import csv
import threading
import time

import numpy as np
import pytest

import verdant
from conftest import data, read


@pytest.fixture(scope="module")
def tomato():
    return verdant.grow(data("tomato.lpy"), seed=3)


def test_gravity_run_equals_cli(tmp_path, cli, tomato):
    s = verdant.Sim(tomato, sag_free=True)
    s.step(100)
    s.save(tmp_path / "py.json")
    cli("sim", data("tomato.lpy"), "--seed", "3", "--sag-free", "--duration", "0.1", "--final", tmp_path / "cli.json")
    assert read(tmp_path / "py.json") == read(tmp_path / "cli.json")
    assert s.time == pytest.approx(0.1) and s.nstep == 100


def test_pull_and_probe_equal_cli(tmp_path, cli, tomato):
    # the command line's loop, written in Python: a ramped pull on a fruit and a moving probe
    dur, dt = 0.3, 1e-3
    p0, p1, r = np.array([0.4, 0, 0.8]), np.array([-0.4, 0, 0.8]), 0.04
    s = verdant.Sim(tomato, sag_free=True, wind=(5, 0, 0), break_force={"fruit": 1.0})
    probe = s.add_collider("sphere", size=r, pos=p0)
    fruit = s.find_organ("fruit")
    pull = np.array([0.0, 0.5, -3.0])
    for _ in range(round(dur / dt)):
        t = s.time
        s.apply_force(fruit, pull * min(1.0, t / dur))
        u = min(max((t + dt) / dur, 0.0), 1.0)
        s.move_collider(probe, p0 + (p1 - p0) * u)
        s.step()
    s.save(tmp_path / "py.json")
    out = tmp_path / "run"
    cli("sim", data("tomato.lpy"), "--seed", "3", "--sag-free", "--wind", "5,0,0", "--break-force", "fruit=1.0",
        "--duration", str(dur), "--pull", "fruit=0,0.5,-3", "--probe", "0.04:0.4,0,0.8:-0.4,0,0.8",
        "--frames", "none", "-o", out)
    assert read(tmp_path / "py.json") == read(out / "plant.json")
    # the same fractures, field by field
    with open(out / "events.csv") as f:
        rows = list(csv.DictReader(f))
    ev = s.events
    assert len(ev) == len(rows) >= 1
    for e, row in zip(ev, rows):
        assert f"{e['time']:.6f}" == row["time_s"] and e["segment"] == int(row["segment"])
        assert e["label_name"] == row["label_name"] and e["cause"] == row["cause"]
        assert f"{e['force']:.6g}" == row["force_N"]
    assert s.stats["nevents"] == len(ev) and s.seg_broken.sum() >= 1


def test_state_views(tomato):
    s = verdant.Sim(tomato)
    pos = s.node_pos
    assert pos.base is s and not pos.flags.writeable and pos.shape == (len(s.node_pos0), 3)
    before = pos.copy()
    s.step(50)
    assert not np.array_equal(pos, before)        # a view of the state: it moved with the step
    assert np.array_equal(pos, s.node_pos)
    q = s.seg_quat
    assert np.allclose(np.linalg.norm(q, axis=1), 1)
    st = s.stress
    assert st.shape == (len(q),) and (st >= 0).all() and st.max() > 0
    ps = s.plant_stress
    assert ps.shape == (len(tomato.segments),)
    f = s.node_force
    assert f.flags.writeable
    tip = int(np.argmax(s.node_pos0[:, 2]))
    f[tip] = (0, 2.0, 0)                          # a force written through the view
    s.step(100)
    assert s.node_pos[tip, 1] > before[tip, 1] + 1e-3
    assert s.stats["kinetic_energy"] > 0 and s.stats["steps"] == 150
    s.reset()
    assert s.time == 0 and np.array_equal(s.node_pos, s.node_pos0)


def test_colliders_ties_settle(tomato):
    s = verdant.Sim(tomato, sag_free=True, ground=None)
    assert s.colliders == []
    # a box pushed into the plant, a mesh collider (a closed cube), a tie
    b = s.add_collider("box", size=(0.05, 0.05, 0.05), pos=(0.3, 0, 0.8), quat=(1, 0, 0, 0))
    v = np.array([[x, y, z] for x in (-.05, .05) for y in (-.05, .05) for z in (-.05, .05)])
    tri = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                    [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    m = s.add_mesh_collider(v, tri, pos=(-0.3, 0, 0.5))
    assert [c["shape"] for c in s.colliders] == ["box", "mesh"] and (b, m) == (0, 1)
    s.move_collider(b, (0.25, 0, 0.8))
    assert s.colliders[0]["vel"][0] == pytest.approx(-0.05 / 1e-3)
    node = s.find_organ("fruit", instance=0)
    k = s.add_tie(node, target=s.node_pos[node] + (0, 0, 0.05), compliance=1e-4)
    s.move_tie(k, s.node_pos0[node] + (0, 0, 0.02))
    converged, steps = s.settle(max_time=0.15)
    assert isinstance(converged, bool) and steps > 0
    assert np.linalg.norm(s.node_pos[node] - (s.node_pos0[node] + (0, 0, 0.02))) < 0.015


def test_set_and_options(tomato):
    s = verdant.Sim(tomato, dt=2e-3, solver="gs", iterations=4, young={"green": 2e9})
    o = s.options
    assert o["dt"] == 2e-3 and o["solver"] == "gs" and o["iterations"] == 4
    s.set(dt=1e-3, wind=(1, 2, 3), wind_series=[[0, 0, 0, 0], [1, 5, 0, 0]], gust=(0.2, 1.0))
    o = s.options
    assert o["dt"] == 1e-3 and o["wind"] == (1, 2, 3) and o["wind_series_rows"] == 2
    s.step(5)


BAD = [
    ({"dt": 0}, verdant.ArgumentError), ({"dt": "1"}, TypeError), ({"solver": "cg"}, verdant.ArgumentError),
    ({"young": -1}, verdant.ArgumentError), ({"young": {"bark": 1e9}}, verdant.ArgumentError),
    ({"break_strain": 1}, TypeError), ({"gravity": (0, 0)}, TypeError), ({"wind": (1e9, 0, 0)}, verdant.ArgumentError),
    ({"wind_series": [[1, 0, 0, 0], [0, 0, 0, 0]]}, verdant.ArgumentError), ({"wind_series": [[1, 2]]}, verdant.ArgumentError),
    ({"ground": "low"}, TypeError), ({"segment_length": 0}, verdant.ArgumentError), ({"max_segments": 3}, verdant.LimitError),
    ({"colour": 1}, TypeError),
]


@pytest.mark.parametrize("kw,exc", BAD)
def test_bad_sim_options(tomato, kw, exc):
    with pytest.raises(exc):
        verdant.Sim(tomato, **kw)


def test_bad_sim_calls(tomato):
    s = verdant.Sim(tomato)
    with pytest.raises(TypeError):
        verdant.Sim("plant.lpy")
    for call, exc in ((lambda: s.step(-1), verdant.ArgumentError), (lambda: s.step(1.5), TypeError),
                      (lambda: s.add_collider("cone"), verdant.ArgumentError),
                      (lambda: s.add_collider("sphere"), verdant.ArgumentError),
                      (lambda: s.add_collider("sphere", size=-1), verdant.ArgumentError),
                      (lambda: s.add_collider("box", size=(1, 1)), TypeError),
                      (lambda: s.add_collider("sphere", size=1, quat=(0, 0, 0, 0)), verdant.ArgumentError),
                      (lambda: s.move_collider(5, (0, 0, 0)), verdant.ArgumentError),
                      (lambda: s.move_collider(-1, (0, 0, 0)), verdant.ArgumentError),
                      (lambda: s.apply_force(10 ** 9, (0, 0, 1)), verdant.ArgumentError),
                      (lambda: s.apply_force("wing", (0, 0, 1)), verdant.UndefinedNameError),
                      (lambda: s.apply_force(0, (0, 0, float("nan"))), verdant.ArgumentError),
                      (lambda: s.add_tie(0, compliance=0), verdant.ArgumentError),
                      (lambda: s.move_tie(3, (0, 0, 0)), verdant.ArgumentError),
                      (lambda: s.add_mesh_collider([[0, 0, 0]], [[0, 0, 0]]), verdant.ArgumentError),
                      (lambda: s.add_mesh_collider(np.zeros((4, 3)), [[0, 1, 9]] * 4), verdant.ArgumentError),
                      (lambda: s.add_mesh_collider(np.eye(4, 3), [[0, 1, 2]] * 4), verdant.BadValueError),
                      (lambda: s.set(colour=1), TypeError), (lambda: s.set(1), TypeError),
                      (lambda: s.settle(max_steps=-1), verdant.ArgumentError)):
        with pytest.raises(exc):
            call()
    for _ in range(VD_MAX := 64):
        try:
            s.add_collider("sphere", size=0.01, pos=(5, 5, 5))
        except verdant.ArgumentError:
            break
    else:
        raise AssertionError("more than 64 colliders accepted")
    s.step(2)


def test_threads_step_side_by_side(tomato):
    # while one thread steps (the GIL released), another runs Python; and two Sims stepped in two
    # threads end where they end stepped one after the other
    ref = []
    for w in (1.0, -1.0):
        s = verdant.Sim(tomato, wind=(w, 0, 0))
        s.step(150)
        ref.append(s.node_pos.copy())
    sims = [verdant.Sim(tomato, wind=(w, 0, 0)) for w in (1.0, -1.0)]
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t0 = threading.Thread(target=tick)
    t0.start()
    ts = [threading.Thread(target=s.step, args=(150,)) for s in sims]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    done.set()
    t0.join()
    assert len(ticks) > 5
    assert all(np.array_equal(s.node_pos, r) for s, r in zip(sims, ref))


def test_busy_sim_raises(tomato):
    s = verdant.Sim(tomato)
    err = []

    def other():
        time.sleep(0.02)
        try:
            s.step()
        except verdant.Error as e:
            err.append(e)

    t = threading.Thread(target=other)
    t.start()
    s.step(600)
    t.join()
    assert err and err[0].status == "busy"


def test_deformed_cloud(tomato, tmp_path, cli):
    s = verdant.Sim(tomato, sag_free=True, wind=(8, 0, 0))
    s.step(100)
    c = s.cloud(points=5000)
    s.save(tmp_path / "final.json")
    c.save(tmp_path / "py.ply")
    cli("cloud", tmp_path / "final.json", "--seed", "3", "--points", "5000", "-o", tmp_path / "cli.ply")
    assert read(tmp_path / "py.ply") == read(tmp_path / "cli.ply")
