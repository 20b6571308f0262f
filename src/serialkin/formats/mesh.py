"""Triangle meshes: loading mesh files (STL, OBJ, DAE, GLB/glTF, PLY), decimation, posing.

Loading uses trimesh (the optional extra ``serialkin[mesh]``: ``pip install
"serialkin[mesh]"``), imported lazily inside the functions that need it; kinematics never
needs it and ``import serialkin`` does not import it.

* :func:`load_mesh` reads a file into a :class:`TriangleMesh` (vertices in metres). A file
  holding a scene (DAE, GLB, OBJ with several objects) is flattened into one mesh with
  each node's transform applied; the ``<unit meter="...">`` of a COLLADA file is honoured
  (a file in millimetres is scaled by 0.001), as ROS tools do; STL and OBJ carry no unit
  and are read as metres (the URDF convention); glTF is metres by its specification.
  Then the per-axis ``scale`` (URDF ``<mesh scale>``) multiplies the coordinates. Loaded
  meshes are cached per (resolved path, modification time, size, scale).
* :func:`decimate` reduces a mesh to at most ``max_faces`` triangles by quadric edge
  collapse (trimesh's ``simplify_quadric_decimation``, through ``fast-simplification``).
* :func:`link_meshes` loads the visual or collision meshes of a robot
  (:attr:`Robot.geometry <serialkin.model.robot.Robot.geometry>`), each posed in its chain
  frame: vertex ``p`` of the file is placed at ``origin · diag(scale) · p``, so that its
  world position at joint values ``q`` is ``fk_all(q)[frame] · origin · diag(scale) · p``.
"""

from __future__ import annotations

import os
import threading
from collections import OrderedDict
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from serialkin._checks import check_choice, check_int, require, short_repr
from serialkin.errors import InputTypeError, NotSupportedError, RobotDefinitionError
from serialkin.model.geometry import Box, Capsule, Cylinder, Mesh, Sphere

__all__ = ["MESH_SUFFIXES", "LinkMesh", "TriangleMesh", "clear_mesh_cache", "decimate", "welded",
           "link_meshes", "load_mesh", "primitive_mesh"]

#: File suffixes :func:`load_mesh` reads (lower case) and the trimesh file type of each.
MESH_SUFFIXES = {".stl": "stl", ".obj": "obj", ".dae": "dae", ".glb": "glb", ".gltf": "gltf",
                 ".ply": "ply", ".off": "off"}

#: Most meshes kept in the cache of :func:`load_mesh`.
CACHE_SIZE = 256

#: Largest mesh file read [bytes].
MAX_MESH_BYTES = 256 * 1024 * 1024

_cache: OrderedDict[tuple, TriangleMesh] = OrderedDict()
_cache_lock = threading.Lock()


def _trimesh() -> Any:
    """Import trimesh, or raise naming the extra to install."""
    return require("trimesh", "mesh", "loading mesh files")


