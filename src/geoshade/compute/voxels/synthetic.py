"""Deterministic synthetic volumes: a CT-like digital rock and random labels for tests."""

from __future__ import annotations

import math

import numpy as np

from geoshade.errors import InputError
from geoshade.models import VoxelVolume

#: grey levels (pore, grain, noise sigma) by dtype, like a micro-CT scan's two histogram peaks
_LEVELS = {
    "uint8": (40.0, 200.0, 8.0),
    "uint16": (8000.0, 30000.0, 1200.0),
    "int16": (-8000.0, 14000.0, 1200.0),
    "float32": (0.2, 1.0, 0.04),
}


def _shape_xyz(n, shape) -> tuple[int, int, int]:
    if shape is None:
        shape = (n, n, n)
    try:
        s = tuple(int(v) for v in shape)
    except (TypeError, ValueError):
        raise InputError(
            f"shape: expected 3 positive integers (nx, ny, nz), got {shape!r}"
        ) from None
    if len(s) != 3 or min(s) < 1:
        raise InputError(f"shape: expected 3 positive integers (nx, ny, nz), got {shape!r}")
    return s


def _smooth(a: np.ndarray, w: float = 0.25) -> np.ndarray:
    """Separable ``[w, 1 - 2w, w]`` blur of a float32 array padded by one voxel; the inside."""
    for axis in range(a.ndim):
        lo = [slice(None)] * a.ndim
        hi = [slice(None)] * a.ndim
        mid = [slice(None)] * a.ndim
        lo[axis], mid[axis], hi[axis] = slice(None, -2), slice(1, -1), slice(2, None)
        inner = (
            np.float32(w) * (a[tuple(lo)] + a[tuple(hi)]) + np.float32(1 - 2 * w) * a[tuple(mid)]
        )
        a[tuple(mid)] = inner
    return a[1:-1, 1:-1, 1:-1]


def _paint_grains(shape_zyx, centres, radii) -> np.ndarray:
    """int32 label: index of the first grain (in order) covering each voxel, or len(radii)."""
    nz, ny, nx = shape_zyx
    none = len(radii)
    label = np.full(shape_zyx, none, dtype=np.int32)
    for i, ((cx, cy, cz), r) in enumerate(zip(centres, radii, strict=True)):  # grains, not voxels
        x0, x1 = max(0, math.floor(cx - r)), min(nx, math.ceil(cx + r) + 1)
        y0, y1 = max(0, math.floor(cy - r)), min(ny, math.ceil(cy + r) + 1)
        z0, z1 = max(0, math.floor(cz - r)), min(nz, math.ceil(cz + r) + 1)
        if x0 >= x1 or y0 >= y1 or z0 >= z1:
            continue
        dx = (np.arange(x0, x1) + 0.5 - cx) ** 2
        dy = (np.arange(y0, y1) + 0.5 - cy) ** 2
        dz = (np.arange(z0, z1) + 0.5 - cz) ** 2
        ball = (dz[:, None, None] + dy[None, :, None] + dx[None, None, :]) <= r * r
        sub = label[z0:z1, y0:y1, x0:x1]
        sub[ball & (sub == none)] = i
    return label


