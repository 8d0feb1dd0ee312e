# SPDX-License-Identifier: MIT
"""verdant.HarvestEnv: a robot arm harvesting fruit from a simulated plant, as a reinforcement
learning environment with Gymnasium's API. When gymnasium imports, HarvestEnv is a
gymnasium.Env with gymnasium.spaces, registered as "verdant/Harvest-v0"
(gymnasium.make("verdant/Harvest-v0", scene=...)); without it, the same API duck-typed (the
spaces Box and Dict below, np_random, spec, unwrapped).

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

Every reset succeeds or says why: a draw whose plant has no fruit the robot can reach is drawn
again, up to 32 draws (the C constant VDPY_DRAWS); construction makes the first reset's draws
and raises BadValueError naming the scene and the reason when none of them is possible.
"""
import numpy as np

from . import _verdant

try:  # optional: Debian has no python3-gymnasium; the duck-typed API below is the same
    import gymnasium as _gym
except ImportError:
    _gym = None

# the default reward: what each term weighs (docs/python.md); the order is the C layer's
# Where the wrist camera sits in the end-effector's frame (m): behind the tool point along the
# approach axis, aside along the axis normal to the fingers' opening, and the point ahead of the
# tool point it is aimed at (the default pre-grasp distance). Measured at the reach's start on
# tomato_pull (docs/python.md): the target 5-13 % of the picture where leaves leave it in view,
# the robot under 1 %.
WRIST_CAMERA = {"back": 0.0, "side": 0.05, "aim": 0.06}

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

ENV_ID = "verdant/Harvest-v0"


class ResetNeeded(_verdant.Error, RuntimeError):
    """step() before a successful reset(), after the episode ended (terminated or truncated),
    or after close()."""


class _Space:
    """What Gymnasium's Space gives: shape, dtype, a seeded np_random, seed(), sample(),
    contains() and `x in space`."""

    def __init__(self, shape, dtype):
        self._shape = None if shape is None else tuple(shape)
        self.dtype = None if dtype is None else np.dtype(dtype)
        self._np_random = None

    @property
    def shape(self):
        return self._shape

    @property
    def np_random(self):
        """The generator behind sample() (seeded by seed(), else from the OS on first use)."""
        if self._np_random is None:
            self.seed()
        return self._np_random

    def seed(self, seed=None):
        """Seed the generator behind sample(); returns [seed]."""
        self._np_random = np.random.default_rng(seed)
        return [seed]

    def __contains__(self, x):
        return self.contains(x)


class Box(_Space):
    """A box of real or integer arrays (Gymnasium's Box): low, high, shape, dtype. sample()
    draws uniformly where both bounds are finite, from an exponential past a single bound and
    from a normal where there is none, as Gymnasium does."""

    def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):
        shape = tuple(shape) if shape is not None else np.shape(low)
        super().__init__(shape, dtype)
        self.low = np.broadcast_to(np.asarray(low, self.dtype), shape).copy()
        self.high = np.broadcast_to(np.asarray(high, self.dtype), shape).copy()
        if seed is not None:
            self.seed(seed)

    def sample(self, mask=None):
        """A draw within the bounds, of the box's dtype."""
        lo, hi = self.low.astype(np.float64), self.high.astype(np.float64)
        r = self.np_random
        integer = np.issubdtype(self.dtype, np.integer)
        if integer:
            hi = hi + 1.0
        below, above = np.isfinite(lo), np.isfinite(hi)
        x = np.empty(self.shape)
        both, only_lo, only_hi, none = below & above, below & ~above, ~below & above, ~below & ~above
        x[both] = r.uniform(lo[both], hi[both])
        x[only_lo] = lo[only_lo] + r.exponential(size=int(only_lo.sum()))
        x[only_hi] = hi[only_hi] - r.exponential(size=int(only_hi.sum()))
        x[none] = r.normal(size=int(none.sum()))
        if integer:
            x = np.floor(x)
        return np.clip(x, lo, self.high.astype(np.float64)).astype(self.dtype)

    def contains(self, x):
        """True when x (array-like) casts to the dtype, has the shape and lies within the
        bounds."""
        if not isinstance(x, np.ndarray):
            try:
                x = np.asarray(x, dtype=self.dtype)
            except (ValueError, TypeError):
                return False
        return bool(np.can_cast(x.dtype, self.dtype) and x.shape == self.shape
                    and np.all(x >= self.low) and np.all(x <= self.high))

    def __eq__(self, other):
        return (isinstance(other, Box) and self.shape == other.shape and self.dtype == other.dtype
                and np.array_equal(self.low, other.low) and np.array_equal(self.high, other.high))

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"


