# SPDX-License-Identifier: MIT
"""The README's Python command prints what the README says, and the tour's code in
docs/python.md runs (blocks that need a display are left out)."""
import os
import re
import subprocess
import sys
import warnings

import pytest
from conftest import SRC


def test_readme_command():
    text = open(os.path.join(SRC, "README.md")).read()
    lines = text.splitlines()
    runs = [i for i, l in enumerate(lines) if l.startswith("PYTHONPATH=build/python /usr/bin/python3 -c ")]
    assert runs, "the README's Python command is gone"
    for i in runs:
        code = re.match(r'PYTHONPATH=build/python /usr/bin/python3 -c "(.*)"$', lines[i]).group(1)
        expected = re.match(r"# prints: (.*?)   ", lines[i + 1]).group(1)
        # the build tree under test (ctest's PYTHONPATH), from the source folder as documented
        r = subprocess.run([sys.executable, "-c", code], cwd=SRC, capture_output=True, text=True,
                           check=True)
        assert r.stdout.strip() == expected


def test_docs_tour_runs(tmp_path):
    text = open(os.path.join(SRC, "docs", "python.md")).read()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 3
    env = {}
    os.chdir(tmp_path)  # files the tour writes land here; its data/ paths point into the source
    try:
        for b in blocks:
            # blocks of an optional peer run only where it is installed (deps.sh --dev)
            peer = next((m for m in ("open3d", "torch") if re.search(rf"^(from|import) {m}\b", b, re.M)), None)
            if peer and not optional(peer):
                warnings.warn(f"skipped a docs/python.md block: {peer} is not installed (scripts/deps.sh --dev)")
                continue
            if peer == "open3d":
                b = b.replace("o3d.visualization.draw_geometries", "(lambda g: g)")
            if "bad.lpy" in b:
                continue  # an illustration of errors
            b = b.replace('"data/', f'"{SRC}/data/')
            exec(compile(b, "docs/python.md", "exec"), env)
    finally:
        os.chdir(os.path.dirname(__file__))


def optional(name):
    """Whether the optional module `name` imports (torch, open3d: scripts/deps.sh --dev)."""
    try:
        __import__(name)
        return True
    except ImportError:
        return False


def missing_docstrings(mod, names):
    import inspect

    missing = []
    for name in names:
        obj = getattr(mod, name)
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for attr in dir(obj):
                if attr.startswith("_"):
                    continue
                if not (getattr(getattr(obj, attr), "__doc__", None) or "").strip():
                    missing.append(f"{name}.{attr}")
    return missing


def test_every_public_name_has_a_docstring():
    import verdant

    missing = missing_docstrings(verdant, verdant.__all__)
    assert not missing, missing


def test_torch_names_have_docstrings():
    pytest.importorskip("torch", reason="python3-torch is not installed (scripts/deps.sh --dev)")
    import verdant.torch as vt

    missing = missing_docstrings(vt, ["PlantCloudDataset", "collate_ragged"])
    assert not missing, missing
