# SPDX-License-Identifier: MIT
"""verdant: virtual plants from L-systems, with labels, physics and sensors.

A thin layer over verdant's C library (the extension module verdant._verdant). Arrays are numpy
views of the library's own memory where it holds them contiguously (a view keeps its owner
alive); long calls release the GIL; failures raise verdant.Error subclasses that carry the
file, line, column and message of the fault.

    >>> import verdant
    >>> p = verdant.grow("data/tomato.lpy", seed=3)       # an L-Py file, a plant or curves JSON
    >>> c = p.cloud(points=100000)                          # labelled points
    >>> c.xyz.shape, sorted(set(c.label))
    ((100000, 3), [1, 2, 3, 4, 5, 6])

See docs/python.md for the tour: plants, clouds, Open3D, simulation, pictures, datasets.
"""

try:
    from . import _verdant
except ImportError as e:  # the usual cause: another interpreter than the one it was built for
    import sys as _sys

    raise ImportError(
        f"verdant's extension module did not load in {_sys.executable} ({e}). It is built for "
        "Debian's /usr/bin/python3 with python3-numpy (make python; then "
        "PYTHONPATH=build/python /usr/bin/python3), or installed with pip into that Python."
    ) from e

from ._verdant import (  # noqa: F401  (the exception classes are part of the API)
    ArgumentError,
    BadValueError,
    Error,
    FileError,
    FormatError,
    LimitError,
    ModelAssertionError,
    OutOfMemoryError,
    ParseError,
    UndefinedNameError,
    UnsupportedError,
    WrongTypeError,
    alloc_bytes,
    read_png,
)

__version__ = _verdant.version

__all__ = [
    "grow", "load", "read_cloud", "read_png", "render", "Plant", "Mesh", "Cloud", "Sim",
    "Renderer", "HarvestEnv", "VectorHarvestEnv",
    "Error", "ParseError", "UnsupportedError", "UndefinedNameError", "WrongTypeError",
    "BadValueError", "ModelAssertionError", "LimitError", "FileError", "FormatError",
    "OutOfMemoryError", "ArgumentError",
]


def _label_colors(table, ids):
    """RGB in [0, 1] per id from a label table (grey for ids without an entry)."""
    import numpy as np

    lut = {e["id"]: e["rgb"] for e in table}
    uniq, inv = np.unique(np.asarray(ids), return_inverse=True)
    rgb = np.array([lut.get(int(u), (0.6, 0.6, 0.6)) for u in uniq], dtype=np.float64)
    return rgb.reshape(-1, 3)[inv] if len(uniq) else np.zeros((0, 3))


def _through_file(name, write, read):
    """write(path) into a private temporary folder, then read(path): pickling by file formats."""
    import os
    import tempfile

    with tempfile.TemporaryDirectory(prefix="verdant-pickle-") as d:
        path = os.path.join(d, name)
        write(path)
        return read(path)


def _unpickle_plant(text, seed):
    return _verdant.grow(text, seed=seed)


def _read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def _open3d():
    try:
        import open3d
    except ImportError as e:
        raise ImportError("to_open3d needs Open3D (Debian: apt-get install python3-open3d)") from e
    return open3d


