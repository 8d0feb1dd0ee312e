# SPDX-License-Identifier: MIT
"""Pick a tomato by pulling it: a force ramped on the first fruit until its stalk breaks, the
plant swinging in a breeze; prints the fracture events and stress, and draws the final state
with its stress colours (the picture's arrays are saved as .npz).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/sim_pick.py [--duration 1.0]
"""
import argparse
import os

import numpy as np

import verdant

here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--duration", type=float, default=1.0, help="simulated seconds")
ap.add_argument("--force", type=float, default=4.0, help="largest pull (N)")
ap.add_argument("-o", "--output", default="tomato_pick.npz")
a = ap.parse_args()

plant = verdant.grow(os.path.join(here, "..", "..", "data", "tomato.lpy"), seed=3)
sim = verdant.Sim(plant, sag_free=True, wind=(3, 0, 0))       # = verdant sim --sag-free --wind 3,0,0
fruit = sim.find_organ("fruit")
steps = round(a.duration / sim.options["dt"])
for k in range(steps):
    ramp = min(1.0, k / (0.8 * steps))
    sim.apply_force(fruit, (0, 0, -a.force * ramp))           # N, downwards
    sim.step()
    if sim.events:                                            # picked: 50 ms more, then stop
        sim.apply_force(fruit, (0, 0, 0))
        sim.step(50)
        break
for e in sim.events:
    print(f"t = {e['time']:.3f} s: {e['label_name']} #{e['instance']} broke "
          f"({e['cause']}, {e['force']:.2f} N)")
st = sim.stats
print(f"{st['steps']} steps, tip moved {st['tip_displacement'] * 1000:.1f} mm, "
      f"largest bending stress {sim.stress.max() / 1e6:.2f} MPa")

try:
    pic = verdant.render(sim, color_by="stress", camera="front", size=(480, 360))
    np.savez_compressed(a.output, **{k: pic[k] for k in ("rgb", "depth", "label", "instance", "K", "pose")})
    print(f"picture arrays in {a.output}")
except verdant.UnsupportedError as err:   # no OpenGL here
    print("no picture:", err)
