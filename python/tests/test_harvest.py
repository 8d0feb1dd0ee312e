# SPDX-License-Identifier: MIT
"""HarvestEnv and Harvest: a random policy through 100 episodes of a test-sized scene, a Python
controller that picks a fruit, the scripted run equal to `verdant harvest`, the wrist camera's
picture and cloud, bad arguments."""
import json
import os

import numpy as np
import pytest

import verdant
from conftest import SRC

HERE = os.path.join(SRC, "data", "scenes")
MINI = os.path.join(HERE, "mini_harvest.json")    # a small tomato, the Lite 6, 0.15 s episodes
PICK = os.path.join(HERE, "mini_pick.json")       # the same with 6 s episodes and a faster pull
# the sanitized build (make test SANITIZE=1) runs ten times slower: fewer episodes there
EPISODES = 10 if os.environ.get("VERDANT_SANITIZE") else 100


def test_random_policy_100_episodes():
    env = verdant.HarvestEnv(MINI)
    assert env.action_space.shape == (7,) and env.action_space.dtype == np.float32
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    episodes, targets, returns = 0, set(), []
    for ep in range(EPISODES):
        if ep:
            obs, info = env.reset()
        assert info["episode"] == ep and not info["detached"]
        targets.add(info["target_instance"])
        total, steps = 0.0, 0
        while True:
            obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
            steps += 1
            assert env.observation_space.contains(obs) and np.isfinite(reward)
            assert abs(sum(info["reward_terms"].values()) - reward) < 1e-12
            total += reward
            if terminated or truncated:
                break
            assert steps <= 15
        assert info["summary"]["steps"] == steps and info["reason"]
        episodes += 1
        returns.append(total)
    assert episodes == EPISODES and len(targets) > 1     # random reachable targets
    # the same seed, the same episodes
    env2 = verdant.HarvestEnv(MINI)
    env2.reset(seed=0)
    env.reset(seed=0)
    a = [env.action_space.sample() for _ in range(5)]
    r1 = [env.step(x)[1] for x in a]
    r2 = [env2.step(x)[1] for x in a]
    assert r1 == r2


def test_controller_picks_fruit():
    # straight to the fruit, close, pull back: the reward pays the detachment
    env = verdant.HarvestEnv(PICK, randomize=False)
    obs, info = env.reset(seed=0)
    phase, wait, total, kinds = "go", 0, 0.0, []
    for _ in range(600):
        e = obs["fruit_pos"] - obs["ee_pos"]
        if phase == "go":
            v, g = np.clip(2 * e, -0.1, 0.1), 0.0
            phase = "close" if np.linalg.norm(e) < 0.004 else phase
        elif phase == "close":
            v, g, wait = np.zeros(3), 1.0, wait + 1
            phase = "pull" if obs["held"][0] or wait > 100 else phase
        else:
            v, g = np.array([0.05, 0, 0]), 1.0
        obs, r, terminated, truncated, info = env.step(np.r_[v, 0, 0, 0, g])
        total += r
        kinds += [ev["kind"] for ev in info["events"]]
        if terminated or truncated:
            break
    assert terminated and info["reason"] == "detached" and obs["detached"][0]
    assert "grasp" in kinds and "detach" in kinds and info["site"] != "none"
    # the detachment's reward outweighs the penalties of getting there (distance, pull force:
    # larger for a fruit whose drawn calyx threshold is high)
    assert total > 0.5 * verdant.env.REWARD_WEIGHTS["detach"]


def test_scripted_run_equals_cli(cli):
    h = verdant._verdant.Harvest(PICK)
    assert h.run() and h.done
    s = h.summary()
    ref = json.loads(cli("harvest", PICK, "--stats").stdout)
    assert s["detached"] == ref["detached"] and s["site"] == ref["site"] and s["reason"] == ref["reason"]
    assert s["steps"] == ref["steps"] and s["target_instance"] == ref["target_instance"]
    # the same double: cJSON prints 15 digits whenever they read back within DBL_EPSILON
    assert s["pull_force"] == pytest.approx(ref["pull_force"], rel=4e-16, abs=0)
    assert s["time"] == pytest.approx(ref["detach_time"] or s["time"])
    with pytest.raises(verdant.ArgumentError):
        h.step((0, 0, 0), (0, 0, 0), 0)                 # the episode is over
    h.reset(0)
    h.step((0, 0, 0), (0, 0, 0), 0)
    with pytest.raises(verdant.ArgumentError):
        h.run()                                          # not from the start any more


