"""Deterministic synthetic corner-point grids.

:func:`synthetic_grid` makes a small but realistic reservoir grid for tests, the demo and the
benchmarks: sloping pillars, dipping and undulating layers of varying thickness, two faults
with throw that varies along them, inactive blobs, PORO/PERMX/NTG/FIPNUM and a few report
steps of SWAT moving out from an injector.  :func:`geoshade.io.grids.grdecl_writer.write_grdecl`
writes it (or any grid) as GRDECL text.
"""

from __future__ import annotations

import numpy as np

from geoshade.errors import InputError
from geoshade.models import CornerPointGrid, Fault


def _smooth_field(shape, rng, waves: int = 4) -> np.ndarray:
    """Sum of a few random low-frequency cosines over a (nx, ny, nz) index grid, in [-1, 1]."""
    nx, ny, nz = shape
    u = (np.arange(nx) + 0.5)[:, None, None] / nx
    v = (np.arange(ny) + 0.5)[None, :, None] / ny
    w = (np.arange(nz) + 0.5)[None, None, :] / nz
    out = np.zeros(shape, np.float32)
    for _ in range(waves):  # a few waves, not cells
        f = rng.uniform(0.5, 2.5, 3)
        ph = rng.uniform(0, 2 * np.pi, 3)
        out += (np.cos(2 * np.pi * f[0] * u + ph[0]) * np.cos(2 * np.pi * f[1] * v + ph[1])
                * np.cos(2 * np.pi * f[2] * w + ph[2])).astype(np.float32)
    return out / waves