class Plant(_verdant.Plant):
    """A labelled plant: segments (frustums between nodes), spheres and triangle meshes, each
    with a semantic label and an organ instance id. Made by verdant.grow or verdant.load.

    Arrays (read-only numpy views of the compiled plant, no copies): nodes (n x 3, m),
    segments (m x 2 node indices), radii (m x 2, m), labels and instances (m), parents, axes,
    orders, frames (m x 4 quaternions), spheres (k x 3), sphere_radii, sphere_labels,
    sphere_instances, sphere_nodes, vertices and triangles of the leaf meshes, mesh_labels,
    mesh_instances, mesh_closed, mesh_vertex_range, mesh_triangle_range.
    label_names is {id: name}; stats is the summary `verdant grow --stats` prints.
    """

    __slots__ = ()

    def cloud(self, *, points=None, sensor=None, scanners=None, noise=None, occlusion=None,
              interior=None, density_law=None, pattern=None, fov=None, res=None, labels=None,
              slices=None, seed=None, threads=None, max_points=None):
        """Sample a labelled point cloud of the plant (the options of `verdant cloud`).

        points: points of the surface sensors (default 100000).
        sensor: 'uniform' (default), 'distance' (density falling with distance from the
            scanners) or 'scan' (rays on each scanner's grid; the hits are the points).
        scanners: scanner positions (x, y, z) looking at the plant's bounding-box centre, or
            (x, y, z, tx, ty, tz) with a target, in metres, and/or preset file paths
            (data/scanners/*.json), in order; one view each.
        noise: Gaussian noise sigma (m), or (sigma, slope): sigma + slope * distance.
        occlusion: keep only points a scanner sees. interior: remove points inside other
            closed organs (default True).
        density_law: 'inverse-square' (default), 'linear', 'constant' or [(d, g), ...].
        pattern, fov, res: scan rays: 'angular' or 'pinhole', (h, v) degrees, (w, h) rays.
        labels: 'semantic' (default) or 'instance' (label holds the instance id).
        slices: sides of every frustum and sphere (default: each primitive's own).
        seed: sampling seed (default: the plant's growth seed, as the command line does).
        threads: threads (default all cores); the points never depend on it.
        max_points: most points (default 50e6); more raises LimitError before any allocation.

        Returns a Cloud. The GIL is released while sampling.
        """
        kw = dict(points=points, sensor=sensor, scanners=scanners, noise=noise,
                  occlusion=occlusion, interior=interior, density_law=density_law,
                  pattern=pattern, fov=fov, res=res, labels=labels, slices=slices, seed=seed,
                  threads=threads, max_points=max_points)
        return self._cloud(**{k: v for k, v in kw.items() if v is not None})

    @property
    def stats(self):
        """The summary of `verdant grow --stats`: engine (.lpy only), modules, module_counts, nodes, segments,
        spheres, leaves, meshes, instances, labels (organ instances per label name), organs (per
        label name: count, length_m, area_m2, volume_m3, diameter_m_mean), bbox_min, bbox_max (m),
        total_length (m)."""
        import numpy as np

        info, geo = self._info, self._geometry
        keys = np.concatenate([
            (np.asarray(lab, np.int64) << 32) | np.asarray(ins, np.int64)
            for lab, ins in ((self.labels, self.instances),
                             (self.sphere_labels, self.sphere_instances),
                             (self.mesh_labels, self.mesh_instances))])
        per_label = np.unique(np.unique(keys) >> 32, return_counts=True)
        count = dict(zip(per_label[0].tolist(), per_label[1].tolist()))
        organs = {}
        traits = self.traits
        for e in self.label_table:
            mine = [t for t in traits if t["label"] == e["id"]]
            if mine:
                organs[e["name"]] = {
                    "count": len(mine), "length_m": sum(t["length_m"] for t in mine),
                    "area_m2": sum(t["area_m2"] for t in mine),
                    "volume_m3": sum(t["volume_m3"] for t in mine),
                    "diameter_m_mean": sum(t["diameter_m"] for t in mine) / len(mine)}
        return {
            **({"engine": info["engine"]} if info.get("engine") else {}),
            "modules": info.get("modules", 0),
            "module_counts": info.get("module_counts", {}),
            "nodes": geo["nodes"], "segments": geo["segments"], "spheres": geo["spheres"],
            "leaves": geo["leaves"], "meshes": geo["meshes"], "instances": geo["instances"],
            "labels": {e["name"]: count.get(e["id"], 0) for e in self.label_table},
            "organs": organs,
            "bbox_min": list(geo["bbox_min"]), "bbox_max": list(geo["bbox_max"]),
            "total_length": geo["total_length"],
        }

    def __reduce__(self):
        """Pickled as its plant JSON (exact: the file format keeps every number) and seed."""
        text = _through_file("plant.json", self.save, _read_bytes).decode("utf-8")
        return (_unpickle_plant, (text, self.seed))

    def to_open3d(self, slices=None):
        """The plant's labelled mesh as an open3d.geometry.TriangleMesh coloured by label."""
        return self.mesh(slices=slices).to_open3d()

    def __repr__(self):
        return (f"<verdant.Plant {self.source!r} seed={self.seed}: {len(self.nodes)} nodes, "
                f"{len(self.segments)} segments, {len(self.spheres)} spheres, "
                f"{len(self.mesh_labels)} meshes, labels {self.label_names}>")


class Mesh(_verdant.Mesh):
    """A labelled triangle mesh of a plant (Plant.mesh()): vertices, normals, triangles and per
    triangle label, instance, prim and kind, as read-only numpy views."""

    __slots__ = ()

    def to_open3d(self):
        """An open3d.geometry.TriangleMesh with vertex normals, coloured by label."""
        import numpy as np

        o3d = _open3d()
        # (Open3D takes writable arrays only: copies of the read-only views)
        m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(np.array(self.vertices)),
                                      o3d.utility.Vector3iVector(np.array(self.triangles)))
        m.vertex_normals = o3d.utility.Vector3dVector(np.array(self.normals))
        vlabel = np.zeros(len(self.vertices), np.int32)
        vlabel[self.triangles.reshape(-1)] = np.repeat(self.label, 3)
        m.vertex_colors = o3d.utility.Vector3dVector(_label_colors(self.plant.label_table, vlabel))
        return m

    def __repr__(self):
        return f"<verdant.Mesh {len(self.vertices)} vertices, {len(self.triangles)} triangles>"