def test_wrist_camera_sees_the_target_at_pregrasp():
    # issue 20 item 7: where the scripted reach begins (the arm at its pre-grasp pose) the wrist
    # camera shows the target fruit (>= 5 % of the picture) and little of the robot (<= 30 %)
    scene = os.path.join(HERE, "tomato_pull.json")
    for seed in (0, 1):
        env = verdant.HarvestEnv(scene, image=True, masks=True)
        env.reset(seed=seed)
        assert env._h.run(until="reach")
        raw = env._h.observe()
        assert raw["phase"] == "reach"
        obs = env._observation(raw)
        target = np.mean(obs["instance"] == raw["target_instance"])
        robot = np.mean(obs["label"] == 65535)
        assert target >= 0.05 and robot <= 0.30, (seed, target, robot)
        obs, *_ = env.step(np.zeros(7, np.float32))          # the episode goes on under step()
        with pytest.raises(verdant.ArgumentError):
            env._h.run()
        env.close()
    with pytest.raises(verdant.ArgumentError):
        verdant.HarvestEnv(MINI)._h.run(until="lunch")
    with pytest.raises(verdant.ArgumentError):
        verdant.HarvestEnv(MINI, camera_fov=0)


def test_wrist_camera_observations():
    env = verdant.HarvestEnv(MINI, image=True, masks=True, cloud=True, image_size=(64, 48),
                             cloud_points=500, render_mode="rgb_array")
    obs, info = env.reset(seed=1)
    assert env.observation_space.contains(obs)
    assert obs["rgb"].shape == (48, 64, 3) and obs["depth"].shape == (48, 64)
    plant_labels = set(env._h.plant().label_names) | {0, 65535}
    assert set(np.unique(obs["label"])) <= plant_labels
    assert obs["cloud_xyz"].shape == (500, 3) and set(np.unique(obs["cloud_label"])) <= plant_labels
    assert obs["cloud_instance"].shape == (500,)
    assert set(np.unique(obs["cloud_instance"])) <= set(env._h.plant().instances) | set(
        env._h.plant().sphere_instances) | set(env._h.plant().mesh_instances)
    # the camera with the picture: the target's pixels project where K and the pose put them
    K, pose = obs["camera_K"], obs["camera_pose"]
    assert K.shape == (3, 3) and pose.shape == (4, 4) and 0 <= obs["target_visible"][0] <= 1
    ys, xs = np.nonzero(obs["instance"] == info["target_instance"])
    if len(xs):
        p = np.linalg.inv(pose) @ np.r_[obs["fruit_pos"], 1.0]
        u, v = (K @ (p[:3] / p[2]))[:2]
        assert abs(u - xs.mean()) < 8 and abs(v - ys.mean()) < 8
        assert obs["target_visible"][0] > 0
    obs, *_ = env.step(np.zeros(7, np.float32))
    assert obs["rgb"].dtype == np.uint8
    assert env.render().shape == (240, 320, 3)
    pic = verdant.render(env._h, size=(80, 60))           # a Harvest draws like a Sim
    assert pic["rgb"].shape == (60, 80, 3)
    env.close()


def test_plant_seed_randomisation():
    env = verdant.HarvestEnv(PICK, max_episode_steps=3)
    seeds = []
    for ep in range(3):
        env.reset(seed=5) if ep == 0 else env.reset()
        for _ in range(3):
            *_, truncated, info = env.step(np.zeros(7))
        assert truncated
        seeds.append(env._h.summary()["plant_seed"])
    assert len(set(seeds)) == 3


def test_bad_arguments(tmp_path):
    env = verdant.HarvestEnv(MINI)
    env.reset(seed=0)
    for bad in ([0] * 6, [np.nan] * 7, "fast"):
        with pytest.raises((verdant.ArgumentError, ValueError)):
            env.step(bad)
    with pytest.raises(verdant.ArgumentError):
        verdant.HarvestEnv(MINI, reward_weights={"speed": 1})
    with pytest.raises(verdant.ArgumentError):
        verdant.HarvestEnv(MINI, render_mode="human")
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "verdant-scene", "version": 1, "plant": {"file": "a.lpy"}, '
                   '"robot": {"mjcf": "r.xml"}, "method": {"speed": -1}}')
    with pytest.raises(verdant.FormatError) as e:
        verdant.HarvestEnv(bad)
    assert e.value.file
    with pytest.raises(verdant.FileError):
        verdant.HarvestEnv(tmp_path / "none.json")
    h = verdant._verdant.Harvest(MINI)
    for call, exc in ((lambda: h.step((0, 0), (0, 0, 0), 0), TypeError),
                      (lambda: h.step((0, 0, 0), (0, 0, 0), 2), verdant.ArgumentError),
                      (lambda: h.step((99, 0, 0), (0, 0, 0), 0), verdant.ArgumentError),
                      (lambda: h.reset(-1), verdant.ArgumentError),
                      (lambda: h.events(since=-1), verdant.ArgumentError)):
        with pytest.raises(exc):
            call()
