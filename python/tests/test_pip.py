# SPDX-License-Identifier: MIT
"""`pip install ./python` works offline: into a fresh virtual environment that sees Debian's
packages (numpy), from a copy of python/ (VERDANT_SOURCE_DIR names the source tree), and the
installed package grows the same plant as the build tree's. (Its own ctest entry: python_pip.)"""
import os
import shutil
import subprocess
import sys

import verdant
from conftest import SRC, data


def test_pip_install_offline(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", venv], check=True)
    shutil.copytree(os.path.join(SRC, "python"), tmp_path / "python",
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__", "tests"))
    env = dict(os.environ, VERDANT_SOURCE_DIR=SRC, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    env.pop("PYTHONPATH", None)  # the installed package, not the build tree's
    r = subprocess.run([venv / "bin" / "pip", "install", "--no-build-isolation", tmp_path / "python"],
                       env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    code = ("import verdant, sys; p = verdant.grow(sys.argv[1], seed=3); "
            "print(verdant.__file__); print(p.cloud(points=1000).pos.sum().hex())")
    r = subprocess.run([venv / "bin" / "python", "-c", code, data("tomato.lpy")], env=env, cwd=tmp_path,
                       capture_output=True, text=True, check=True)
    where, total = r.stdout.split()
    assert where.startswith(str(venv))
    assert total == verdant.grow(data("tomato.lpy"), seed=3).cloud(points=1000).pos.sum().hex()
