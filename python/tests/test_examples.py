# SPDX-License-Identifier: MIT
"""examples/python/ run (at small sizes) and end without an error."""
import os
import subprocess
import sys

import pytest

import verdant
from conftest import SRC

# the package under test, wherever the examples run from
ENV = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(os.path.abspath(verdant.__file__))))

QUICK = {
    "grow_and_cloud.py": ["--points", "20000"],
    "sim_pick.py": ["--duration", "0.3"],
    "render_masks.py": [],
    "torch_dataset.py": ["--steps", "3", "--points", "512"],
    "parallel_plants.py": ["--count", "2", "--steps", "30"],
    "harvest_env.py": ["--episodes", "1"],
    "train_pick.py": ["--iterations", "2", "--population", "4", "--steps", "60"],
}


def test_every_example_is_listed():
    assert sorted(f for f in os.listdir(os.path.join(SRC, "examples", "python")) if f.endswith(".py")) == sorted(QUICK)


@pytest.mark.parametrize("name", sorted(QUICK))
def test_example_runs(tmp_path, name):
    if name == "torch_dataset.py":
        pytest.importorskip("torch")
    r = subprocess.run([sys.executable, os.path.join(SRC, "examples", "python", name), *QUICK[name]],
                       cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert r.stdout.strip()
