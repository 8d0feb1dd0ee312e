# SPDX-License-Identifier: MIT
"""An environment loop: verdant.HarvestEnv (Gymnasium's conventions, no Gymnasium needed) with a
hand-written policy that reaches the target fruit, closes the gripper and pulls until the fruit
comes off; then a random policy for a few episodes. Works as is with a Gymnasium-style agent.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/harvest_env.py [--scene SCENE.json]
"""
import argparse
import os

import numpy as np

import verdant

here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--scene", default=os.path.join(here, "..", "..", "data", "scenes", "mini_pick.json"))
ap.add_argument("--episodes", type=int, default=3, help="random-policy episodes")
a = ap.parse_args()

env = verdant.HarvestEnv(a.scene, randomize=False)
print(env, "\n  actions:", env.action_space, "\n  observations:", list(env.observation_space.spaces))

# a policy from the observation: go to the fruit, close, pull back along +x
obs, info = env.reset(seed=0)
phase, total = "reach", 0.0
while True:
    to_fruit = obs["fruit_pos"] - obs["ee_pos"]
    if phase == "reach":
        action = np.r_[np.clip(2 * to_fruit, -0.1, 0.1), 0, 0, 0, 0.0]
        if np.linalg.norm(to_fruit) < 0.004:
            phase = "grasp"
    elif phase == "grasp":
        action = np.r_[0, 0, 0, 0, 0, 0, 1.0]
        if obs["held"][0]:
            phase = "pull"
    else:
        action = np.r_[0.05, 0, 0, 0, 0, 0, 1.0]
    obs, reward, terminated, truncated, info = env.step(action)
    total += reward
    for e in info["events"]:
        if e["kind"] in ("grasp", "detach", "fracture", "hit", "drop"):
            print(f"  t = {info['time']:.2f} s: {e['kind']} {e['site'] if e['kind'] == 'detach' else ''}")
    if terminated or truncated:
        break
print(f"hand-written policy: {info['reason']} after {info['time']:.2f} s, return {total:.2f}")

# random actions, the next episodes of the scene's randomisation
env = verdant.HarvestEnv(a.scene, max_episode_steps=50)
env.reset(seed=1)
for ep in range(a.episodes):
    if ep:
        env.reset()
    total, steps = 0.0, 0
    while True:
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        total, steps = total + reward, steps + 1
        if terminated or truncated:
            break
    print(f"random policy, episode {ep}: {steps} steps, return {total:.3f}, target {info['target_instance']}")
