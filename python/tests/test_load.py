# SPDX-License-Identifier: MIT
"""One way in (issue 22): the same file through the C API (vd_plant_load, in build/example_load),
the command line (verdant grow) and Python (verdant.grow) makes the same plant, ids and bytes,
for every input format and instance mode; and growth (verdant sim --grow) numbers instances as
they do."""
import os
import subprocess

import pytest

import verdant
from conftest import CLI, data, read

EXAMPLE = os.path.join(os.path.dirname(CLI), "example_load")


def through_all(tmp_path, src, instances, tag):
    """The plant JSON bytes of src from the C API, the command line and Python."""
    out = {k: str(tmp_path / f"{tag}_{k}.json") for k in ("c", "cli", "py")}
    mode = [instances] if instances else []
    subprocess.run([EXAMPLE, src, out["c"], *mode], check=True, capture_output=True)
    subprocess.run([CLI, "grow", src, "-o", out["cli"], "--no-progress",
                    *(["--instances", instances] if instances else [])], check=True, capture_output=True)
    kw = {"instances": instances} if instances else {}
    verdant.grow(src, **kw).save(out["py"])
    return {k: read(v) for k, v in out.items()}


@pytest.mark.parametrize("name,instances", [("tomato.lpy", None), ("tomato.lpy", "modules"),
                                            ("curves_tomato.json", None), ("curves_tomato.json", "modules")])
def test_same_plant_through_every_front_end(tmp_path, name, instances):
    if not os.path.exists(EXAMPLE):
        pytest.skip(f"{EXAMPLE} not built")
    got = through_all(tmp_path, data(name), instances, "x")
    assert got["c"] == got["cli"], f"{name}: the C API and the command line differ"
    assert got["py"] == got["cli"], f"{name}: Python and the command line differ"


def test_plant_file_instances_applied_everywhere(tmp_path):
    """A plant file keeps its numbering unless asked; asked, every front end renumbers (Python's
    grow("x.json", instances=...) was ignored)."""
    if not os.path.exists(EXAMPLE):
        pytest.skip(f"{EXAMPLE} not built")
    src = str(tmp_path / "modules.json")
    subprocess.run([CLI, "grow", data("tomato.lpy"), "-o", src, "--instances", "modules", "--no-progress"],
                   check=True, capture_output=True)
    kept = through_all(tmp_path, src, None, "kept")
    organs = through_all(tmp_path, src, "organs", "organs")
    for got in (kept, organs):
        assert got["c"] == got["cli"] == got["py"]
    assert kept["cli"] == read(src)
    assert verdant.grow(src).stats["instances"] > verdant.grow(src, instances="organs").stats["instances"]


def test_growth_numbers_instances_as_grow(tmp_path):
    """verdant sim --grow draws each age with the loader's naming: as many instances as verdant grow
    makes of the same derivation (organs), not one per module."""
    run = tmp_path / "run"
    subprocess.run([CLI, "sim", data("tomato.lpy"), "--grow", "--ages", "2", "--substeps", "2", "--model", "rods",
                    "-o", str(run)], check=True, capture_output=True)
    grown = verdant.load(str(run / "plant.json"))
    drawn = verdant.grow(data("tomato.lpy"), steps=2)
    assert grown.stats["instances"] == drawn.stats["instances"]
    assert grown.stats["labels"] == drawn.stats["labels"]  # organ instances per label name
