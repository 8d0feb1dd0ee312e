# SPDX-License-Identifier: MIT
# Type stubs of verdant's C extension (python/src/*.c); the pure-Python layer (verdant/__init__.py,
# env.py, vector.py) subclasses these types. Arrays are numpy views unless said otherwise.
import os
from typing import Any, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, bytes, "os.PathLike[str]"]
Vec3 = Union[Sequence[float], npt.NDArray[np.floating]]
F64 = npt.NDArray[np.float64]
I32 = npt.NDArray[np.int32]

version: str

class Error(Exception):
    status: str
    file: str
    line: int
    column: int
    message: str

class ParseError(Error): ...
class UnsupportedError(Error): ...
class UndefinedNameError(Error): ...
class WrongTypeError(Error, TypeError): ...
class BadValueError(Error, ValueError): ...
class ModelAssertionError(Error): ...
class LimitError(Error): ...
class FileError(Error, OSError):
    errno: int
    strerror: str
    filename: Optional[str]
class FormatError(Error): ...
class OutOfMemoryError(Error, MemoryError): ...
class ArgumentError(Error, ValueError): ...

def grow(source: Union[PathLike, str], *, seed: int = 0, steps: Optional[int] = None,
         set: Optional[Mapping[str, Any]] = None, labels: Optional[Mapping[int, str]] = None,
         max_modules: int = 50000000, max_ops: int = 1000000000, curve_step: Optional[float] = None,
         curve_connect: Optional[float] = None, curve_distance: Optional[float] = None,
         engine: str = "auto", instances: str = "organs") -> Plant: ...
def load(path: PathLike, *, labels: Optional[Mapping[int, str]] = None, seed: int = 0) -> Plant: ...
def read_cloud(path: PathLike) -> Cloud: ...
def read_png(path: PathLike) -> npt.NDArray[np.uint8]: ...
def alloc_bytes() -> int: ...
def _cloud_unpickle(data: bytes, stats: dict[str, Any], /) -> Cloud: ...
def _register(plant: Optional[type] = None, mesh: Optional[type] = None,
              cloud: Optional[type] = None) -> None: ...

class Plant:
    nodes: F64
    segments: I32
    radii: F64
    labels: I32
    instances: I32
    parents: I32
    axes: I32
    orders: I32
    frames: F64
    spheres: F64
    sphere_radii: F64
    sphere_labels: I32
    sphere_instances: I32
    sphere_nodes: I32
    vertices: F64
    triangles: I32
    mesh_vertex_range: I32
    mesh_triangle_range: I32
    mesh_labels: I32
    mesh_instances: I32
    mesh_closed: I32
    label_names: dict[int, str]
    label_table: list[dict[str, Any]]
    seed: int
    source: str
    traits: list[dict[str, Any]]
    _info: dict[str, Any]
    _geometry: dict[str, Any]
    def save(self, path: PathLike, *, ascii: bool = False) -> None: ...
    def mesh(self, *, slices: Optional[int] = None, stacks: Optional[int] = None,
             caps: bool = True) -> Mesh: ...
    def _cloud(self, **options: Any) -> Cloud: ...
    def __reduce__(self) -> Tuple[Any, ...]: ...

class Mesh:
    vertices: F64
    normals: F64
    triangles: I32
    label: I32
    instance: I32
    prim: I32
    kind: I32
    labels: dict[int, str]
    plant: Plant
    def save(self, path: PathLike, *, ascii: bool = False) -> None: ...

class Cloud:
    xyz: npt.NDArray[np.float32]
    pos: F64
    normals: F64
    label: I32
    instance: I32
    view: I32
    range: F64
    labels: dict[int, str]
    label_table: list[dict[str, Any]]
    stats: dict[str, Any]
    seed: int
    nview: int
    def __len__(self) -> int: ...
    def save(self, path: PathLike, *, ascii: bool = False, ply_prefix: Optional[str] = None,
             comment: Optional[str] = None, threads: Optional[int] = None) -> None: ...
    def __reduce__(self) -> Tuple[Any, ...]: ...

