"""Which voxel faces can be seen: CPU references for the GPU culling and the trefoil tables.

Conventions (paper Section 3): voxel ``(x, y, z)`` spans ``[x, x+1] × [y, y+1] × [z, z+1]``;
cube vertex ``v`` is ``(v & 1, (v >> 1) & 1, (v >> 2) & 1)``; faces are numbered
``0 +x, 1 +y, 2 +z, 3 −x, 4 −y, 5 −z``; the trefoil variant is ``t = b0 + 2 b1 + 4 b2`` where
``b_p`` is 1 when the ``+p`` face looks towards the camera.
"""

from __future__ import annotations

import numpy as np

from geoshade.errors import InputError

#: (8, 3) int: cube vertex v -> (x, y, z) corner offset
CUBE_CORNERS = np.array([(v & 1, (v >> 1) & 1, (v >> 2) & 1) for v in range(8)], dtype=np.int64)
#: (6, 3) int: outward normal of face 0..5 (+x, +y, +z, -x, -y, -z)
FACE_NORMALS = np.array(
    [(1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 0, 0), (0, -1, 0), (0, 0, -1)], dtype=np.int64
)

#: the paper's triangle strips S_0..S_7, exactly as printed
_STRIPS = (
    (5, 4, 1, 0, 3, 2, 2, 0, 6, 4),
    (4, 0, 5, 1, 7, 3, 3, 1, 2, 0),
    (1, 0, 3, 2, 7, 6, 6, 2, 4, 0),
    (5, 1, 7, 3, 6, 2, 2, 3, 0, 1),
    (1, 5, 0, 4, 2, 6, 6, 4, 7, 5),
    (0, 1, 4, 5, 6, 7, 7, 5, 3, 1),
    (0, 4, 2, 6, 3, 7, 7, 6, 5, 4),
    (4, 5, 6, 7, 2, 3, 3, 7, 1, 5),
)
#: the paper's normal tables N_0..N_7 as printed ('*' written as -1)
_PAPER_NORMALS = (
    (-1, -1, 4, 4, 0, 0, 0, 0, 5, 5),
    (-1, -1, 5, 5, 1, 1, 1, 1, 3, 3),
    (-1, -1, 4, 4, 2, 2, 2, 2, 0, 0),
    (-1, -1, 3, 3, 1, 1, 1, 1, 2, 2),
    (-1, -1, 4, 4, 5, 5, 5, 5, 3, 3),
    (-1, -1, 0, 0, 1, 1, 1, 1, 5, 5),
    (-1, -1, 4, 4, 3, 3, 3, 3, 2, 2),
    (-1, -1, 2, 2, 1, 1, 1, 1, 0, 0),
)

_AXIS_OF_XYZ = (2, 1, 0)  # x, y, z -> array axis of a (nz, ny, nx) mask


def _mask3(sel) -> np.ndarray:
    a = np.asarray(sel)
    if a.ndim != 3:
        raise InputError(f"sel: expected a 3D (nz, ny, nx) mask, got shape {a.shape}")
    return a if a.dtype == np.bool_ else a.astype(bool)


def _along(axis: int, start: int, stop: int) -> tuple[slice, ...]:
    idx = [slice(None)] * 3
    idx[axis] = slice(start, stop)
    return tuple(idx)


def _and_facing_neighbour(hidden: np.ndarray, sel: np.ndarray, axis: int, k: int) -> None:
    """``hidden &= camera-facing neighbour``: voxels with index < k look at +1, the rest at -1.

    Neighbours outside the box count as not selected.
    """
    n = sel.shape[axis]
    k = min(max(k, 0), n)
    e = min(k, n - 1)  # [0, e): +1 neighbour inside the box
    if e > 0:
        hidden[_along(axis, 0, e)] &= sel[_along(axis, 1, e + 1)]
    if k == n:  # the last slice looks out of the box
        hidden[_along(axis, n - 1, n)] = False
    s = max(k, 1)  # [s, n): -1 neighbour inside the box
    if s < n:
        hidden[_along(axis, s, n)] &= sel[_along(axis, s - 1, n - 1)]
    if k == 0:  # the first slice looks out of the box
        hidden[_along(axis, 0, 1)] = False


