# SPDX-License-Identifier: MIT
"""Pictures: the same pixels as `verdant render`, masks and depth consistent with the
intrinsics and pose, simulation states with colliders, clouds, bad arguments."""
import threading

import numpy as np
import pytest

import verdant
from conftest import data


@pytest.fixture(scope="module")
def tomato():
    return verdant.grow(data("tomato.lpy"), seed=3)


@pytest.fixture(scope="module")
def renderer():
    try:
        return verdant.Renderer(size=(320, 240))
    except verdant.UnsupportedError as e:  # no OpenGL context on this machine (Mesa is in deps)
        pytest.fail(f"no OpenGL context: {e}")


@pytest.mark.parametrize("camera,flags", [({"camera": "front"}, ["--camera", "front"]),
                                          ({"azimuth": 30, "elevation": 10, "fov": 30}, ["--camera", "orbit:30:10", "--fov", "30"]),
                                          ({"eye": (1.5, -1, 1), "lookat": (0, 0, 0.6)}, ["--eye", "1.5,-1,1", "--lookat", "0,0,0.6"])])
def test_pixels_equal_cli(tmp_path, cli, tomato, renderer, camera, flags):
    f = renderer.draw(tomato, **camera)
    out = tmp_path / "t.png"
    cli("render", data("tomato.lpy"), "--seed", "3", "--size", "320x240", "--depth", "--masks", *flags, "-o", out)
    assert np.array_equal(f["rgb"], verdant.read_png(out))
    assert np.array_equal(f["label"], verdant.read_png(tmp_path / "t.label.png"))
    assert np.array_equal(f["instance"], verdant.read_png(tmp_path / "t.instance.png"))
    mm = verdant.read_png(tmp_path / "t.depth.png").astype(np.int64)
    ours = np.where(f["depth"] > 0, np.maximum(1, np.floor(f["depth"].astype(np.float64) * 1000 + 0.5)), 0)
    assert np.abs(ours - mm).max() <= 1          # float32 depth against millimetres


def test_frame_geometry(tomato, renderer):
    f = renderer.draw(tomato, camera="side")
    h, w = f["label"].shape
    assert f["rgb"].shape == (h, w, 3) and f["rgb"].dtype == np.uint8 and (h, w) == (240, 320)
    assert f["depth"].dtype == np.float32 and f["label"].dtype == np.int32
    lab = f["label"]
    assert set(np.unique(lab)) - {0} <= set(tomato.label_names) and (lab == 5).any()
    assert (f["depth"][lab > 0] > 0).all()                  # (the floor has depth, label 0)
    assert (f["instance"][lab > 0] > 0).all()
    # back-project every plant pixel with K and pose: it lands on the plant
    K, pose = f["K"], f["pose"]
    v, u = np.nonzero(lab)
    z = f["depth"][v, u].astype(np.float64)
    cam = np.stack([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z])
    world = (pose[:3, :3] @ cam).T + pose[:3, 3]
    g = tomato._geometry
    lo, hi = np.array(g["bbox_min"]) - 0.01, np.array(g["bbox_max"]) + 0.01
    assert ((world >= lo) & (world <= hi)).all(axis=1).mean() > 0.999
    # the fruit pixels are the fruits' surfaces: within a radius of a fruit centre
    fruit = tomato.spheres[tomato.sphere_labels == 5]
    wf = world[lab[v, u] == 5]
    d = np.linalg.norm(wf[:, None, :] - fruit[None, :, :], axis=2).min(axis=1)
    assert np.median(d) < tomato.sphere_radii.max() * 1.2
    assert f["legend"][0]["name"] == "stem" and "range" not in f


def test_sim_and_cloud(tomato, renderer):
    s = verdant.Sim(tomato, sag_free=True)
    s.add_collider("sphere", size=0.05, pos=(0.2, 0, 0.8))
    s.step(20)
    f = renderer.draw(s, color_by="stress", camera="front")
    assert (f["label"] == 65535).any()                      # the collider, labelled as robots are
    assert f["range"][1] > f["range"][0] >= 0
    f2 = renderer.draw(s, color_by="displacement", range=(0, 0.01), depth=False, masks=False)
    assert set(f2) >= {"rgb", "K", "pose"} and "depth" not in f2 and f2["range"] == (0, 0.01)
    c = tomato.cloud(points=20000)
    f3 = renderer.draw(c, point_size=0.003, color_by="instance")
    assert (f3["label"] > 0).mean() > 0.01
    both = verdant.render([tomato, c], size=(160, 120))
    assert both["rgb"].shape == (120, 160, 3)
    assert verdant.render(tomato, size=(160, 120))["rgb"].shape == (120, 160, 3)


def test_renderer_between_threads(tomato, renderer):
    ref = renderer.draw(tomato, masks=False)["rgb"]
    out = []
    t = threading.Thread(target=lambda: out.append(renderer.draw(tomato, masks=False)["rgb"]))
    t.start()
    t.join()
    assert np.array_equal(out[0], ref)


BAD = [({"camera": "fisheye"}, verdant.ArgumentError), ({"camera": 3}, TypeError),
       ({"eye": (1, 1, 1)}, verdant.ArgumentError), ({"eye": (1, 1, 1), "lookat": (1, 1, 1)}, verdant.BadValueError),
       ({"fov": 0}, verdant.ArgumentError), ({"elevation": 100}, verdant.ArgumentError),
       ({"color_by": "heat"}, verdant.ArgumentError), ({"color_by": "stress"}, verdant.ArgumentError),
       ({"range": (1, 0)}, verdant.ArgumentError), ({"point_size": -1}, verdant.ArgumentError),
       ({"robot_qpos": [0.1, 0.2]}, verdant.Error), ({"shading": 1}, TypeError)]


@pytest.mark.parametrize("kw,exc", BAD)
def test_bad_render_arguments(tomato, renderer, kw, exc):
    with pytest.raises(exc):
        renderer.draw(tomato, **kw)


def test_bad_render_objects(tomato, renderer):
    with pytest.raises(TypeError):
        renderer.draw("tomato.lpy")
    with pytest.raises(verdant.ArgumentError):
        renderer.draw([])
    with pytest.raises(verdant.ArgumentError):
        renderer.draw(tomato.cloud(points=100), color_by="displacement")
    s = verdant.Sim(tomato)
    with pytest.raises(verdant.ArgumentError):
        renderer.draw([s, s])
    for kw in ({"size": (0, 10)}, {"size": (10.5, 10)}, {"supersample": 9}, {"background": (2, 0, 0)}):
        with pytest.raises(verdant.ArgumentError):
            verdant.Renderer(**kw)
    with pytest.raises(verdant.FormatError):
        verdant.Renderer(robot=data("tomato.lpy"))
    with pytest.raises(verdant.FileError):
        verdant.read_png("/nonexistent.png")
