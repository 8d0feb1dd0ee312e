# SPDX-License-Identifier: MIT
"""Shared fixtures of the Python tests: the source tree, the verdant command (the peer every
result is compared with, byte for byte) and a runner for it. ctest sets VERDANT_CLI,
VERDANT_SOURCE_DIR and PYTHONPATH (build/python); by hand:
    PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests
"""
import os
import subprocess

import pytest

SRC = os.environ.get("VERDANT_SOURCE_DIR") or os.path.dirname(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CLI = os.environ.get("VERDANT_CLI") or os.path.join(SRC, "build", "verdant")


def data(name):
    """Path of a bundled file under data/."""
    return os.path.join(SRC, "data", name)


@pytest.fixture
def src():
    return SRC


@pytest.fixture
def cli():
    """Run `verdant ARGS...`; returns the CompletedProcess (check=True unless told)."""
    def run(*args, check=True):
        return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, check=check)
    return run


def read(path):
    with open(path, "rb") as f:
        return f.read()