def visible_mask(sel, eye_ijk=None, view_signs=None) -> np.ndarray:
    """Selected voxels that are not hidden by their three camera-facing neighbours.

    A selected voxel is hidden when its camera-facing neighbours along x, y and z are all
    selected (neighbours outside the box count as not selected). Along x the camera-facing
    neighbour is ``+x`` when the eye is at ``x >= voxel centre x`` and ``-x`` otherwise; the
    same for y and z. This is the exact reference for the GPU hidden-voxel cull.

    Parameters
    ----------
    sel : (nz, ny, nx) bool
        Selection mask.
    eye_ijk : (3,) float, optional
        Eye position in voxel index space (x, y, z); voxel ``(x, y, z)`` spans ``[x, x+1]``.
    view_signs : (3,) bool, optional
        The paper's ``(b0, b1, b2)``: whether the ``+x, +y, +z`` faces are visible, the same for
        every voxel (orthographic view). Give exactly one of ``eye_ijk`` and ``view_signs``.

    Returns
    -------
    (nz, ny, nx) bool

    Examples
    --------
    >>> sel = np.ones((3, 3, 3), bool)
    >>> int(visible_mask(sel, view_signs=(True, True, True)).sum())   # 27 - 2**3 hidden
    19
    >>> int(visible_mask(sel, eye_ijk=(-5.0, 1.5, 9.0)).sum())        # sees -x, +y/-y, +z
    15
    """
    s = _mask3(sel)
    if (eye_ijk is None) == (view_signs is None):
        raise InputError("visible_mask: give exactly one of eye_ijk and view_signs")
    if eye_ijk is not None:
        eye = np.asarray(eye_ijk, dtype=np.float64).reshape(-1)
        if eye.shape != (3,) or np.isnan(eye).any():
            raise InputError(f"eye_ijk: expected 3 numbers (x, y, z), got {eye_ijk!r}")
    else:
        signs = np.asarray(view_signs).reshape(-1)
        if signs.shape != (3,):
            raise InputError(f"view_signs: expected 3 booleans (b0, b1, b2), got {view_signs!r}")
    hidden = s.copy()
    for p, axis in enumerate(_AXIS_OF_XYZ):
        n = s.shape[axis]
        if eye_ijk is not None:
            # voxel i looks at +1 iff eye >= i + 0.5  <=>  i <= floor(eye - 0.5)
            c = float(np.clip(eye[p], -2.0, n + 2.0))
            k = int(np.floor(c - 0.5)) + 1
        else:
            k = n if bool(signs[p]) else 0
        _and_facing_neighbour(hidden, s, axis, k)
    return s & ~hidden


def exposed_mask(sel) -> np.ndarray:
    """Selected voxels with at least one of their 6 neighbours unselected or outside the box.

    The camera-independent cull of the 'cubes' baseline.

    Examples
    --------
    >>> sel = np.ones((3, 3, 3), bool)
    >>> int(exposed_mask(sel).sum()), bool(exposed_mask(sel)[1, 1, 1])
    (26, False)
    """
    s = _mask3(sel)
    inner = np.zeros_like(s)
    c = (slice(1, -1),) * 3
    core = s[c].copy()
    for axis in range(3):
        core &= s[tuple(slice(2, None) if a == axis else slice(1, -1) for a in range(3))]
        core &= s[tuple(slice(None, -2) if a == axis else slice(1, -1) for a in range(3))]
    inner[c] = core
    return s & ~inner


def face_of(vertices) -> int:
    """Face (0 +x, 1 +y, 2 +z, 3 −x, 4 −y, 5 −z) all given cube vertices lie on, or -1.

    Degenerate triangles (a repeated vertex) give -1.

    Examples
    --------
    >>> face_of((5, 4, 1)), face_of((3, 2, 2))
    (4, -1)
    """
    v = list(vertices)
    if len(set(v)) != len(v):
        return -1
    c = CUBE_CORNERS[v]
    for p in range(3):
        if (c[:, p] == 1).all():
            return p
        if (c[:, p] == 0).all():
            return p + 3
    return -1


def strip_triangles(strip) -> np.ndarray:
    """Triangles of a triangle strip in OpenGL order: ``(len-2, 3)`` vertex ids.

    Triangle ``g`` is ``(s[g], s[g+1], s[g+2])`` for even ``g`` and ``(s[g+1], s[g], s[g+2])``
    for odd ``g`` (so all keep one winding); the provoking (last) vertex is ``s[g+2]``.

    Examples
    --------
    >>> strip_triangles((0, 1, 2, 3)).tolist()
    [[0, 1, 2], [2, 1, 3]]
    """
    s = list(strip)
    tris = []
    for g in range(len(s) - 2):
        a, b, c = s[g : g + 3]
        tris.append((a, b, c) if g % 2 == 0 else (b, a, c))
    return np.array(tris, dtype=np.int64).reshape(-1, 3)


