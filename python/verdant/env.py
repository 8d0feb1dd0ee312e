# SPDX-License-Identifier: MIT
"""verdant.HarvestEnv: a robot arm harvesting fruit from a simulated plant, as a reinforcement
learning environment with the Gymnasium conventions (reset, step, action_space,
observation_space, render) and no dependency on Gymnasium itself.

    env = verdant.HarvestEnv("data/scenes/tomato_pull.json")
    obs, info = env.reset(seed=0)
    while True:
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:
            break

An action is an end-effector velocity (linear m/s and angular rad/s, world frame) and a gripper
command in [0, 1] (0 open, 1 closed): a float32 vector of 7. The robot follows it through
damped least-squares inverse kinematics and position servos; the plant is Cosserat rods, and
the fruit comes off when its pedicel or calyx breaks (docs/physics.md, robot.h).
"""
import numpy as np

from . import _verdant

# the default reward: what each term weighs (docs/python.md)
REWARD_WEIGHTS = {
    "detach": 10.0,     # once, when the target fruit comes off the plant
    "grasp": 1.0,       # once, when the gripper first holds the target fruit
    "distance": 1.0,    # per second: minus the gripper's distance to the target fruit (m)
    "pull_force": 0.1,  # per second: minus the held fruit's pull on the gripper (N): the force on
                        # the pedicel
    "fracture": 1.0,    # per broken plant joint other than the target's detachment (damage)
    "drop": 2.0,        # per other fruit that comes off (damage)
    "hit": 0.2,         # per other fruit the robot touches
}


class Box:
    """A box of real vectors (Gymnasium's Box without Gymnasium): low, high, shape, dtype;
    sample() draws uniformly (a seeded numpy Generator: seed())."""

    def __init__(self, low, high, shape=None, dtype=np.float32):
        self.dtype = np.dtype(dtype)
        self.shape = tuple(shape) if shape is not None else np.shape(low)
        self.low = np.broadcast_to(np.asarray(low, self.dtype), self.shape).copy()
        self.high = np.broadcast_to(np.asarray(high, self.dtype), self.shape).copy()
        self._rng = np.random.default_rng()

    def seed(self, seed=None):
        """Seed the generator behind sample()."""
        self._rng = np.random.default_rng(seed)
        return [seed]

    def sample(self):
        """A uniform draw (an unbounded dimension draws from a unit normal)."""
        lo, hi = self.low.astype(np.float64), self.high.astype(np.float64)
        bounded = np.isfinite(lo) & np.isfinite(hi)
        x = np.where(bounded, self._rng.uniform(np.where(bounded, lo, 0), np.where(bounded, hi, 1)),
                     self._rng.standard_normal(self.shape))
        if np.issubdtype(self.dtype, np.integer):
            x = np.floor(x + 0.5)
        return x.astype(self.dtype)

    def contains(self, x):
        """True when x has the shape and lies within the bounds."""
        x = np.asarray(x)
        return x.shape == self.shape and bool(np.all(x >= self.low) and np.all(x <= self.high))

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"


class Dict:
    """A dict of spaces (Gymnasium's Dict without Gymnasium)."""

    def __init__(self, spaces):
        self.spaces = dict(spaces)

    def seed(self, seed=None):
        """Seed every sub-space (seed + k for the k-th)."""
        for k, s in enumerate(self.spaces.values()):
            s.seed(None if seed is None else seed + k)
        return [seed]

    def sample(self):
        """A draw of every sub-space."""
        return {k: s.sample() for k, s in self.spaces.items()}

    def contains(self, x):
        """True when x has the keys and every value is in its space."""
        return isinstance(x, dict) and x.keys() == self.spaces.keys() and all(
            s.contains(x[k]) for k, s in self.spaces.items())

    def __getitem__(self, key):
        return self.spaces[key]

    def __repr__(self):
        return "Dict(" + ", ".join(f"{k}: {v}" for k, v in self.spaces.items()) + ")"