class Sim:
    node_pos: F64
    node_vel: F64
    node_force: F64
    node_mass: F64
    seg_quat: F64
    seg_omega: F64
    seg_torque: F64
    seg_broken: npt.NDArray[np.int8]
    node_pos0: F64
    seg_node: I32
    seg_label: I32
    seg_instance: I32
    seg_class: I32
    seg_radius: F64
    seg_len0: F64
    stress: F64
    plant_stress: F64
    events: list[dict[str, Any]]
    stats: dict[str, Any]
    colliders: list[dict[str, Any]]
    options: dict[str, Any]
    time: float
    nstep: int
    initial_plant: Plant
    def __init__(self, plant: Plant, **options: Any) -> None: ...
    def step(self, n: int = 1) -> None: ...
    def settle(self, *, statics: bool = False, ke_tol: float = 1e-9, disp_tol: float = 1e-9,
               max_time: float = 10, max_steps: int = 400,
               extra_damping: float = 5) -> Tuple[bool, int]: ...
    def reset(self) -> None: ...
    def set(self, **options: Any) -> None: ...
    def add_collider(self, shape: str, size: Union[None, float, Sequence[float]] = None,
                     pos: Vec3 = (0, 0, 0), quat: Sequence[float] = (1, 0, 0, 0)) -> int: ...
    def add_mesh_collider(self, vertices: npt.ArrayLike, triangles: npt.ArrayLike,
                          pos: Vec3 = (0, 0, 0), quat: Sequence[float] = (1, 0, 0, 0),
                          cell: Optional[float] = None) -> int: ...
    def move_collider(self, index: int, pos: Vec3, quat: Optional[Sequence[float]] = None) -> None: ...
    def find_organ(self, organ: Union[int, str], instance: int = 0) -> int: ...
    def apply_force(self, node_or_organ: Union[int, str], force: Vec3, instance: int = 0) -> int: ...
    def add_tie(self, node_or_organ: Union[int, str], target: Optional[Vec3] = None,
                compliance: float = 1e-5, instance: int = 0) -> int: ...
    def move_tie(self, index: int, target: Vec3) -> None: ...
    def get_state(self) -> bytes: ...
    def set_state(self, state: Union[bytes, bytearray, memoryview], /) -> None: ...
    def plant(self) -> Plant: ...

class Renderer:
    size: Tuple[int, int]
    info: str
    max_geoms: int
    def __init__(self, *, size: Tuple[int, int] = (640, 480), supersample: int = 2,
                 shadows: bool = True, floor: bool = True, sky: bool = True,
                 background: Optional[Sequence[float]] = None, legend: bool = True,
                 robot: Optional[PathLike] = None, max_geoms: int = 20000) -> None: ...
    def draw(self, objects: Any, **options: Any) -> dict[str, Any]: ...

class Harvest:
    done: bool
    info: dict[str, Any]
    qpos: F64
    def __init__(self, scene: Union[PathLike, str]) -> None: ...
    def reset(self, seed: int, episode: int = 0, *, randomize: bool = True) -> int: ...
    def step(self, lin_vel: Vec3, ang_vel: Vec3, gripper: float) -> bool: ...
    def act(self, lin_vel: Vec3, ang_vel: Vec3, gripper: float, weights: Sequence[float],
            terminate_on_detach: bool = True, max_steps: Optional[int] = None
            ) -> Tuple[bool, float, dict[str, float], bool, bool, str, list[dict[str, Any]]]: ...
    def close(self) -> None: ...
    def run(self, until: Optional[str] = None) -> bool: ...
    def observe(self) -> dict[str, Any]: ...
    def events(self, since: int = 0) -> list[dict[str, Any]]: ...
    def summary(self) -> dict[str, Any]: ...
    def forces(self) -> dict[str, Any]: ...
    def cloud(self, **options: Any) -> Cloud: ...
    def plant(self) -> Plant: ...

class VectorHarvest:
    num_envs: int
    threads: int
    nq: int
    control_dt: float
    def __init__(self, scene: Union[PathLike, str], num_envs: int, threads: int,
                 weights: Sequence[float], terminate_on_detach: bool = True,
                 max_steps: Optional[int] = None, randomize: bool = True) -> None: ...
    def reset(self, seeds: Sequence[int]) -> Tuple[dict[str, npt.NDArray[Any]], dict[str, Any]]: ...
    def step(self, actions: npt.ArrayLike) -> Tuple[dict[str, npt.NDArray[Any]], F64,
                                                   npt.NDArray[np.bool_], npt.NDArray[np.bool_],
                                                   dict[str, Any]]: ...
    def close(self) -> None: ...