@dataclass(frozen=True, eq=False)
class TriangleMesh:
    """An indexed triangle mesh (read-only arrays).

    Attributes:
        vertices: (V, 3) float64 vertex positions [m].
        faces: (F, 3) int64 vertex indices of each triangle (counter-clockwise seen from
            outside for a well-formed closed mesh).
        source: the file the mesh was read from ('' if built in memory).
    """

    vertices: np.ndarray
    faces: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        """Validate the shapes, finiteness and index range; make the arrays read-only."""
        v = np.array(self.vertices, dtype=np.float64)
        f = np.array(self.faces)
        if v.ndim != 2 or v.shape[1] != 3:
            raise RobotDefinitionError(
                f"mesh vertices must have shape (V, 3), got {v.shape} ({self.source or 'mesh'})")
        if not np.isfinite(v).all():
            raise RobotDefinitionError(
                f"mesh vertices must be finite ({self.source or 'mesh'})")
        if f.size == 0:
            f = f.reshape(0, 3).astype(np.int64)
        if f.dtype.kind not in "iu" or f.ndim != 2 or f.shape[1] != 3:
            raise RobotDefinitionError(
                f"mesh faces must be an integer array of shape (F, 3), got {f.dtype} "
                f"{f.shape} ({self.source or 'mesh'})")
        f = f.astype(np.int64)
        if f.size and (f.min() < 0 or f.max() >= v.shape[0]):
            raise RobotDefinitionError(
                f"mesh faces index vertices outside 0..{v.shape[0] - 1} "
                f"({self.source or 'mesh'})")
        for name, a in (("vertices", v), ("faces", f)):
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        object.__setattr__(self, "source", str(self.source))

    def transformed(self, T: np.ndarray) -> TriangleMesh:
        """The mesh with every vertex mapped by the 4×4 transform ``T``: ``p' = R p + t``."""
        T = np.asarray(T, dtype=float)
        return TriangleMesh(self.vertices @ T[:3, :3].T + T[:3, 3], self.faces, self.source)

    @property
    def volume(self) -> float:
        """Enclosed volume [m³] by the divergence theorem, ``|Σ a·(b×c)| / 6``.

        Exact for a closed, consistently oriented mesh; an estimate otherwise.
        """
        tri = self.vertices[self.faces]
        return float(abs(np.einsum("ij,ij->i", tri[:, 0],
                                   np.cross(tri[:, 1], tri[:, 2])).sum()) / 6.0)

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3): the smallest and largest coordinate along x, y, z [m]."""
        if self.vertices.shape[0] == 0:
            return np.zeros((2, 3))
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])


def _scale3(scale: object) -> tuple[float, float, float]:
    try:
        s = np.asarray(scale, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputTypeError(f"scale must be 3 numbers, got {short_repr(scale)}") from None
    if s.shape == (1,):
        s = np.repeat(s, 3)
    if s.shape != (3,) or not np.isfinite(s).all() or (s <= 0).any():
        raise RobotDefinitionError(
            f"scale must be 3 finite numbers > 0, got {short_repr(scale)}")
    return (float(s[0]), float(s[1]), float(s[2]))


def load_mesh(path: str | os.PathLike[str], scale: object = (1.0, 1.0, 1.0)) -> TriangleMesh:
    """Read a mesh file into one :class:`TriangleMesh` [m] (needs ``serialkin[mesh]``).

    Args:
        path: an STL, OBJ, DAE, GLB/glTF, PLY or OFF file.
        scale: per-axis factors (3 numbers > 0, or one), applied after the file's unit:
            ``p = diag(scale) · unit · p_file``.

    Returns:
        The mesh; scene files are flattened with every node transform applied. Cached:
        a second call for an unchanged file returns the same object.

    Raises:
        RobotDefinitionError: the file does not exist, is not a regular file, has an
            unsupported suffix, cannot be parsed (corrupt), or holds no triangles (the
            message names the file).
        NotSupportedError: trimesh is not installed (the message names the extra).
    """
    if not isinstance(path, str | os.PathLike):
        raise InputTypeError(f"mesh path must be a str or os.PathLike, got "
                             f"{type(path).__name__} {short_repr(path)}")
    s = _scale3(scale)
    p = Path(path).expanduser()
    try:
        p = p.resolve()
        st = p.stat()
    except FileNotFoundError:
        raise RobotDefinitionError(f"{path}: mesh file not found") from None
    except (OSError, RuntimeError) as exc:
        raise RobotDefinitionError(f"{path}: cannot read the mesh file ({exc})") from None
    if not p.is_file():
        raise RobotDefinitionError(f"{p}: is not a regular file (a mesh file must be one)")
    file_type = MESH_SUFFIXES.get(p.suffix.lower())
    if file_type is None:
        raise RobotDefinitionError(
            f"{p}: unsupported mesh file type {p.suffix or '(no suffix)'!r}; expected one of "
            f"{', '.join(sorted(MESH_SUFFIXES))}")
    if st.st_size > MAX_MESH_BYTES:
        raise RobotDefinitionError(f"{p}: the mesh file has {st.st_size} bytes, more than "
                                   f"the limit of {MAX_MESH_BYTES} bytes")
    key = (str(p), st.st_mtime_ns, st.st_size, s)
    with _cache_lock:
        hit = _cache.get(key)
        if hit is not None:
            _cache.move_to_end(key)
            return hit
    mesh = _read(p, file_type, s)
    with _cache_lock:
        _cache[key] = mesh
        while len(_cache) > CACHE_SIZE:
            _cache.popitem(last=False)
    return mesh


def _read(p: Path, file_type: str, scale: tuple[float, float, float]) -> TriangleMesh:
    """Parse one file with trimesh; every parser failure becomes a RobotDefinitionError."""
    from serialkin.kinematics.parallel import single_threaded_blas

    trimesh = _trimesh()
    try:
        with single_threaded_blas():  # many small products: ×1.4 faster on a busy machine
            scene = trimesh.load_scene(str(p), file_type=file_type)
            unit = 1.0
            if file_type == "dae" and scene.units not in (None, "meters", "meter", "m"):
                unit = float(trimesh.units.unit_conversion(scene.units, "meters"))
            flat = scene.to_mesh() if len(scene.geometry) else None
    except NotSupportedError:
        raise
    except Exception as exc:  # noqa: BLE001 - any parser error means a corrupt file
        raise RobotDefinitionError(
            f"{p}: cannot read the mesh file, it is corrupt or not a {file_type.upper()} "
            f"file ({type(exc).__name__}: {short_repr(str(exc), 200)})") from None
    faces = None if flat is None else getattr(flat, "faces", None)
    if faces is None or len(faces) == 0:
        raise RobotDefinitionError(f"{p}: the mesh file holds no triangles")
    v = np.asarray(flat.vertices, dtype=np.float64) * (unit * np.asarray(scale))
    return TriangleMesh(v, np.asarray(faces, dtype=np.int64), str(p))


def clear_mesh_cache() -> None:
    """Forget every mesh :func:`load_mesh` has cached."""
    with _cache_lock:
        _cache.clear()


def welded(mesh: TriangleMesh) -> TriangleMesh:
    """The same triangles over merged vertices: exactly equal positions become one vertex.

    Mesh files (STL always, COLLADA often) repeat a vertex for every face corner; edge
    collapse needs the shared vertices to see the surface as connected (without welding,
    decimating the Panda's link0 to 3,000 triangles kept 9 % of its area). Unused vertices
    are dropped.

    Returns:
        a TriangleMesh with (V', 3) unique vertices and (F, 3) faces indexing them.
    """
    used = np.unique(mesh.faces)
    uniq, inverse = np.unique(mesh.vertices[used], axis=0, return_inverse=True)
    remap = np.empty(mesh.vertices.shape[0], dtype=np.int64)
    remap[used] = inverse.reshape(-1)
    return TriangleMesh(uniq, remap[mesh.faces], mesh.source)


def decimate(mesh: TriangleMesh, max_faces: int) -> TriangleMesh:
    """A mesh of at most ``max_faces`` triangles, by quadric edge collapse of the welded mesh.

    Returns ``mesh`` itself when it already has at most ``max_faces`` faces. Uses trimesh's
    ``simplify_quadric_decimation`` (Garland & Heckbert 1997 quadric error metric, in
    ``fast-simplification``); the result approximates the surface, it does not bound it.

    Raises:
        InputError: ``max_faces`` is not an integer >= 4.
        NotSupportedError: trimesh or fast-simplification is not installed.
    """
    if not isinstance(mesh, TriangleMesh):
        raise InputTypeError(f"mesh must be a TriangleMesh, got {type(mesh).__name__}")
    max_faces = check_int(max_faces, "max_faces", minimum=4)
    if mesh.faces.shape[0] <= max_faces:
        return mesh
    trimesh = _trimesh()
    require("fast_simplification", "mesh", "mesh decimation")
    mesh = welded(mesh)
    tm = trimesh.Trimesh(mesh.vertices.copy(), mesh.faces.copy(), process=False)
    out = tm.simplify_quadric_decimation(face_count=max_faces)
    faces = np.asarray(out.faces, dtype=np.int64)
    if faces.shape[0] > max_faces:  # the collapse may stop a few faces short
        out = tm.simplify_quadric_decimation(face_count=max(4, 2 * max_faces - faces.shape[0]))
        faces = np.asarray(out.faces, dtype=np.int64)
    return TriangleMesh(np.asarray(out.vertices, dtype=np.float64), faces, mesh.source)


def primitive_mesh(geometry: object, sections: int = 24) -> TriangleMesh:
    """A triangulated box, cylinder, sphere or capsule, placed as it is in its frame.

    The vertices are in the shape's frame: a shape at its frame's origin (link geometry,
    as URDF: centred, axis z) is meshed there, a placed one (``center``, ``rotation``,
    capsule ends) where it is.

    Args:
        geometry: a :class:`~serialkin.model.geometry.Box`, ``Cylinder``, ``Sphere`` or
            ``Capsule``.
        sections: segments around a circle (>= 3).

    Raises:
        InputTypeError: ``geometry`` is not one of those primitives.
        NotSupportedError: trimesh is not installed, or an infinite cylinder.
    """
    sections = check_int(sections, "sections", minimum=3, maximum=1024)
    trimesh = _trimesh()
    g = geometry
    if isinstance(g, Cylinder) and np.isinf(g.length):
        raise NotSupportedError("an infinite cylinder has no finite mesh")
    if isinstance(g, Box):
        tm = trimesh.creation.box(extents=g.size)
    elif isinstance(g, Cylinder):
        tm = trimesh.creation.cylinder(radius=g.radius, height=g.length, sections=sections)
    elif isinstance(g, Sphere):
        tm = trimesh.creation.uv_sphere(radius=g.radius,
                                        count=(sections // 2 + 1, sections))
    elif isinstance(g, Capsule):
        tm = trimesh.creation.capsule(height=g.length, radius=g.radius,
                                      count=(sections, sections))
    else:
        raise InputTypeError(f"geometry must be a Box, Cylinder, Sphere or Capsule, got "
                             f"{type(g).__name__}")
    V = np.asarray(tm.vertices, dtype=float)
    T = g.pose
    if not np.array_equal(T, np.eye(4)):
        V = V @ T[:3, :3].T + T[:3, 3]
    return TriangleMesh(V, np.asarray(tm.faces, dtype=np.int64), type(g).__name__.lower())


@dataclass(frozen=True)
class LinkMesh:
    """One shape of a link as a mesh posed in its chain frame.

    Attributes:
        link_name: the link (URDF ``<link>``) the shape belongs to.
        frame: chain frame 0..n (index of :meth:`Robot.fk_all`).
        mesh: vertices in frame ``frame`` [m] (shape origin and mesh scale applied).
        shape: the :class:`~serialkin.model.geometry.Shape` it came from (name, rgba,
            material, the unposed geometry).
    """

    link_name: str
    frame: int
    mesh: TriangleMesh
    shape: Any


def link_meshes(robot: Any, kind: str = "visual", *, primitives: bool = False,
                max_faces: int | None = None) -> Iterator[LinkMesh]:
    """Yield the robot's visual or collision meshes, each posed in its chain frame.

    For every :class:`~serialkin.model.geometry.LinkGeometry` of ``robot.geometry`` and
    every shape of kind ``kind``: a :class:`~serialkin.model.geometry.Mesh` is loaded
    (:func:`load_mesh`, with its scale) and moved by the shape's origin; with
    ``primitives=True`` boxes, cylinders, spheres and capsules are triangulated too
    (:func:`primitive_mesh`), otherwise skipped. ``max_faces`` decimates each mesh.

    Raises:
        RobotDefinitionError: a mesh file is missing or corrupt (the message names the
            link and the file; an unresolved ``package://`` path says so).
        NotSupportedError: trimesh is not installed.
    """
    kind = check_choice(kind, "kind", ("visual", "collision"))
    for lg in getattr(robot, "geometry", ()):
        for shape in getattr(lg, kind):
            g = shape.geometry
            if isinstance(g, Mesh):
                try:
                    m = load_mesh(g.filename, g.scale)
                except RobotDefinitionError as exc:
                    hint = ""
                    if g.filename.startswith("package://") or not os.path.isabs(g.filename):
                        hint = (" (the path was never resolved: load the URDF with "
                                "package_map= or search_path=)")
                    raise RobotDefinitionError(
                        f"link {lg.link_name!r} {kind} mesh: {exc}{hint}") from None
            elif primitives:
                m = primitive_mesh(g)
            else:
                continue
            if max_faces is not None:
                m = decimate(m, max_faces)
            yield LinkMesh(lg.link_name, lg.frame, m.transformed(shape.origin), shape)
