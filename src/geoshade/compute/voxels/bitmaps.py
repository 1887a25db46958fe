"""The GPU-side structures of the trefoil method (paper Section 4) and the ray caster.

All are computed from ``sel``, the bool selection mask ``(nz, ny, nx)`` of a box:

==========================  ===============================  ==================================
name                        shape, dtype                     meaning
==========================  ===============================  ==================================
bit map of voxels ``B``     ``(nz, ny, ceil(nx/32))`` uint32  bit ``x % 32`` of word ``x // 32``
                                                             is voxel ``x`` (little bit order);
                                                             an R32UI 3D texture
bit map of patch-quads      ``(q_p, m_p, ceil(n_p/32))``     1 if any voxel of the patch's
``B_p``                     uint32                           ``(l+1)×(l+1)`` group is selected
brick occupancy             ``ceil((nz, ny, nx)/brick)``     1 if any voxel of the brick is
                            uint8                            selected (ray-caster skipping)
colour index map ``I``      ``(nz, ny, nx)`` uint8           ``round((v-lo)/(hi-lo)*255)``
palette ``A``               ``(256, 4)`` uint8 RGBA          :mod:`geoshade.styles.palette`
==========================  ===============================  ==================================

:func:`build_selection_maps` builds them all slab by slab; :func:`gpu_bytes_breakdown` is the one
definition of how many bytes each method's GPU objects take.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from geoshade.compute.voxels.layout import skip_map_bytes, words_per_row
from geoshade.compute.voxels.selection import (
    SLAB_BYTES,
    check_range,
    iter_z_slabs,
    resolve_data_box,
    select,
    slab_depth,
)
from geoshade.errors import InputError
from geoshade.models import Box
from geoshade.progress import Progress

#: texels of the 1D palette texture (RGBA8)
PALETTE_SIZE = 256
#: vertices and bytes per vertex of one drawn cube in the 'cubes' baseline VBO
CUBE_VERTICES = 36
CUBE_VERTEX_BYTES = 8
#: bytes per selected voxel of the 'gs' (one point per voxel) VBO
GS_VOXEL_BYTES = 4
#: methods :func:`gpu_bytes_breakdown` knows
METHODS = ("trefoil", "raycast", "gs", "cubes")


def _mask3(sel, name: str = "sel") -> np.ndarray:
    a = np.asarray(sel)
    if a.ndim != 3:
        raise InputError(f"{name}: expected a 3D (nz, ny, nx) mask, got shape {a.shape}")
    return a if a.dtype == np.bool_ else a.astype(bool)


def _positive_int(v, name: str) -> int:
    try:
        i = int(v)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a positive integer, got {v!r}") from None
    if i < 1 or i != v:
        raise InputError(f"{name}: expected a positive integer, got {v!r}")
    return i


def pack_bits(sel) -> np.ndarray:
    """Pack a bool mask into 32-bit words along x (the bit map of voxels ``B``).

    Parameters
    ----------
    sel : (nz, ny, nx) bool
        Selection mask.

    Returns
    -------
    (nz, ny, ceil(nx/32)) uint32
        Bit ``x % 32`` of word ``x // 32`` is ``sel[..., x]``; padding bits are 0.

    Examples
    --------
    >>> sel = np.zeros((1, 1, 33), bool)
    >>> sel[0, 0, [0, 3, 32]] = True
    >>> pack_bits(sel)
    array([[[9, 1]]], dtype=uint32)
    """
    s = _mask3(sel)
    nz, ny, nx = s.shape
    nw = words_per_row(nx)
    words = np.zeros((nz, ny, nw), dtype="<u4")
    packed = np.packbits(s, axis=-1, bitorder="little")
    words.view(np.uint8)[..., : packed.shape[-1]] = packed
    return words.astype(np.uint32, copy=False)


def unpack_bits(words, nx: int) -> np.ndarray:
    """Inverse of :func:`pack_bits`: ``(nz, ny, nw)`` uint32 -> ``(nz, ny, nx)`` bool.

    Examples
    --------
    >>> unpack_bits(np.array([[[9, 1]]], np.uint32), 33).nonzero()[2]
    array([ 0,  3, 32])
    """
    w = np.ascontiguousarray(np.asarray(words, dtype="<u4"))
    if w.ndim != 3 or w.shape[-1] * 32 < nx:
        raise InputError(f"words: expected (nz, ny, >= {words_per_row(nx)}) uint32, got {w.shape}")
    bits = np.unpackbits(w.view(np.uint8), axis=-1, count=int(nx), bitorder="little")
    return bits.astype(bool)


def patch_grid(nx: int, ny: int, nz: int, l: int = 64) -> tuple[int, int, int]:
    """The paper's grid of patch-quads ``(n_p, m_p, q_p)``.

    Each patch covers ``(l+1) × (l+1)`` voxels in x and y of one z slice:
    ``n_p = ceil(nx/(l+1))``, ``m_p = ceil(ny/(l+1))``, ``q_p = nz``.

    Examples
    --------
    >>> patch_grid(1000, 1000, 1000)
    (16, 16, 1000)
    """
    L = _positive_int(l, "l") + 1
    nx, ny, nz = (_positive_int(n, "size") for n in (nx, ny, nz))
    return (-(-nx // L), -(-ny // L), nz)


def _any_blocks(a: np.ndarray, step: int, axis: int) -> np.ndarray:
    """OR over consecutive groups of ``step`` along ``axis`` (last group may be short)."""
    if step == 1:
        return a
    return np.logical_or.reduceat(a, np.arange(0, a.shape[axis], step), axis=axis)


def patch_bitmap(sel, l: int = 64) -> np.ndarray:
    """Patch-quad occupancy ``(q_p, m_p, n_p)`` bool: any selected voxel in the patch's group.

    Pack it with :func:`pack_bits` for the GPU.

    Examples
    --------
    >>> sel = np.zeros((2, 3, 70), bool); sel[1, 2, 66] = True
    >>> patch_bitmap(sel, l=64).astype(int).tolist()
    [[[0, 0]], [[0, 1]]]
    """
    s = _mask3(sel)
    L = _positive_int(l, "l") + 1
    return _any_blocks(_any_blocks(s, L, 1), L, 2)


def brick_occupancy(sel, brick: int = 8) -> np.ndarray:
    """Brick occupancy, ``ceil((nz, ny, nx) / brick)`` uint8: 1 if any voxel of the brick is on.

    Examples
    --------
    >>> sel = np.zeros((9, 8, 17), bool); sel[8, 0, 16] = True
    >>> brick_occupancy(sel).shape, int(brick_occupancy(sel)[1, 0, 2])
    ((2, 1, 3), 1)
    """
    s = _mask3(sel)
    b = _positive_int(brick, "brick")
    return _any_blocks(_any_blocks(_any_blocks(s, b, 0), b, 1), b, 2).astype(np.uint8)


def brick_occupancy_from_bits(words, nx: int, brick: int = 8) -> np.ndarray:
    """:func:`brick_occupancy` from the packed bit map (fast: ORs 32 voxels at a time).

    ``brick`` must divide 32 (1, 2, 4, 8, 16 or 32).

    Examples
    --------
    >>> sel = np.zeros((9, 8, 17), bool); sel[8, 0, 16] = True
    >>> np.array_equal(brick_occupancy_from_bits(pack_bits(sel), 17), brick_occupancy(sel))
    True
    """
    b = _positive_int(brick, "brick")
    if 32 % b:
        raise InputError(f"brick: {b} does not divide 32; use brick_occupancy")
    w = np.asarray(words, dtype=np.uint32)
    if w.ndim != 3 or w.shape[-1] != words_per_row(nx):
        raise InputError(f"words: expected (nz, ny, {words_per_row(nx)}) uint32, got {w.shape}")
    w = np.bitwise_or.reduceat(w, np.arange(0, w.shape[0], b), axis=0)
    w = np.bitwise_or.reduceat(w, np.arange(0, w.shape[1], b), axis=1)
    per = 32 // b
    mask = np.uint32((1 << b) - 1) if b < 32 else np.uint32(0xFFFFFFFF)
    shifts = (np.arange(per, dtype=np.uint32) * np.uint32(b))[None, None, None, :]
    occ = ((w[..., None] >> shifts) & mask) != 0
    occ = occ.reshape(*w.shape[:2], -1)[..., : -(-int(nx) // b)]
    return np.ascontiguousarray(occ, dtype=np.uint8)


def _colour_lut(dtype: np.dtype, lo: float, hi: float) -> np.ndarray:
    info = np.iinfo(dtype)
    v = np.arange(int(info.min), int(info.max) + 1, dtype=np.float64)
    return _colour_float(v, lo, hi)


def _colour_float(v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    if hi == lo:
        return np.zeros(np.shape(v), np.uint8)
    t = np.asarray(v, dtype=np.float64) - lo
    t /= hi - lo
    t *= 255.0
    np.rint(t, out=t)
    np.clip(t, 0, 255, out=t)
    t[np.isnan(t)] = 0
    return t.astype(np.uint8)


def color_index(block, lo, hi, out=None) -> np.ndarray:
    """The 1-byte colour index map ``I``: ``round((v - lo) / (hi - lo) * 255)`` clipped to 0..255.

    Rounding is numpy's (half to even) in float64; ``lo == hi`` gives all 0 and NaN gives 0.
    8- and 16-bit integer data go through an exact lookup table (no float temporary).

    Parameters
    ----------
    block : array_like
        Values, any shape.
    lo, hi : number
        Colour range (finite, ``lo <= hi``); values outside it clip to 0 or 255.
    out : numpy.ndarray of uint8, optional
        Where to write the result (same shape as ``block``).

    Examples
    --------
    >>> color_index(np.array([100, 150, 200, 250], np.uint16), 100, 200)
    array([  0, 128, 255, 255], dtype=uint8)
    """
    a = np.asarray(block)
    flo, fhi = check_range(lo, hi, None, name="colour range")
    if not (math.isfinite(flo) and math.isfinite(fhi)):
        raise InputError(f"colour range: expected finite bounds, got [{lo}, {hi}]")
    if out is not None and (out.shape != a.shape or out.dtype != np.uint8):
        raise InputError(f"out: expected {a.shape} uint8, got {out.shape} {out.dtype}")
    if out is None:
        out = np.empty(a.shape, np.uint8)
    if a.dtype.kind in "ui" and a.dtype.itemsize <= 2:
        lut = _colour_lut(a.dtype, flo, fhi)
        # blocks of 1M values bound the intp index temporary numpy makes for the gather
        for b in _blocks(a.shape, 1 << 20):
            idx = a[b]
            if a.dtype.kind == "i":  # order-preserving int -> uint: flip the sign bit (v - min)
                ut = np.dtype(f"u{a.dtype.itemsize}")
                idx = idx.view(ut) ^ ut.type(1 << (8 * a.dtype.itemsize - 1))
            out[b] = np.take(lut, idx)
        return out
    for b in _blocks(a.shape, 1 << 22):  # blocks of 4M values bound the float64 temporary
        out[b] = _colour_float(a[b], flo, fhi)
    return out


def _blocks(shape, limit: int):
    """Index tuples covering an array of ``shape`` in blocks of about ``limit`` elements or less.

    Leading axes are split first, so blocks of a C-ordered array are contiguous; no reshape (and
    so no copy of a non-contiguous array) is needed.
    """
    if len(shape) == 0 or math.prod(shape) <= limit:
        yield ()
        return
    rest = math.prod(shape[1:])
    if rest <= limit:
        step = max(1, limit // rest)
        for i in range(0, shape[0], step):
            yield (slice(i, i + step),)
        return
    for i in range(shape[0]):
        for sub in _blocks(shape[1:], limit):
            yield (i, *sub)


@dataclass
class SelectionMaps:
    """Everything the GPU needs to draw the selected voxels of one box.

    bits:        (nz, ny, ceil(nx/32)) uint32   bit map of voxels ``B`` (see :func:`pack_bits`)
    patch_bits:  (q_p, m_p, ceil(n_p/32)) uint32 bit map of patch-quads ``B_p``
    patch_shape: (n_p, m_p, q_p)                 the patch grid, as :func:`patch_grid` returns it
    bricks:      ceil((nz, ny, nx)/brick) uint8  brick occupancy (host side: bricked views; the
                                                 ray caster's skip map is built from ``bits``)
    color:       (nz, ny, nx) uint8              colour index map ``I``
    count:       int                             number of selected voxels
    shape_xyz:   (nx, ny, nz)                    box size in voxels
    """

    bits: np.ndarray
    patch_bits: np.ndarray
    patch_shape: tuple[int, int, int]
    bricks: np.ndarray
    color: np.ndarray
    count: int
    shape_xyz: tuple[int, int, int]
    box: Box | None = None
    range: tuple[float, float] = (0.0, 0.0)
    color_range: tuple[float, float] = (0.0, 0.0)
    l: int = 64
    brick: int = 8

    @property
    def patch_mask(self) -> np.ndarray:
        """(q_p, m_p, n_p) bool: the unpacked patch bit map."""
        return unpack_bits(self.patch_bits, self.patch_shape[0])

    @property
    def active_patches(self) -> int:
        """Number of patch-quads holding at least one selected voxel."""
        return int(np.count_nonzero(self.patch_mask))

    def gpu_bytes(self, method: str, count: int | None = None) -> int:
        """:func:`gpu_bytes_estimate` for this box (``count`` defaults to :attr:`count`)."""
        return gpu_bytes_estimate(
            self.shape_xyz, method, self.count if count is None else count, self.l
        )


def slab_maps(slab, flo: float, fhi: float, clo: float, chi: float, l: int = 64,
              brick: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """The maps of one z slab (a multiple of ``brick`` slices but the last):
    ``(bits, patch mask, brick occupancy, colour indices, selected count)``.

    The body of :func:`build_selection_maps` and of the dask graph's tasks
    (:func:`geoshade.compute.voxels.lazy.selection_maps_graph`); ranges already checked.
    """
    slab = np.asarray(slab)
    sel = select(slab, flo, fhi)
    bits = pack_bits(sel)
    if 32 % brick == 0:
        bricks = brick_occupancy_from_bits(bits, slab.shape[2], brick)
    else:
        bricks = brick_occupancy(sel, brick)
    return (bits, np.ascontiguousarray(patch_bitmap(sel, l)), bricks,
            color_index(slab, clo, chi), int(np.count_nonzero(sel)))


#: input bytes per chunk of a slab processed on one core (the chunks of a slab run in parallel)
WORK_BYTES = 4 * 2**20
_POOL: list[ThreadPoolExecutor] = []


def _pool_map(fn, items: list) -> list:
    """``[fn(i) for i in items]`` on a thread pool of one thread per usable core."""
    if len(items) < 2:
        return [fn(i) for i in items]
    if not _POOL:
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
        _POOL.append(ThreadPoolExecutor(max(1, min(8, cores or 1)), "geoshade-maps"))
    return list(_POOL[0].map(fn, items))


def maps_args(dtype, lo, hi, color_lo, color_hi, l, brick):
    """Checked ``(l, brick, lo, hi, colour lo, colour hi)`` of a maps build (the colour range
    defaults to the selection range)."""
    l, brick = _positive_int(l, "l"), _positive_int(brick, "brick")
    flo, fhi = check_range(lo, hi, dtype)
    clo, chi = (flo, fhi) if color_lo is None and color_hi is None else (color_lo, color_hi)
    return (l, brick, flo, fhi, *check_range(clo, chi, None, name="colour range"))


def build_selection_maps(
    block_or_volume_data,
    box=None,
    lo=0,
    hi=0,
    color_lo=None,
    color_hi=None,
    l: int = 64,
    brick: int = 8,
    progress: Progress | None = None,
    slab_bytes: int = SLAB_BYTES,
) -> SelectionMaps:
    """Build all selection maps of a box, streaming z-slabs of about ``slab_bytes`` of input.

    Parameters
    ----------
    block_or_volume_data : VoxelVolume or (nz, ny, nx) array
        Numpy array, memmap, dask or zarr array (each slab goes through ``np.asarray``).
    box : Box, [x0, y0, z0, nx, ny, nz] or None
        Sub-volume (None: all of it).
    lo, hi : number
        Selection range, inclusive.
    color_lo, color_hi : number, optional
        Colour range of the colour index map (default: the selection range).
    l : int
        Patch-quad subdivision (each patch covers ``(l+1)²`` voxels).
    brick : int
        Brick edge for the occupancy map.
    progress : callable(done, total), optional
        Called after each slab with the number of z slices done and in all.
    slab_bytes : int
        Input bytes per slab (slabs hold a multiple of ``lcm(8, brick)`` slices).

    Returns
    -------
    SelectionMaps

    Examples
    --------
    >>> a = np.arange(4 * 5 * 40, dtype=np.uint16).reshape(4, 5, 40)
    >>> m = build_selection_maps(a, None, 100, 299)
    >>> m.count, m.bits.shape, m.patch_shape, m.bricks.shape, m.color.shape
    (200, (4, 5, 2), (1, 1, 4), (1, 1, 5), (4, 5, 40))
    """
    data, box, _ = resolve_data_box(block_or_volume_data, box)
    l, brick, flo, fhi, clo, chi = maps_args(data.dtype, lo, hi, color_lo, color_hi, l, brick)
    nx, ny, nz = box.size
    n_p, m_p, q_p = patch_grid(nx, ny, nz, l)
    bits = np.zeros((nz, ny, words_per_row(nx)), np.uint32)
    patch_mask = np.zeros((q_p, m_p, n_p), bool)
    bricks = np.zeros((-(-nz // brick), -(-ny // brick), -(-nx // brick)), np.uint8)
    color = np.empty((nz, ny, nx), np.uint8)
    multiple = math.lcm(8, brick)

    def fill(z: int, part: np.ndarray) -> int:  # the maps of slices z.. (disjoint outputs)
        z1 = z + part.shape[0]
        b, p, br, c, n = slab_maps(part, flo, fhi, clo, chi, l, brick)
        bits[z:z1], patch_mask[z:z1], color[z:z1] = b, p, c
        bricks[z // brick : -(-z1 // brick)] = br
        return n

    count = 0
    for z, slab in iter_z_slabs(data, box, multiple, slab_bytes, progress):
        # numpy releases the GIL: the slab's chunks run on all cores
        step = slab_depth(box.size, slab.dtype.itemsize, multiple, WORK_BYTES)
        chunks = [(z + k, slab[k : k + step]) for k in range(0, slab.shape[0], step)]
        count += sum(_pool_map(lambda c: fill(*c), chunks))
    return SelectionMaps(
        bits=bits,
        patch_bits=pack_bits(patch_mask),
        patch_shape=(n_p, m_p, q_p),
        bricks=bricks,
        color=color,
        count=count,
        shape_xyz=(nx, ny, nz),
        box=box,
        range=(flo, fhi),
        color_range=(clo, chi),
        l=l,
        brick=brick,
    )


def gpu_bytes_breakdown(
    shape_xyz, method: str, count: int | None = None, l: int = 64
) -> dict[str, int]:
    """Bytes of each GPU object a method allocates for a box; the renderer allocates exactly these.

    ========  ==================================================================================
    method    objects
    ========  ==================================================================================
    trefoil   ``bits`` (R32UI ``ceil(nx/32)×ny×nz``), ``patch_bits`` (R32UI
              ``ceil(n_p/32)×m_p×q_p``), ``color`` (R8UI ``nx×ny×nz``), ``palette`` (RGBA8 256)
    raycast   ``bits``, ``bricks`` (the skip map: RGB32UI ``ceil(n/8)`` per axis, see
              :mod:`geoshade.compute.voxels.skipmap`), ``color``, ``palette``
    gs        ``bits``, ``color``, ``palette``, ``points``: 4 bytes per selected voxel
    cubes     ``palette``, ``vertices``: 36 vertices × 8 bytes per drawn voxel
    ========  ==================================================================================

    ``count`` is required for 'gs' (selected voxels) and 'cubes' (drawn voxels).

    Examples
    --------
    >>> gpu_bytes_breakdown((100, 100, 100), "trefoil")
    {'bits': 160000, 'patch_bits': 800, 'color': 1000000, 'palette': 1024}
    """
    nx, ny, nz = (_positive_int(n, "shape") for n in shape_xyz)
    n_p, m_p, q_p = patch_grid(nx, ny, nz, l)
    bits = 4 * nz * ny * words_per_row(nx)
    color = nx * ny * nz
    palette = 4 * PALETTE_SIZE
    if method in ("gs", "cubes"):
        if count is None or int(count) < 0:
            raise InputError(f"gpu bytes: method {method!r} needs count >= 0, got {count!r}")
        count = int(count)
    if method == "trefoil":
        patch = 4 * q_p * m_p * words_per_row(n_p)
        return {"bits": bits, "patch_bits": patch, "color": color, "palette": palette}
    if method == "raycast":
        return {"bits": bits, "bricks": skip_map_bytes((nx, ny, nz)), "color": color,
                "palette": palette}
    if method == "gs":
        return {"bits": bits, "color": color, "palette": palette, "points": GS_VOXEL_BYTES * count}
    if method == "cubes":
        return {"palette": palette, "vertices": CUBE_VERTICES * CUBE_VERTEX_BYTES * count}
    raise InputError(f"method: unknown {method!r}; expected one of {', '.join(METHODS)}")


def gpu_bytes_estimate(shape_xyz, method: str, count: int | None = None, l: int = 64) -> int:
    """Total GPU bytes of a method for a box: the sum of :func:`gpu_bytes_breakdown`.

    Examples
    --------
    >>> gpu_bytes_estimate((100, 100, 100), "cubes", count=10)
    3904
    """
    return sum(gpu_bytes_breakdown(shape_xyz, method, count, l).values())


def bytes_per_voxel(shape_xyz, method: str, count: int | None = None, **kw) -> float:
    """GPU bytes per voxel of the box (:func:`gpu_bytes_estimate` / number of voxels).

    Examples
    --------
    >>> round(bytes_per_voxel((1000, 1000, 1000), "trefoil"), 4)
    1.1281
    """
    nx, ny, nz = (int(n) for n in shape_xyz)
    return gpu_bytes_estimate(shape_xyz, method, count, **kw) / (nx * ny * nz)