class Dict(_Space):
    """A dict of spaces (Gymnasium's Dict)."""

    def __init__(self, spaces, seed=None):
        super().__init__(None, None)
        self.spaces = dict(spaces)
        if seed is not None:
            self.seed(seed)

    def seed(self, seed=None):
        """Seed every sub-space: the k-th from a seed drawn from this space's generator."""
        super().seed(seed)
        subs = self._np_random.integers(np.iinfo(np.int32).max, size=len(self.spaces))
        for s, sub in zip(self.spaces.values(), subs):
            s.seed(int(sub))
        return [seed]

    def sample(self, mask=None):
        """A draw of every sub-space."""
        return {k: s.sample() for k, s in self.spaces.items()}

    def contains(self, x):
        """True when x is a dict with the same keys whose every value is in its space."""
        return isinstance(x, dict) and x.keys() == self.spaces.keys() and all(
            x[k] in s for k, s in self.spaces.items())

    def __getitem__(self, key):
        return self.spaces[key]

    def __iter__(self):
        return iter(self.spaces)

    def __len__(self):
        return len(self.spaces)

    def keys(self):
        return self.spaces.keys()

    def values(self):
        return self.spaces.values()

    def items(self):
        return self.spaces.items()

    def __eq__(self, other):
        return isinstance(other, Dict) and self.spaces == other.spaces

    def __repr__(self):
        return "Dict(" + ", ".join(f"{k}: {v}" for k, v in self.spaces.items()) + ")"


if _gym is not None:  # the real thing where it imports
    Box, Dict = _gym.spaces.Box, _gym.spaces.Dict  # noqa: F811
    _EnvBase = _gym.Env
else:
    _EnvBase = object


class EnvSpec:
    """What Gymnasium's EnvSpec gives where gymnasium does not import: id, entry_point, kwargs,
    nondeterministic, max_episode_steps, and make(**kwargs) for a new environment."""

    def __init__(self, id, entry_point, kwargs, max_episode_steps=None):
        self.id, self.entry_point, self.kwargs = id, entry_point, dict(kwargs)
        self.nondeterministic = False
        self.max_episode_steps = max_episode_steps

    def make(self, **kwargs):
        return self.entry_point(**{**self.kwargs, **kwargs})

    def __repr__(self):
        return f"EnvSpec({self.id!r}, kwargs={self.kwargs!r})"


def _state_spaces(nq):
    """The state part of an observation (without pictures and clouds)."""
    inf = np.inf
    return {
        "q": Box(-inf, inf, (nq,), np.float64), "qd": Box(-inf, inf, (nq,), np.float64),
        "gripper": Box(0, inf, (1,), np.float64), "ee_pos": Box(-inf, inf, (3,), np.float64),
        "ee_quat": Box(-1, 1, (4,), np.float64), "fruit_pos": Box(-inf, inf, (3,), np.float64),
        "fruit_vel": Box(-inf, inf, (3,), np.float64), "held": Box(0, 1, (1,), np.int8),
        "touching": Box(0, 1, (2,), np.int8), "finger_force": Box(0, inf, (2,), np.float64),
        "pull_force": Box(-inf, inf, (3,), np.float64), "detached": Box(0, 1, (1,), np.int8),
    }