class Cloud(_verdant.Cloud):
    """A labelled point cloud. xyz (float32 n x 3, a copy made once), pos (float64 n x 3, the
    library's array), normals, label, instance, view, range (read-only numpy views, no copies);
    labels is {id: name}; stats the sampling's counters; save(path) writes a file."""

    __slots__ = ()

    def to_open3d(self):
        """An open3d.geometry.PointCloud with normals, coloured by label."""
        import numpy as np

        o3d = _open3d()
        # (Open3D takes writable arrays only: copies of the read-only views)
        pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.array(self.pos)))
        pc.normals = o3d.utility.Vector3dVector(np.array(self.normals))
        pc.colors = o3d.utility.Vector3dVector(_label_colors(self.label_table, self.label))
        return pc

    def __repr__(self):
        return f"<verdant.Cloud {len(self)} points, labels {self.labels}>"


class Sim(_verdant.Sim):
    """Sim(plant, **options): the plant as Cosserat rods (XPBD with the exact tree solver), in SI
    units; the options of `verdant sim` (docs/physics.md):

    build: segment_length (m, 0.02), clamp_length (m, 0.01), clamp_roots, leaf_graphs,
        sag_free (the modelled shape is the equilibrium under gravity), stake (m, 0: none),
        max_segments; materials: young (Pa), density (kg/m^3), poisson, break_force (N),
        break_moment (N m), break_strain ((cs, cb)): a number for every class or
        {class: value} with classes green, wood, pedicel, leaf, fruit, flower, root;
        float('inf') disables a threshold.
    run (also set() between steps): dt (s, 1e-3), iterations, solver ('direct' or 'gs'),
        gravity (m/s^2), wind (m/s), gust ((amplitude, period s)), wind_series (rows t, vx, vy,
        vz), drag, stokes (Pa s), damping (s), mass_damping (1/s), fracture, contacts,
        friction, self_collision.
    ground: height of the ground plane (m, default 0), None for none.

    step(n) and settle() release the GIL, so threads step their own Sims side by side. Between
    steps: add_collider / add_mesh_collider / move_collider, apply_force (a node or an organ
    name), add_tie / move_tie, node_force and seg_torque (writable views). The state arrays
    (node_pos, node_vel, seg_quat, seg_broken, ...) are views of the state: they change with
    every step. stress is computed on access (Pa per rod segment); events lists fractures;
    stats is `verdant sim --stats`; plant() the deformed plant (`--final`).
    """

    __slots__ = ()

    def cloud(self, **options):
        """A labelled point cloud of the deformed plant: plant().cloud(**options)."""
        return self.plant().cloud(**options)

    def save(self, path, ascii=False):
        """Write the deformed plant (.json, .obj, .ply): plant().save(path)."""
        self.plant().save(path, ascii=ascii)

    def __repr__(self):
        return (f"<verdant.Sim t={self.time:.4g} s, {len(self.node_pos)} nodes, "
                f"{len(self.seg_quat)} rod segments, {len(self.colliders)} colliders>")


class Renderer(_verdant.Renderer):
    """Renderer(*, size=(640, 480), supersample=2, shadows=True, floor=True, sky=True,
    background=None, legend=True, robot=None, max_geoms=20000): an offscreen renderer (EGL and
    MuJoCo's renderer, headless; software rendering without a GPU). Its settings are fixed;
    draw(objects, ...) makes one picture (see verdant.render). Creating one costs 0.2-0.4 s with
    software rendering, so keep it for many pictures; it is used by one thread at a time and may
    be handed between threads. Raises UnsupportedError where no OpenGL context can be made."""

    __slots__ = ()

    def __repr__(self):
        w, h = self.size
        return f"<verdant.Renderer {w}x{h}: {self.info}>"


_local = __import__("threading").local()
# renderers verdant.render keeps per thread, one per settings (size, ...), least recently used
# dropped first
RENDERER_CACHE = 4


def _geoms_needed(objects):
    need = 16
    for o in objects:
        if isinstance(o, _verdant.Cloud):
            need += len(o)
        elif isinstance(o, _verdant.Sim):
            need += o.initial_plant._geometry["instances"] + len(o.colliders)
        elif isinstance(o, _verdant.Plant):
            need += o._geometry["instances"]
    return need


