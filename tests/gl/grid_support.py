"""Hand-built corner-point grids and a brute-force reference for the grid rendering tests.

``reference_faces`` is an independent oracle for face visibility (the paper's three rules,
written directly from ZCORN); the renderer itself uses ``geoshade.compute.grid.faces``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geoshade.models.grid import CornerPointGrid, Fault, WellPath

#: (di, dj, dk) of faces 0..5 = I+ J+ K+ I- J- K-
FACE_DIRS = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]])


def make_grid(nx=6, ny=5, nz=4, dx=10.0, dy=10.0, dz=5.0, top=1000.0, dip=(0.05, 0.02),
              throw=0.0, fault_i=None, inactive=(), props=True, mapaxes=None, steps=0,
              seed=0, name="test") -> CornerPointGrid:
    """A regular, dipping grid; with ``throw`` the cells ``i >= fault_i`` drop by ``throw``.

    Vertical pillars, depth ``top + k*dz + dip·(x, y)`` (+ throw), so faces are planar only where
    the dip is 0 (bilinear otherwise, like real grids).
    """
    x = np.arange(nx + 1) * dx
    y = np.arange(ny + 1) * dy
    X, Y = np.meshgrid(x, y, indexing="ij")
    coord = np.zeros((nx + 1, ny + 1, 6))
    coord[..., 0] = coord[..., 3] = X
    coord[..., 1] = coord[..., 4] = Y
    coord[..., 2] = top - 50
    coord[..., 5] = top + nz * dz + 50
    i2 = np.arange(2 * nx)
    j2 = np.arange(2 * ny)
    k2 = np.arange(2 * nz)
    ci, ca = i2 // 2, i2 % 2
    cj, cb = j2 // 2, j2 % 2
    ck, cc = k2 // 2, k2 % 2
    xi = (ci + ca) * dx
    yj = (cj + cb) * dy
    z = (top + (ck + cc) * dz)[None, None, :] + dip[0] * xi[:, None, None] \
        + dip[1] * yj[None, :, None]
    if throw and fault_i is not None:
        z = z + np.where(ci >= fault_i, throw, 0.0)[:, None, None]
    zcorn = np.asfortranarray(z)
    act = np.ones((nx, ny, nz), bool)
    for c in inactive:
        act[tuple(c)] = False
    rng = np.random.default_rng(seed)
    properties = {}
    if props:
        properties = {
            "PORO": np.asfortranarray(rng.uniform(0.05, 0.35, (nx, ny, nz))),
            "PERMX": np.asfortranarray(10 ** rng.uniform(0, 3, (nx, ny, nz))),
            "CELLID": np.asfortranarray(np.arange(nx * ny * nz, dtype=float).reshape(
                (nx, ny, nz), order="F")),
        }
    st = [{"SWAT": np.asfortranarray(rng.uniform(0, 1, (nx, ny, nz)))} for _ in range(steps)]
    faults = []
    if throw and fault_i is not None:
        faces = np.array([[fault_i - 1, j, k, 0] for j in range(ny) for k in range(nz)])
        faults.append(Fault("F1", faces))
    return CornerPointGrid(coord=np.asfortranarray(coord), zcorn=zcorn,
                           actnum=np.asfortranarray(act), mapaxes=mapaxes,
                           properties=properties, steps=st, faults=faults, name=name)


@dataclass
class RefFaceSet:
    cells: np.ndarray
    face: np.ndarray
    fault: np.ndarray
    fault_id: np.ndarray
    neighbour_shown: np.ndarray


def _corner_depths(grid: CornerPointGrid) -> np.ndarray:
    """(nx, ny, nz, 8) depths of the cell corners."""
    nx, ny, nz = grid.dims
    z = np.asarray(grid.zcorn).reshape(2, nx, 2, ny, 2, nz, order="F")
    # corner c = a + 2b + 4c'
    return z.transpose(1, 3, 5, 4, 2, 0).reshape(nx, ny, nz, 8)


def reference_faces(grid: CornerPointGrid, shown=None) -> RefFaceSet:
    """Visible faces by the paper's rules: grid boundary, shown next to not shown, or a shared
    face whose four corner depths differ on the two sides (a fault)."""
    nx, ny, nz = grid.dims
    shown = grid.active if shown is None else np.asarray(shown, bool) & grid.active
    cz = _corner_depths(grid)
    rows = []
    for f, (di, dj, dk) in enumerate(FACE_DIRS):
        ax = int(np.argmax(np.abs([di, dj, dk])))
        plus = (di + dj + dk) > 0
        own = [c for c in range(8) if (c >> ax & 1) == plus]
        other = [c ^ (1 << ax) for c in own]
        idx = np.argwhere(shown)
        nb = idx + np.array([di, dj, dk])
        inside = np.all((nb >= 0) & (nb < [nx, ny, nz]), axis=1)
        nbc = np.where(inside[:, None], nb, 0)
        nshown = inside & shown[nbc[:, 0], nbc[:, 1], nbc[:, 2]]
        za = cz[idx[:, 0], idx[:, 1], idx[:, 2]][:, own]
        zb = cz[nbc[:, 0], nbc[:, 1], nbc[:, 2]][:, other]
        mismatch = inside & np.any(za != zb, axis=1)
        vis = ~nshown | mismatch
        rows.append((idx[vis], np.full(int(vis.sum()), f), mismatch[vis], nshown[vis]))
    cells = np.concatenate([r[0] for r in rows]).astype(np.int32).reshape(-1, 3)
    face = np.concatenate([r[1] for r in rows]).astype(np.uint8)
    fault = np.concatenate([r[2] for r in rows]).astype(bool)
    nsh = np.concatenate([r[3] for r in rows]).astype(bool)
    return RefFaceSet(cells, face, fault, np.full(face.size, -1, np.int16), nsh)


def vertical_well(x, y, z0, z1, n=3, markers=()) -> WellPath:
    pts = np.stack([np.full(n, x), np.full(n, y), np.linspace(z0, z1, n)], axis=1)
    return WellPath("W", pts, markers=np.asarray(markers, float).reshape(-1, 3))


def mismatch(a, b, tol=3) -> float:
    """Fraction of pixels whose RGBA differ by more than ``tol``."""
    d = np.abs(a.astype(int) - b.astype(int)).max(axis=-1)
    return float((d > tol).mean())