def trefoil_tables() -> tuple[np.ndarray, np.ndarray]:
    """The trefoil strips ``S`` (as printed in the paper) and their face tables ``N`` (derived).

    Returns
    -------
    S : (8, 10) int
        ``S[t]`` is the triangle strip (cube vertex ids) of trefoil variant
        ``t = b0 + 2 b1 + 4 b2``; it covers exactly the three faces that are visible for ``t``,
        counter-clockwise seen from outside.
    N : (8, 10) int
        ``N[t][g + 2]`` is the face (0 +x, 1 +y, 2 +z, 3 −x, 4 −y, 5 −z) of triangle ``g`` of
        ``S[t]``, written at its provoking (last) vertex; the first two entries and the entries of
        degenerate triangles are -1.

    Notes
    -----
    **Erratum.** The paper's printed normal tables (``N0 = (*,*,4,4,0,0,0,0,5,5)`` …, see
    :func:`paper_normal_tables`) agree with the printed strips only for ``t = 7`` (ignoring the
    entries of degenerate triangles). The strips themselves are right, so ``N`` is derived here
    from the geometry: each triangle's three vertices lie on one face, whose number is the entry.

    Examples
    --------
    >>> S, N = trefoil_tables()
    >>> S[0].tolist()
    [5, 4, 1, 0, 3, 2, 2, 0, 6, 4]
    >>> N[0].tolist()
    [-1, -1, 4, 4, 5, 5, -1, -1, 3, 3]
    """
    S = np.array(_STRIPS, dtype=np.int64)
    N = np.full_like(S, -1)
    for t in range(8):
        for g in range(S.shape[1] - 2):
            N[t, g + 2] = face_of(S[t, g : g + 3])
    return S, N


def paper_normal_tables() -> np.ndarray:
    """The normal tables ``N_0..N_7`` exactly as printed in the paper (``*`` as -1), for the record.

    They are wrong for ``t != 7``; use :func:`trefoil_tables`.

    Examples
    --------
    >>> paper_normal_tables()[7].tolist()
    [-1, -1, 2, 2, 1, 1, 1, 1, 0, 0]
    """
    return np.array(_PAPER_NORMALS, dtype=np.int64)


def visible_faces(t: int) -> tuple[int, int, int]:
    """The three faces visible for trefoil variant ``t`` (``b_p`` set: ``+p``, else ``−p``).

    Examples
    --------
    >>> visible_faces(0), visible_faces(7)
    ((3, 4, 5), (0, 1, 2))
    """
    if not 0 <= int(t) <= 7:
        raise InputError(f"trefoil variant: expected 0..7, got {t}")
    return tuple(p if (int(t) >> p) & 1 else p + 3 for p in range(3))


def view_signs_from_modelview(modelview) -> tuple[bool, bool, bool]:
    """The paper's ``(b0, b1, b2)`` from a 4×4 (or 3×3) ModelView matrix.

    ``b_p`` is true when the z component (in view space) of the ``+p`` face normal, transformed
    by the normal matrix ``inverse(M)^T``, is ``>= 0``.

    Examples
    --------
    >>> view_signs_from_modelview(np.eye(4))   # head-on: side faces are edge-on, ties count
    (True, True, True)
    >>> view_signs_from_modelview(np.diag([1.0, -1.0, -1.0, 1.0]))   # turned 180° about x
    (True, True, False)
    """
    m = np.asarray(modelview, dtype=np.float64)
    if m.shape not in ((4, 4), (3, 3)):
        raise InputError(f"modelview: expected a 4x4 or 3x3 matrix, got shape {m.shape}")
    nm = np.linalg.inv(m[:3, :3]).T
    return tuple(bool(nm[2, p] >= 0.0) for p in range(3))


def trefoil_variant(view_signs) -> int:
    """``t = b0 + 2 b1 + 4 b2``.

    Examples
    --------
    >>> trefoil_variant((True, False, True))
    5
    """
    b = [bool(x) for x in view_signs]
    if len(b) != 3:
        raise InputError(f"view_signs: expected 3 booleans (b0, b1, b2), got {view_signs!r}")
    return int(b[0]) + 2 * int(b[1]) + 4 * int(b[2])
