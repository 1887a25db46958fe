"""Triangle meshes (:class:`~geoshade.models.TriangleMesh`) to PLY, OBJ and STL, atomically.

=========  ========================================================================  ==========
suffix     content                                                                   normals
=========  ========================================================================  ==========
``.ply``   binary little-endian: vertex ``x y z`` (float32), ``nx ny nz`` and a      per vertex
           ``value`` property when the mesh has them; faces as ``uchar`` + 3 ``int``
``.obj``   text: ``v``, ``vn``, ``f a//a b//b c//c`` (1-based)                       per vertex
``.stl``   binary: 80-byte header, count, per face normal + 3 vertices + 2 bytes     per face
=========  ========================================================================  ==========

Each writer builds the whole file in memory and hands it to
:func:`geoshade.io.output.atomic_write_bytes`: a reader never sees half a mesh.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.output import atomic_write_bytes
from geoshade.models.field import TriangleMesh

#: suffixes :func:`write_mesh` knows
MESH_SUFFIXES = (".ply", ".obj", ".stl")


def _check(mesh) -> TriangleMesh:
    if not isinstance(mesh, TriangleMesh):
        raise InputError(f"mesh: expected a TriangleMesh, got {type(mesh).__name__}")
    return mesh


def write_ply(path, mesh: TriangleMesh) -> Path:
    """Binary little-endian PLY with per-vertex normals and value when present.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> m = TriangleMesh(np.eye(3, dtype=np.float32), [[0, 1, 2]])
    >>> p = write_ply(os.path.join(tempfile.mkdtemp(), "m.ply"), m)
    >>> p.read_bytes()[:3]
    b'ply'
    """
    m = _check(mesh)
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if m.normals is not None:
        fields += [("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")]
    if m.values is not None:
        fields += [("value", "<f4")]
    vert = np.empty(m.n_vertices, dtype=fields)
    xyz = np.asarray(m.vertices, np.float32)
    vert["x"], vert["y"], vert["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    if m.normals is not None:
        vert["nx"], vert["ny"], vert["nz"] = m.normals[:, 0], m.normals[:, 1], m.normals[:, 2]
    if m.values is not None:
        vert["value"] = m.values
    face = np.empty(m.n_faces, dtype=[("n", "u1"), ("v", "<i4", (3,))])
    face["n"] = 3
    face["v"] = m.faces
    header = ["ply", "format binary_little_endian 1.0",
              f"comment geoshade isosurface {m.name}".rstrip(),
              f"element vertex {m.n_vertices}"]
    header += [f"property float {n}" for n, _ in fields]
    header += [f"element face {m.n_faces}", "property list uchar int vertex_indices",
               "end_header"]
    data = ("\n".join(header) + "\n").encode("ascii") + vert.tobytes() + face.tobytes()
    return atomic_write_bytes(path, data)


def write_obj(path, mesh: TriangleMesh) -> Path:
    """Wavefront OBJ (text) with vertex normals when present.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> m = TriangleMesh(np.eye(3, dtype=np.float32), [[0, 1, 2]])
    >>> p = write_obj(os.path.join(tempfile.mkdtemp(), "m.obj"), m)
    >>> p.read_text().splitlines()[-1]
    'f 1 2 3'
    """
    m = _check(mesh)
    buf = io.StringIO()
    buf.write(f"# geoshade isosurface {m.name}\n".replace("  ", " "))
    np.savetxt(buf, np.asarray(m.vertices, np.float64), fmt="v %.9g %.9g %.9g")
    f = m.faces + 1
    if m.normals is not None:
        np.savetxt(buf, m.normals, fmt="vn %.6g %.6g %.6g")
        np.savetxt(buf, np.repeat(f, 2, axis=1), fmt="f %d//%d %d//%d %d//%d")
    else:
        np.savetxt(buf, f, fmt="f %d %d %d")
    return atomic_write_bytes(path, buf.getvalue().encode("ascii"))


def write_stl(path, mesh: TriangleMesh) -> Path:
    """Binary STL (face normals computed from the triangles' corners, counter-clockwise).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> m = TriangleMesh(np.eye(3, dtype=np.float32), [[0, 1, 2]])
    >>> p = write_stl(os.path.join(tempfile.mkdtemp(), "m.stl"), m)
    >>> p.stat().st_size
    134
    """
    m = _check(mesh)
    tri = m.triangles().astype(np.float64)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, ln, out=np.zeros_like(n), where=ln > 0)
    rec = np.zeros(m.n_faces, dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["n"], rec["v"] = n, tri
    head = f"geoshade isosurface {m.name}".encode("ascii", "replace")[:80].ljust(80, b" ")
    data = head + np.uint32(m.n_faces).tobytes() + rec.tobytes()
    return atomic_write_bytes(path, data)


def write_mesh(path, mesh: TriangleMesh) -> Path:
    """Write ``mesh`` in the format its suffix names (``.ply``, ``.obj``, ``.stl``).

    Examples
    --------
    >>> write_mesh("out.vtk", TriangleMesh(np.eye(3), [[0, 1, 2]]))
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: out.vtk: unknown mesh format '.vtk'; expected .ply, .obj or .stl
    """
    suffix = Path(path).suffix.lower()
    writer = {".ply": write_ply, ".obj": write_obj, ".stl": write_stl}.get(suffix)
    if writer is None:
        raise InputError(f"{path}: unknown mesh format {suffix or '(no suffix)'!r}; expected "
                         ".ply, .obj or .stl")
    return writer(path, mesh)