def _action_space(max_lin_vel, max_ang_vel):
    return Box(np.r_[[-max_lin_vel] * 3, [-max_ang_vel] * 3, 0.0],
               np.r_[[max_lin_vel] * 3, [max_ang_vel] * 3, 1.0], (7,), np.float32)


_NOT_RUNNING = {
    "new": "step() before a successful reset(): call reset() first",
    "ended": "step() after the episode ended (terminated or truncated): call reset() first",
    "closed": "step() on a closed HarvestEnv: make a new one",
}


class HarvestEnv(_EnvBase):
    """HarvestEnv(scene, *, image=False, masks=False, cloud=False, image_size=(96, 72),
    camera_fov=40.0, cloud_points=1024, max_lin_vel=0.1, max_ang_vel=1.0,
    reward_weights=None, max_episode_steps=None, randomize=True, terminate_on_detach=True,
    render_mode=None)

    scene: a scene file (docs/formats.md) or its JSON text: plant, robot MJCF, target fruit,
    method (its grip force and friction), episodes (what reset randomises: plant seed, target,
    method parameters), duration (truncation) and control_dt (one step).

    Observation (a dict): q, qd (arm joints), gripper (finger opening, m), ee_pos, ee_quat
    (w, x, y, z), fruit_pos, fruit_vel (the target fruit), held, touching (two fingers),
    finger_force (N), pull_force (the held fruit's pull on the gripper, N), detached; with
    image=True the wrist camera's picture (rgb, uint8 H x W x 3) with its intrinsics camera_K
    (3 x 3, OpenCV) and pose camera_pose (4 x 4 camera-to-world), with masks=True also its depth
    (float32, m), label and instance masks and target_visible (the target fruit's visible
    fraction); with cloud=True a labelled point cloud of what the wrist camera's position sees
    (cloud_xyz float32 (N, 3), cloud_label and cloud_instance int32 (N)). The wrist
    camera (WRIST_CAMERA) sits on the wrist beside the gripper, level with the tool point and
    5 cm off it across the fingers' plane, aimed at the point 6 cm ahead of the tool point (the
    default pre-grasp distance: where the target is when the reach begins), with a vertical
    field of view of camera_fov degrees; pictures show the plant and the robot's collision
    shapes (label 65535), clouds the plant.

    Action: float32 (7,): end-effector velocity (3, m/s, within max_lin_vel), angular velocity
    (3, rad/s, within max_ang_vel), gripper command in [0, 1]; values outside are clipped.

    Reward (default weights REWARD_WEIGHTS, reward_weights= replaces some): +detach when the
    target fruit comes off; +grasp when it is first held; -distance x (gripper-fruit distance,
    m) x control_dt; -pull_force x |pull of the held fruit| (N) x control_dt (the force on the
    pedicel); -fracture per broken joint other than the target's detachment; -drop per other
    fruit that falls; -hit per other fruit touched. The terms of each step are in
    info["reward_terms"].

    terminated: the episode ended by its outcome (the target fruit came off, with
    terminate_on_detach=True; the scripted outcomes: not grasped, slipped; the simulation
    failed); truncated: its duration (or max_episode_steps) ran out. info: time, phase,
    target_instance, detached, site, events of the step, episode, seed, draws (plant draws the
    reset took), reason and summary (at the end).

    reset(seed=s) starts episode 0 of seed s; reset() the next episode of the same seed. A draw
    whose plant has no reachable fruit is drawn again (at most 32 draws, BadValueError naming
    the scene after that). step() raises ResetNeeded before a successful reset, after the
    episode ended and after close().
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, scene, *, image=False, masks=False, cloud=False, image_size=(96, 72),
                 camera_fov=40.0, cloud_points=1024, max_lin_vel=0.1, max_ang_vel=1.0,
                 reward_weights=None, max_episode_steps=None, randomize=True,
                 terminate_on_detach=True, render_mode=None):
        unknown = set(reward_weights or {}) - set(REWARD_WEIGHTS)
        if unknown:
            raise _verdant.ArgumentError(f"reward_weights: unknown terms {sorted(unknown)}")
        if render_mode not in (None, "rgb_array"):
            raise _verdant.ArgumentError("render_mode: None or 'rgb_array'")
        self._h = _verdant.Harvest(scene)
        self.scene = scene
        self.image, self.masks, self.cloud = bool(image or masks), bool(masks), bool(cloud)
        self.image_size = tuple(int(v) for v in image_size)
        self.camera_fov = float(camera_fov)
        if not 1.0 <= self.camera_fov <= 170.0:
            raise _verdant.ArgumentError(f"camera_fov: degrees in [1, 170], not {camera_fov}")
        self.cloud_points = int(cloud_points)
        self.weights = {**REWARD_WEIGHTS, **(reward_weights or {})}
        self._weights = tuple(float(self.weights[k]) for k in REWARD_WEIGHTS)
        self.max_episode_steps = max_episode_steps
        self.randomize = randomize
        self.terminate_on_detach = terminate_on_detach
        self.render_mode = render_mode
        self._renderer = None
        self._np_random = None
        self._np_random_seed = None
        self._seed, self._episode = 0, -1
        self._state = "new"  # new, running, ended (terminated or truncated), closed
        # a scene where no draw is possible fails here, naming the scene and the reason
        self._h.reset(0, 0, randomize=self.randomize)
        info = self._h.info
        self.control_dt = info["control_dt"]
        self.metadata = {**type(self).metadata, "render_fps": round(1.0 / self.control_dt)}
        self.action_space = _action_space(max_lin_vel, max_ang_vel)
        spaces = _state_spaces(info["nq"])
        w, h = self.image_size
        self._target_radius = None
        if self.image:
            spaces["rgb"] = Box(0, 255, (h, w, 3), np.uint8)
            spaces["camera_K"] = Box(-np.inf, np.inf, (3, 3), np.float64)
            spaces["camera_pose"] = Box(-np.inf, np.inf, (4, 4), np.float64)
        if self.masks:
            spaces["depth"] = Box(0, np.inf, (h, w), np.float32)
            spaces["label"] = Box(0, 65535, (h, w), np.int32)
            spaces["instance"] = Box(0, 2 ** 31 - 1, (h, w), np.int32)
            spaces["target_visible"] = Box(0, 1, (1,), np.float32)
        if self.cloud:
            spaces["cloud_xyz"] = Box(-np.inf, np.inf, (self.cloud_points, 3), np.float32)
            spaces["cloud_label"] = Box(0, 2 ** 31 - 1, (self.cloud_points,), np.int32)
            spaces["cloud_instance"] = Box(0, 2 ** 31 - 1, (self.cloud_points,), np.int32)
        self.observation_space = Dict(spaces)
        self._kwargs = dict(
            scene=scene, image=image, masks=masks, cloud=cloud, image_size=image_size,
            camera_fov=camera_fov, cloud_points=cloud_points, max_lin_vel=max_lin_vel,
            max_ang_vel=max_ang_vel,
            reward_weights=reward_weights, max_episode_steps=max_episode_steps,
            randomize=randomize, terminate_on_detach=terminate_on_detach, render_mode=render_mode)
        if _gym is None:
            self.spec = EnvSpec(ENV_ID, HarvestEnv, self._kwargs, max_episode_steps)

    # the parts of gymnasium.Env's API that the duck-typed version needs ----------------------

    if _gym is None:
        _spec = None

        @property
        def spec(self):
            """The EnvSpec that makes this environment again (spec.make(**changes))."""
            return self._spec

        @spec.setter
        def spec(self, value):
            self._spec = value

        @property
        def unwrapped(self):
            """The environment itself (no wrappers)."""
            return self

        @property
        def np_random(self):
            """The environment's generator: seeded by reset(seed=...), else from the OS."""
            if self._np_random is None:
                self._np_random = np.random.default_rng()
            return self._np_random

        @property
        def np_random_seed(self):
            """The seed of np_random (-1 when it was seeded from the OS)."""
            return -1 if self._np_random_seed is None else self._np_random_seed

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.close()
            return False

        def __str__(self):
            return repr(self)

    # ------------------------------------------------------------------------------------------

    def reset(self, *, seed=None, options=None):
        """Start an episode: episode 0 of `seed` when given, else the next one. Returns
        (observation, info). options: {"episode": k} starts episode k of the current seed."""
        if self._state == "closed":
            raise ResetNeeded("reset() on a closed HarvestEnv: make a new one")
        if seed is not None:
            seed = int(seed)
            if _gym is not None:
                super().reset(seed=seed)
            else:
                self._np_random, self._np_random_seed = np.random.default_rng(seed), seed
            self._seed, self._episode = seed, 0
            self.action_space.seed(seed)
            self.observation_space.seed(seed)
        else:
            self._episode += 1
        if options and "episode" in options:
            self._episode = int(options["episode"])
        self._state = "new"
        self._draws = self._h.reset(self._seed, max(self._episode, 0), randomize=self.randomize)
        self._state = "running"
        self._actions = []
        raw = self._h.observe()
        info = self._info(raw, [])
        info["draws"] = self._draws
        return self._observation(raw), info

    def step(self, action):
        """One control step under action (7 floats). Returns (observation, reward, terminated,
        truncated, info)."""
        if self._state != "running":
            raise ResetNeeded(_NOT_RUNNING[self._state])
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (7,) or not np.all(np.isfinite(a)):
            raise _verdant.ArgumentError("action: 7 finite numbers (linear velocity, angular "
                                         "velocity, gripper)")
        a = np.clip(a, self.action_space.low, self.action_space.high)
        ok, reward, terms, terminated, truncated, reason, events = self._act(a)
        raw = self._h.observe()
        info = self._info(raw, events)
        info["reward_terms"] = terms
        if not ok:
            info["failed"] = True
        if terminated or truncated:
            info["summary"], info["reason"] = self._h.summary(), reason
        return self._observation(raw), reward, terminated, truncated, info

    def _act(self, a):
        out = self._h.act(a[:3], a[3:6], a[6], self._weights, self.terminate_on_detach,
                          self.max_episode_steps)
        self._actions.append(a)
        if out[3] or out[4]:
            self._state = "ended"
        return out

    def get_state(self):
        """The episode so far, as a dict you can keep (pickle, send to another process): its
        seed, episode index and the actions taken since its reset. set_state() on a HarvestEnv of
        the same scene and options replays them to the same state, bit for bit (the simulation
        is deterministic), so the future is the same as not stopping."""
        if self._state not in ("running", "ended"):
            raise ResetNeeded("get_state() before a successful reset()")
        return {"format": "verdant-harvest-state", "version": 1, "seed": self._seed,
                "episode": self._episode,
                "actions": np.array(self._actions, np.float64).reshape(-1, 7)}

    def set_state(self, state):
        """Go to a state of get_state(): the episode's reset, then its actions replayed without
        observations (one C step each). Returns (observation, info) of the state reached."""
        if state.get("format") != "verdant-harvest-state" or state.get("version") != 1:
            raise _verdant.ArgumentError("set_state: not a state of HarvestEnv.get_state()")
        self._seed, self._episode = int(state["seed"]), int(state["episode"]) - 1
        obs, info = self.reset()
        for a in np.asarray(state["actions"], np.float64).reshape(-1, 7):
            if self._state != "running":
                raise _verdant.ArgumentError("set_state: the actions run past the episode's end")
            self._act(a)
        raw = self._h.observe()
        return self._observation(raw), self._info(raw, [])

    def __getstate__(self):
        if self._state == "closed":
            raise TypeError("a closed HarvestEnv cannot be pickled")
        return {"kwargs": self._kwargs,
                "state": self.get_state() if self._state in ("running", "ended") else None}

    def __setstate__(self, d):
        self.__init__(**d["kwargs"])
        if d["state"] is not None:
            self.set_state(d["state"])

    def render(self):
        """With render_mode='rgb_array': the scene from the side (uint8 H x W x 3), the plant in
        its current state and the robot's collision shapes."""
        if self.render_mode != "rgb_array":
            return None
        return self._draw(camera="orbit", azimuth=-60, elevation=20, masks=False, depth=False,
                          size=(320, 240))["rgb"]

    def close(self):
        """Free the episode and the renderer; calling it again is fine."""
        self._renderer = None
        self._state = "closed"
        self._h.close()

    # ------------------------------------------------------------------------------------------

    def _draw(self, size, **kw):
        from . import Renderer

        if self._renderer is None or self._renderer.size != tuple(size):
            self._renderer = Renderer(size=size, legend=False, max_geoms=100000)
        return self._renderer.draw(self._h, **kw)

    def _wrist(self, raw):
        # the wrist camera (WRIST_CAMERA): "back" behind the tool point along the approach axis
        # (+z) and "side" along +x (normal to the fingers' opening axis, so the fingers stay out
        # of the picture), aimed at the point "aim" ahead of the tool point; image up +x
        w, x, y, z = raw["ee_quat"]
        R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        eye = raw["ee_pos"] - WRIST_CAMERA["back"] * R[:, 2] + WRIST_CAMERA["side"] * R[:, 0]
        return eye, raw["ee_pos"] + WRIST_CAMERA["aim"] * R[:, 2], R[:, 0]

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
            f = self._draw(self.image_size, eye=eye, lookat=lookat, up=up, fov=self.camera_fov,
                           depth=self.masks, masks=self.masks)
            obs["rgb"] = f["rgb"]
            obs["camera_K"], obs["camera_pose"] = f["K"], f["pose"]
            if self.masks:
                obs["depth"], obs["label"], obs["instance"] = f["depth"], f["label"], f["instance"]
                obs["target_visible"] = self._visible(raw, f)
        if self.cloud:
            c = self._h.cloud(points=self.cloud_points, scanners=[tuple(eye) + tuple(lookat)],
                              occlusion=True, threads=1, seed=int(raw["step"]))
            obs["cloud_xyz"], obs["cloud_label"] = np.array(c.xyz), np.array(c.label)
            obs["cloud_instance"] = np.array(c.instance)
        return obs

    def _visible(self, raw, f):
        """The target's visible fraction: its pixels in the instance mask over the pixels its
        sphere would cover unoccluded, pi (fx r / z)^2 (r its radius, z its depth along the
        optical axis), at most 1; 0 behind the camera."""
        if self._target_radius is None or self._target_radius[0] != raw["target_instance"]:
            p = self._h.plant()
            r = p.sphere_radii[p.sphere_instances == raw["target_instance"]]
            self._target_radius = (raw["target_instance"], float(r.max()) if len(r) else 0.02)
        pose, K = f["pose"], f["K"]
        z = float((raw["fruit_pos"] - pose[:3, 3]) @ pose[:3, 2])
        seen = int(np.count_nonzero(f["instance"] == raw["target_instance"]))
        if z <= 1e-6:
            return np.zeros(1, np.float32)
        full = np.pi * (K[0, 0] * self._target_radius[1] / z) ** 2
        return np.array([min(1.0, seen / max(full, 1e-9))], np.float32)

    def _info(self, raw, events):
        return {"time": raw["time"], "phase": raw["phase"], "target_instance": raw["target_instance"],
                "detached": raw["detached"], "site": raw["site"], "events": events,
                "episode": self._episode, "seed": self._seed}

    def __repr__(self):
        i = self._h.info
        return f"<verdant.HarvestEnv {i['scene'] or 'scene'}: {i['method']}, {i['nq']} joints>"


if _gym is not None and ENV_ID not in _gym.registry:
    _gym.register(id=ENV_ID, entry_point="verdant.env:HarvestEnv",
                  vector_entry_point="verdant.vector:VectorHarvestEnv")