def synthetic_grid(nx: int = 20, ny: int = 15, nz: int = 6, faults: bool = True,
                   inactive_fraction: float = 0.05, seed: int = 0,
                   steps: int = 4) -> CornerPointGrid:
    """A deterministic corner-point reservoir grid of ``nx × ny × nz`` cells.

    Parameters
    ----------
    nx, ny, nz : int
        Cells along i, j, k (k downwards).
    faults : bool
        Two faults along pillar lines (``FA`` at ``i = nx // 3`` with a throw growing along j,
        ``FB`` at ``j = 2 ny // 3``), listed in ``grid.faults`` (faces I+ and J+ of the cells
        on their low side).
    inactive_fraction : float
        Fraction of inactive cells (smooth blobs, exact to one cell).
    seed : int
        Random seed: the same arguments give the same grid.
    steps : int
        Report steps of SWAT (a front spreading from an injector at cell (0, 0)), monthly
        dates from 2000-01-01.

    Returns
    -------
    CornerPointGrid
        100 m × 100 m cells about 1600–1900 m deep, COORD float64 (mm-rounded), ZCORN
        float32, ACTNUM uint8, PORO/PERMX/NTG float32 and FIPNUM int32, MAPAXES translating
        to a map origin, units METRES.

    Examples
    --------
    >>> g = synthetic_grid(8, 6, 4, seed=1)
    >>> g.dims, g.ncells - g.nactive, sorted(g.properties), len(g.steps), len(g.faults)
    ((8, 6, 4), 10, ['FIPNUM', 'NTG', 'PERMX', 'PORO'], 4, 2)
    >>> bool((g.zcorn[:, :, 1:] >= g.zcorn[:, :, :-1]).all())  # depths grow down each pillar
    True
    """
    nx, ny, nz = int(nx), int(ny), int(nz)
    if min(nx, ny, nz) < 1:
        raise InputError(f"synthetic_grid: expected positive sizes, got {(nx, ny, nz)}")
    if not 0 <= inactive_fraction < 1:
        raise InputError(f"synthetic_grid: inactive_fraction must be in [0, 1), got "
                         f"{inactive_fraction}")
    rng = np.random.default_rng(seed)
    d = 100.0
    px = np.arange(nx + 1, dtype=np.float64)[:, None] * d
    py = np.arange(ny + 1, dtype=np.float64)[None, :] * d
    lx, ly = max(nx * d, 1.0), max(ny * d, 1.0)
    # horizons at the pillars: dipping, undulating, layers of varying thickness
    top = (1600.0 + 0.06 * px + 0.03 * py
           + 25.0 * np.sin(2 * np.pi * px / lx * 1.3) * np.cos(2 * np.pi * py / ly * 0.9))
    h = rng.uniform(6.0, 18.0, nz)
    lat = 1.0 + 0.35 * np.sin(2 * np.pi * (px / lx + 0.3 * py / ly))[..., None] \
        * np.cos(np.pi * np.arange(nz) / max(nz, 1) * 2.0)[None, None, :]
    thick = np.maximum(h[None, None, :] * lat, 0.5)
    horizons = np.concatenate([top[..., None], top[..., None] + np.cumsum(thick, axis=2)],
                              axis=2)  # (nx+1, ny+1, nz+1)
    # sloping pillars through the horizons' x, y; top and bottom points above and below them
    ztop, zbot = float(horizons.min()) - 10.0, float(horizons.max()) + 10.0
    tx = 0.06 * np.sin(2 * np.pi * py / ly) + 0.0 * px
    ty = 0.04 * np.cos(2 * np.pi * px / lx) + 0.0 * py
    zref = 0.5 * (ztop + zbot)
    coord = np.empty((nx + 1, ny + 1, 6))
    for c, z in ((0, ztop), (3, zbot)):
        coord[..., c] = px + tx * (z - zref)
        coord[..., c + 1] = py + ty * (z - zref)
        coord[..., c + 2] = z
    coord = np.round(coord, 3)
    mem = np.empty((ny + 1, nx + 1, 6))  # file order: 6 numbers per pillar, i fastest
    mem[:] = coord.transpose(1, 0, 2)
    coord = mem.transpose(1, 0, 2)
    # ZCORN: cell (i, j) corner (a, b) sits on pillar (i + a, j + b), plus the fault throws
    ia = np.arange(nx)
    jb = np.arange(ny)
    zcorn = np.empty((2 * nx, 2 * ny, 2 * nz), np.float32, order="F")
    fa, fb = max(nx // 3, 1), max(2 * ny // 3, 1)
    for a in (0, 1):
        for b in (0, 1):
            throw = np.zeros((nx, ny))
            if faults:
                pj = (jb + b) / max(ny, 1)
                pi = (ia + a) / max(nx, 1)
                throw += np.where(ia[:, None] >= fa, 8.0 + 14.0 * pj[None, :], 0.0)
                throw += np.where(jb[None, :] >= fb, -(5.0 + 6.0 * pi[:, None]), 0.0)
            for c in (0, 1):
                z = horizons[a:a + nx, b:b + ny, c:c + nz] + throw[..., None]
                zcorn[a::2, b::2, c::2] = np.round(z, 3)
    # properties
    shape = (nx, ny, nz)
    blob = _smooth_field(shape, rng, 5)
    ninact = round(inactive_fraction * nx * ny * nz)
    flat = np.ones(nx * ny * nz, np.uint8)
    if ninact:
        flat[np.argpartition(-blob.ravel(order="F"), ninact - 1)[:ninact]] = 0
    actnum = flat.reshape(shape, order="F")
    layer = rng.uniform(0.08, 0.3, nz).astype(np.float32)
    noise = rng.normal(0.0, 0.01, shape).astype(np.float32)
    poro = np.clip(layer[None, None, :] + 0.06 * _smooth_field(shape, rng) + noise, 0.01, 0.38)
    poro = np.asfortranarray(np.round(poro, 4), np.float32)
    permx = np.asfortranarray(np.round(10.0 ** (-1.0 + 13.0 * poro), 2), np.float32)
    ntg = np.asfortranarray(np.round(np.clip(0.35 + 2.0 * poro, 0.0, 1.0), 3), np.float32)
    fip = np.asfortranarray(1 + (np.arange(nz)[None, None, :] >= nz // 2) * 1
                            + np.zeros(shape, np.int32), np.int32)
    props = {"PORO": poro, "PERMX": permx, "NTG": ntg, "FIPNUM": fip}
    # SWAT steps: a front from cell (0, 0), faster in permeable layers
    cx = (ia + 0.5)[:, None, None] / nx
    cy = (jb + 0.5)[None, :, None] / ny
    r = np.sqrt(cx * cx + cy * cy).astype(np.float32)
    speed = (permx / max(float(permx.mean()), 1e-6)) ** np.float32(0.2)
    step_list, dates = [], []
    for t in range(steps):  # a few report steps, not cells
        front = np.float32(1.2 * t / max(steps - 1, 1)) * speed
        sw = 0.2 + 0.6 * 0.5 * (1.0 - np.tanh((r - front) / np.float32(0.05)))
        step_list.append({"SWAT": np.asfortranarray(np.round(sw, 4), np.float32)})
        dates.append(f"{2000 + t // 12:04d}-{t % 12 + 1:02d}-01")
    fault_list = []
    if faults:
        jj, kk = np.meshgrid(np.arange(ny), np.arange(nz), indexing="ij")
        fault_list.append(Fault("FA", np.stack([np.full(jj.size, fa - 1), jj.ravel(),
                                                kk.ravel(), np.zeros(jj.size)], 1)))
        ii, kk = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
        fault_list.append(Fault("FB", np.stack([ii.ravel(), np.full(ii.size, fb - 1),
                                                kk.ravel(), np.ones(ii.size)], 1)))
    x0, y0 = 456000.0, 5926000.0
    return CornerPointGrid(coord=coord, zcorn=zcorn, actnum=actnum,
                           mapaxes=np.array([x0, y0 + 1000.0, x0, y0, x0 + 1000.0, y0]),
                           properties=props, steps=step_list, step_dates=dates,
                           faults=fault_list, units="METRES",
                           name=f"synthetic {nx}x{ny}x{nz}",
                           meta={"format": "synthetic", "seed": seed})