class HarvestEnv:
    """HarvestEnv(scene, *, image=False, masks=False, cloud=False, image_size=(96, 72),
    cloud_points=1024, max_lin_vel=0.1, max_ang_vel=1.0, reward_weights=None,
    max_episode_steps=None, randomize=True, terminate_on_detach=True, render_mode=None)

    scene: a scene file (docs/formats.md) or its JSON text: plant, robot MJCF, target fruit,
    method (its grip force and friction), episodes (what reset randomises: plant seed, target,
    method parameters), duration (truncation) and control_dt (one step).

    Observation (a dict): q, qd (arm joints), gripper (finger opening, m), ee_pos, ee_quat
    (w, x, y, z), fruit_pos, fruit_vel (the target fruit), held, touching (two fingers),
    finger_force (N), pull_force (the held fruit's pull on the gripper, N), detached; with
    image=True the wrist camera's picture (rgb, uint8 H x W x 3), with masks=True also its depth
    (float32, m) and label and instance masks; with cloud=True a labelled point cloud of what the
    wrist camera's position sees (cloud_xyz float32 (N, 3), cloud_label int32 (N)). The wrist
    camera looks along the end-effector's approach axis; pictures show the plant and the robot's
    collision shapes (label 65535), clouds the plant.

    Action: float32 (7,): end-effector velocity (3, m/s, within max_lin_vel), angular velocity
    (3, rad/s, within max_ang_vel), gripper command in [0, 1]; values outside are clipped.

    Reward (default weights REWARD_WEIGHTS, reward_weights= replaces some): +detach when the
    target fruit comes off; +grasp when it is first held; -distance x (gripper-fruit distance,
    m) x control_dt; -pull_force x |pull of the held fruit| (N) x control_dt (the force on the
    pedicel); -fracture per broken joint other than the target's detachment; -drop per other
    fruit that falls; -hit per other fruit touched. The terms of each step are in
    info["reward_terms"].

    terminated: the episode ended by its outcome (the target fruit came off, with
    terminate_on_detach=True; the scripted outcomes: not grasped, slipped, unreachable; the
    simulation failed); truncated: its duration (or max_episode_steps) ran out. info: time, phase, target_instance, detached, site, reason (at
    the end), events of the step, summary (at the end).
    reset(seed=s) starts episode 0 of seed s; reset() the next episode of the same seed.
    """

    metadata = {"render_modes": ["rgb_array"]}

    def __init__(self, scene, *, image=False, masks=False, cloud=False, image_size=(96, 72),
                 cloud_points=1024, max_lin_vel=0.1, max_ang_vel=1.0, reward_weights=None,
                 max_episode_steps=None, randomize=True, terminate_on_detach=True,
                 render_mode=None):
        unknown = set(reward_weights or {}) - set(REWARD_WEIGHTS)
        if unknown:
            raise _verdant.ArgumentError(f"reward_weights: unknown terms {sorted(unknown)}")
        if render_mode not in (None, "rgb_array"):
            raise _verdant.ArgumentError("render_mode: None or 'rgb_array'")
        self._h = _verdant.Harvest(scene)
        self.scene = scene
        self.image, self.masks, self.cloud = bool(image or masks), bool(masks), bool(cloud)
        self.image_size = tuple(int(v) for v in image_size)
        self.cloud_points = int(cloud_points)
        self.weights = {**REWARD_WEIGHTS, **(reward_weights or {})}
        self.max_episode_steps = max_episode_steps
        self.randomize = randomize
        self.terminate_on_detach = terminate_on_detach
        self.render_mode = render_mode
        self._renderer = None
        self._seed, self._episode, self._steps, self._nevents = 0, -1, 0, 0
        self._was_detached = self._was_held = False
        info = self._h.info
        nq = info["nq"]
        self.control_dt = info["control_dt"]
        self.action_space = Box(np.r_[[-max_lin_vel] * 3, [-max_ang_vel] * 3, 0.0],
                                np.r_[[max_lin_vel] * 3, [max_ang_vel] * 3, 1.0], (7,))
        inf = np.inf
        spaces = {
            "q": Box(-inf, inf, (nq,), np.float64), "qd": Box(-inf, inf, (nq,), np.float64),
            "gripper": Box(0, inf, (1,), np.float64), "ee_pos": Box(-inf, inf, (3,), np.float64),
            "ee_quat": Box(-1, 1, (4,), np.float64), "fruit_pos": Box(-inf, inf, (3,), np.float64),
            "fruit_vel": Box(-inf, inf, (3,), np.float64), "held": Box(0, 1, (1,), np.int8),
            "touching": Box(0, 1, (2,), np.int8), "finger_force": Box(0, inf, (2,), np.float64),
            "pull_force": Box(-inf, inf, (3,), np.float64), "detached": Box(0, 1, (1,), np.int8),
        }
        w, h = self.image_size
        if self.image:
            spaces["rgb"] = Box(0, 255, (h, w, 3), np.uint8)
        if self.masks:
            spaces["depth"] = Box(0, inf, (h, w), np.float32)
            spaces["label"] = Box(0, 65535, (h, w), np.int32)
            spaces["instance"] = Box(0, 2 ** 31 - 1, (h, w), np.int32)
        if self.cloud:
            spaces["cloud_xyz"] = Box(-inf, inf, (self.cloud_points, 3), np.float32)
            spaces["cloud_label"] = Box(0, 2 ** 31 - 1, (self.cloud_points,), np.int32)
        self.observation_space = Dict(spaces)

    # ------------------------------------------------------------------------------------------

    def reset(self, *, seed=None, options=None):
        """Start an episode: episode 0 of `seed` when given, else the next one. Returns
        (observation, info)."""
        if seed is not None:
            self._seed, self._episode = int(seed), 0
            self.action_space.seed(seed)
        else:
            self._episode += 1
        self._h.reset(self._seed, max(self._episode, 0), randomize=self.randomize)
        self._steps, self._nevents = 0, 0
        self._was_detached = self._was_held = False
        raw = self._h.observe()
        self._nevents = len(self._h.events())
        return self._observation(raw), self._info(raw, [])

    def step(self, action):
        """One control step under action (7 floats). Returns (observation, reward, terminated,
        truncated, info)."""
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (7,) or not np.all(np.isfinite(a)):
            raise _verdant.ArgumentError("action: 7 finite numbers (linear velocity, angular "
                                         "velocity, gripper)")
        a = np.clip(a, self.action_space.low, self.action_space.high)
        ok = self._h.step(a[:3], a[3:6], a[6])
        self._steps += 1
        raw = self._h.observe()
        events = self._h.events(self._nevents)
        self._nevents += len(events)
        reward, terms = self._reward(raw, events)
        done = self._h.done or (self.terminate_on_detach and bool(raw["detached"]))
        summary = self._h.summary() if done else None
        reason = (summary["reason"] if self._h.done else "detached") if summary else ""
        truncated = (done and reason == "time") or (
            self.max_episode_steps is not None and self._steps >= self.max_episode_steps and not done)
        terminated = done and not truncated
        info = self._info(raw, events)
        info["reward_terms"] = terms
        if not ok:
            info["failed"] = True
        if summary:
            info["summary"], info["reason"] = summary, reason
        return self._observation(raw), reward, terminated, truncated, info

    def render(self):
        """With render_mode='rgb_array': the scene from the side (uint8 H x W x 3), the plant in
        its current state and the robot's collision shapes."""
        if self.render_mode != "rgb_array":
            return None
        return self._draw(camera="orbit", azimuth=-60, elevation=20, masks=False, depth=False,
                          size=(320, 240))["rgb"]

    def close(self):
        """Free the episode and the renderer."""
        self._renderer = None

    # ------------------------------------------------------------------------------------------

    def _draw(self, size, **kw):
        from . import Renderer

        if self._renderer is None or self._renderer.size != tuple(size):
            self._renderer = Renderer(size=size, legend=False, max_geoms=100000)
        return self._renderer.draw(self._h, **kw)

    def _wrist(self, raw):
        # the wrist camera: just behind the tool point, looking along its approach axis (+z),
        # image up along the fingers' opening axis' normal (+x)
        w, x, y, z = raw["ee_quat"]
        R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        eye = raw["ee_pos"] - 0.06 * R[:, 2]
        return eye, eye + 0.5 * R[:, 2], R[:, 0]

    def _observation(self, raw):
        obs = {
            "q": raw["q"], "qd": raw["qd"], "gripper": np.array([raw["gripper_opening"]]),
            "ee_pos": raw["ee_pos"], "ee_quat": raw["ee_quat"], "fruit_pos": raw["fruit_pos"],
            "fruit_vel": raw["fruit_vel"], "held": np.array([raw["held"]], np.int8),
            "touching": raw["touching"].astype(np.int8), "finger_force": raw["finger_force"],
            "pull_force": raw["pull_force"], "detached": np.array([raw["detached"]], np.int8),
        }
        if self.image or self.cloud:
            eye, lookat, up = self._wrist(raw)
        if self.image:
            f = self._draw(self.image_size, eye=eye, lookat=lookat, up=up, fov=70,
                           depth=self.masks, masks=self.masks)
            obs["rgb"] = f["rgb"]
            if self.masks:
                obs["depth"], obs["label"], obs["instance"] = f["depth"], f["label"], f["instance"]
        if self.cloud:
            c = self._h.cloud(points=self.cloud_points, scanners=[tuple(eye) + tuple(lookat)],
                              occlusion=True, threads=1, seed=self._steps)
            obs["cloud_xyz"], obs["cloud_label"] = np.array(c.xyz), np.array(c.label)
        return obs

    def _info(self, raw, events):
        return {"time": raw["time"], "phase": raw["phase"], "target_instance": raw["target_instance"],
                "detached": raw["detached"], "site": raw["site"], "events": events,
                "episode": self._episode, "seed": self._seed}

    def _reward(self, raw, events):
        w, dt = self.weights, self.control_dt
        dist = float(np.linalg.norm(raw["ee_pos"] - raw["fruit_pos"]))
        pull = float(np.linalg.norm(raw["pull_force"])) if raw["held"] else 0.0
        kinds = [e["kind"] for e in events]
        detached_now = raw["detached"] and not self._was_detached
        held_now = raw["held"] and not self._was_held
        self._was_detached |= bool(raw["detached"])
        self._was_held |= bool(raw["held"])
        terms = {
            "detach": w["detach"] * detached_now,
            "grasp": w["grasp"] * held_now,
            "distance": -w["distance"] * dist * dt,
            "pull_force": -w["pull_force"] * pull * dt,
            # fractures other than the target's detachment (that one is in "detach")
            "fracture": -w["fracture"] * max(0, kinds.count("fracture") - kinds.count("detach")),
            "drop": -w["drop"] * kinds.count("drop"),
            "hit": -w["hit"] * kinds.count("hit"),
        }
        return float(sum(terms.values())), terms

    def __repr__(self):
        i = self._h.info
        return f"<verdant.HarvestEnv {i['scene'] or 'scene'}: {i['method']}, {i['nq']} joints>"