def synthetic_core(
    n: int = 64, porosity: float = 0.2, seed: int = 0, dtype: str = "uint16", shape=None
) -> VoxelVolume:
    """A deterministic synthetic digital rock: overlapping spherical grains in pore space.

    Grains (high grey values) are balls of random radius placed at random; pores are low values.
    The number of grains is chosen so that the pore fraction of the binary structure is as close
    as possible to ``porosity``; a light blur and noise make the histogram look like a CT scan
    (two peaks). ``meta`` holds ``porosity`` (the exact binary pore fraction), ``threshold``
    (the grey value between the peaks), ``pore_range`` and ``grain_range`` (ranges that select
    pores and grains, split at ``threshold``) and ``grains``.

    Parameters
    ----------
    n : int
        Edge of a cubic volume (ignored when ``shape`` is given).
    porosity : float
        Target pore fraction, in (0, 1).
    seed : int
        Random seed; the same arguments always give the same volume.
    dtype : {"uint16", "uint8", "int16", "float32"}
        Value type (uint16: pores ~8000, grains ~30000; uint8: ~40 and ~200).
    shape : (nx, ny, nz), optional
        Size of a non-cubic volume.

    Returns
    -------
    VoxelVolume
        Spacing 2.5 µm (unit ``"um"``).

    Examples
    --------
    >>> vol = synthetic_core(32, porosity=0.3, seed=1)
    >>> vol.shape_xyz, vol.dtype.name, abs(vol.meta["porosity"] - 0.3) < 0.02
    ((32, 32, 32), 'uint16', True)
    """
    nx, ny, nz = _shape_xyz(n, shape)
    dt = np.dtype(dtype).name
    if dt not in _LEVELS:
        raise InputError(f"dtype: {dt} not supported here; expected one of {', '.join(_LEVELS)}")
    p = float(porosity)
    if not 0.0 < p < 1.0:
        raise InputError(f"porosity: expected a fraction in (0, 1), got {porosity!r}")
    rng = np.random.default_rng(seed)
    # grain radius scales with the volume, at least 1.5 voxels
    r_mean = max(1.5, min(nx, ny, nz) / 12.0)
    r_lo, r_hi = 0.6 * r_mean, 1.4 * r_mean
    # a Boolean model of balls leaves exp(-lambda * E[V_ball]) of space empty: expected count
    ext = [s + 2 * r_hi for s in (nx, ny, nz)]
    mean_ball = 4.0 / 3.0 * math.pi * (r_hi**4 - r_lo**4) / (4.0 * (r_hi - r_lo))
    expected = -math.log(p) * math.prod(ext) / mean_ball
    n_grains = int(expected * 1.5) + 16
    total = nx * ny * nz
    while True:
        centres = rng.uniform(-r_hi, [nx + r_hi, ny + r_hi, nz + r_hi], (n_grains, 3))
        radii = rng.uniform(r_lo, r_hi, n_grains)
        label = _paint_grains((nz, ny, nx), centres, radii)
        covered = np.cumsum(np.bincount(label.reshape(-1), minlength=n_grains + 1)[:n_grains])
        pore = 1.0 - covered / total  # pore fraction with the first k+1 grains
        if pore[-1] <= p or n_grains > 50 * expected + 10_000:
            break
        n_grains *= 2
    k = int(np.argmin(np.abs(pore - p))) + 1
    if abs(1.0 - p) < abs(pore[k - 1] - p):
        k = 0
    solid = label < k
    del label
    actual = float(1.0 - np.count_nonzero(solid) / total)

    pore_v, grain_v, sigma = _LEVELS[dt]
    grey = np.pad(np.where(solid, np.float32(grain_v), np.float32(pore_v)), 1, mode="edge")
    grey = _smooth(grey, 0.1)  # mild partial-volume blur at grain boundaries
    noise = _smooth(rng.standard_normal((nz + 2, ny + 2, nx + 2), dtype=np.float32))
    grey += noise * np.float32(sigma / 0.375**1.5)  # the blur keeps 0.375**1.5 of the std
    if np.dtype(dt).kind in "ui":
        info = np.iinfo(dt)
        np.rint(grey, out=grey)
        np.clip(grey, info.min, info.max, out=grey)
    data = grey.astype(dt)
    threshold = 0.5 * (pore_v + grain_v)
    if np.dtype(dt).kind in "ui":
        info = np.iinfo(dt)
        t = int(threshold)
        pore_range, grain_range = (int(info.min), t), (t + 1, int(info.max))
    else:
        pore_range, grain_range = (-math.inf, threshold), (threshold, math.inf)
    return VoxelVolume(
        data,
        spacing=(2.5, 2.5, 2.5),
        unit="um",
        name=f"synthetic_core(n={nx}x{ny}x{nz}, porosity={p}, seed={seed})",
        meta={
            "porosity": actual,
            "threshold": threshold,
            "pore_range": pore_range,
            "grain_range": grain_range,
            "grains": k,
        },
    )


def random_labels(shape_xyz, fraction: float, seed: int = 0) -> VoxelVolume:
    """A uint8 volume of random values: ``fraction`` of the voxels in [100, 200], the rest 0..99.

    Exactly ``round(fraction * nvoxels)`` voxels are in [100, 200]; every voxel has its own
    random value, so a colour map shows single wrong voxels. Select them with range (100, 200).

    Examples
    --------
    >>> vol = random_labels((8, 6, 4), 0.25, seed=3)
    >>> vol.data.shape, int(((vol.data >= 100) & (vol.data <= 200)).sum())
    ((4, 6, 8), 48)
    """
    nx, ny, nz = _shape_xyz(None, shape_xyz)
    f = float(fraction)
    if not 0.0 <= f <= 1.0:
        raise InputError(f"fraction: expected a number in [0, 1], got {fraction!r}")
    rng = np.random.default_rng(seed)
    total = nx * ny * nz
    k = round(f * total)
    data = rng.integers(0, 100, total, dtype=np.uint8)
    chosen = rng.permutation(total)[:k]
    data[chosen] = rng.integers(100, 201, k, dtype=np.uint8)
    return VoxelVolume(
        data.reshape(nz, ny, nx),
        name=f"random_labels({nx}x{ny}x{nz}, fraction={f}, seed={seed})",
        meta={"fraction": k / total, "range": (100, 200)},
    )