def render(objects, *, camera="orbit", azimuth=-60, elevation=20, eye=None, lookat=None,
           up=None, fov=45, size=(640, 480), masks=True, depth=True, color_by="label",
           range=None, point_size=None, supersample=2, shadows=True, floor=True, sky=True,
           legend=True, robot=None, robot_qpos=None, renderer=None):
    """Draw a Plant, a Sim (its current state, with its colliders) or a Cloud, or a list of
    them, headless, as `verdant render` does. Returns a dict of numpy arrays:

    rgb: H x W x 3 uint8 colour (with a legend unless legend=False);
    depth: H x W float32, metres along the optical axis, 0 where nothing (depth=True);
    label, instance: H x W int32 masks, 0 = background, exact (masks=True);
    K: 3 x 3 intrinsics (OpenCV: u = fx X/Z + cx, v = fy Y/Z + cy, pixel centres at integers);
    pose: 4 x 4 camera-to-world (columns: camera X right, Y down, Z forward; then the centre);
    intrinsics, camera (eye, lookat, up, fovy rad, znear, zfar), legend, and range (stress or
    displacement colour scale).

    camera: 'front', 'side', 'top' or 'orbit' (azimuth, elevation in degrees) fitted to the
    scene; or eye and lookat (m) with up and fov (degrees). color_by: 'label', 'instance',
    'stress' (a Sim), 'displacement'; range (min, max) of its scale (Pa or m). point_size:
    splat half-size of cloud points (m). robot: an MJCF file drawn at its reference pose or at
    robot_qpos. A renderer with these settings is kept per thread and reused, at most
    RENDERER_CACHE (4) per thread, the least recently used dropped (renderer= gives your own).
    Raises UnsupportedError where no OpenGL context can be made.
    """
    objs = list(objects) if isinstance(objects, (list, tuple)) else [objects]
    if renderer is None:
        key = (tuple(size), supersample, bool(shadows), bool(floor), bool(sky), bool(legend),
               None if robot is None else str(robot))
        cache = getattr(_local, "renderers", None)
        if cache is None:
            cache = _local.renderers = __import__("collections").OrderedDict()
        need = _geoms_needed(objs)
        renderer = cache.pop(key, None)
        if renderer is None or renderer.max_geoms < need:
            renderer = Renderer(size=size, supersample=supersample, shadows=shadows, floor=floor,
                                sky=sky, legend=legend, robot=robot, max_geoms=max(need, 20000))
        cache[key] = renderer                   # the most recently used last
        while len(cache) > RENDERER_CACHE:      # the least recently used goes (and its memory)
            cache.popitem(last=False)
    return renderer.draw(objs, camera=camera, azimuth=azimuth, elevation=elevation, eye=eye,
                         lookat=lookat, up=up, fov=fov, color_by=color_by, range=range,
                         point_size=point_size, depth=depth, masks=masks, robot_qpos=robot_qpos)


_verdant._register(plant=Plant, mesh=Mesh, cloud=Cloud)

from .env import HarvestEnv  # noqa: E402  (needs Plant and Renderer above)
from .vector import VectorHarvestEnv  # noqa: E402


def grow(source, *, seed=0, steps=None, set=None, labels=None, max_modules=None, max_ops=None,
         curve_step=None, curve_connect=None, curve_distance=None, engine=None, instances=None):
    """Grow a plant: derive an L-Py file (.lpy), read a plant file (.json), build one from a
    curves file (.json with "format": "verdant-curves"), or take the text itself (a str with a
    newline: L-Py, or JSON when it starts with '{').

    seed: random seed, as random.seed(seed) before the axiom (default 0); also the default seed
        of the plant's clouds. steps: derivation steps (default: the file's derivation length).
    set: {name: value} replacing globals of the L-system (values: Python expressions as str,
        numbers, bools, lists). labels: {id: name} naming label ids after the file's LABELS.
    max_modules (default 50e6), max_ops (default 1e9): limits (LimitError beyond).
    curve_step, curve_connect, curve_distance: curves files' sampling (m).
    engine: who runs the file's Python: 'auto' (default: the native subset interpreter when the
        file stays within it, else embedded CPython, as L-Py would), 'native' or 'python'.
    instances: L-Py sources: 'organs' (default: one instance per organ as a botanist names it, a
        pedicel with its knuckle is one) or 'modules' (one per L-string module).

    The same plant as `verdant grow SOURCE --seed SEED ...`. Raises ParseError, FileError, ...
    (verdant.Error subclasses with file, line, column, message). The GIL is released.
    """
    kw = dict(seed=seed, steps=steps, set=set, labels=labels, max_modules=max_modules,
              max_ops=max_ops, curve_step=curve_step, curve_connect=curve_connect,
              curve_distance=curve_distance, engine=engine, instances=instances)
    return _verdant.grow(source, **{k: v for k, v in kw.items() if v is not None})


def load(path, *, labels=None, seed=0):
    """Read a plant file (plant JSON, docs/formats.md). labels: {id: name} renames labels;
    seed: the default seed of its clouds."""
    return _verdant.load(path, labels=labels, seed=seed)


def read_cloud(path):
    """Read a cloud written by verdant (.ply .pcd .xyz .csv .las) into a Cloud."""
    return _verdant.read_cloud(path)
