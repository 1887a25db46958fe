"""The preview of a progressive CoreView: an overview level of the store, scaled to the box.

A box of a multiscale store (``geoshade core ingest``) with more than :data:`PREVIEW_VOXELS`
voxels is first drawn from the finest overview level whose part of the box is within that
budget (:func:`preview_level`), its voxels scaled so that they fill exactly the full box's
world extent (:func:`preview_volume`), the ROI mapped to the level's voxels
(:func:`preview_roi`). :mod:`geoshade.render.progressive` says how the preview is shown and
replaced.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from geoshade.compute.voxels.roi import Cylinder
from geoshade.compute.voxels.sample import SampleRoi
from geoshade.io.stores.zarr_io import read_level
from geoshade.models.volume import Box, VoxelVolume

#: voxels of a progressive View's preview box at most: the finest overview level whose part of
#: the box has no more is drawn first (256³: its maps build and draw in about a second here)
PREVIEW_VOXELS = 256**3


def store_path(volume: VoxelVolume) -> str | None:
    """The multiscale store ``volume`` was read from (level 0 of a store with overview
    levels), else None."""
    meta = volume.meta or {}
    if int(meta.get("levels") or 1) < 2 or meta.get("format") != "zarr" or meta.get("level"):
        return None
    return str(meta.get("source")) if meta.get("source") else None


def preview_level(volume: VoxelVolume, box: Box, budget: float | None = None) -> int | None:
    """The overview level a progressive View draws ``box`` from first: the finest level whose
    part of the box has at most ``budget`` (:data:`PREVIEW_VOXELS`) voxels, else the coarsest;
    None when the volume has no overview levels or the box is within the budget (the full
    picture comes as quickly).

    >>> import geoshade
    >>> vol = geoshade.synthetic_core(16)
    >>> preview_level(vol, vol.resolve_box(None)) is None
    True
    """
    budget = PREVIEW_VOXELS if budget is None else budget
    levels = int((volume.meta or {}).get("levels") or 1)
    if store_path(volume) is None or box.nvoxels <= budget:
        return None
    for k in range(1, levels):
        if box.nvoxels / 8**k <= budget:
            return k
    return levels - 1


def level_box(box: Box, k: int, shape_xyz) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Level ``k``'s voxels ``[lo, hi)`` covering level 0's ``box`` (2**k voxels a side each),
    within the level's ``shape_xyz``.

    >>> level_box(Box((3, 0, 0), (10, 8, 8)), 2, (4, 2, 2))
    ((0, 0, 0), (4, 2, 2))
    """
    f = 2**k
    lo = tuple(int(o) // f for o in box.offset)
    hi = tuple(min(int(n), -(-(int(o) + int(s)) // f))
               for o, s, n in zip(box.offset, box.size, shape_xyz, strict=True))
    return lo, hi


def preview_volume(volume: VoxelVolume, k: int, box: Box) -> tuple[VoxelVolume, Box]:
    """Level ``k`` of ``volume``'s store as a volume whose voxels over ``box`` fill exactly
    ``box``'s world extent (spacing and origin scaled: the preview and the full picture are
    the same size and place), and that box in the level's voxels."""
    lvl = read_level(store_path(volume), k)
    lo, hi = level_box(box, k, lvl.shape_xyz)
    sp0, o0 = np.asarray(volume.spacing, float), np.asarray(volume.origin, float)
    n = np.maximum(np.subtract(hi, lo), 1)
    sp = np.asarray(box.size, float) * sp0 / n
    origin = o0 + np.asarray(box.offset, float) * sp0 - np.asarray(lo, float) * sp
    meta = {**(lvl.meta or {}), "level": int(k), "levels": 1}
    shown = dataclasses.replace(lvl, spacing=(float(sp[0]), float(sp[1]), float(sp[2])),
                                origin=(float(origin[0]), float(origin[1]), float(origin[2])),
                                name=volume.name, meta=meta)
    return shown, shown.resolve_box([*lo, *(int(v) for v in n)])


def level_voxels(v, box: Box, lbox: Box) -> tuple[tuple, tuple]:
    """The first and last level-0 voxels (x, y, z) of ``box`` that the preview's voxel ``v``
    (of ``lbox``, the box in the level's voxels: :func:`preview_volume`) covers.

    >>> b0, b1 = Box((0, 0, 0), (64, 64, 32)), Box((0, 0, 0), (16, 16, 8))
    >>> level_voxels((1, 0, 7), b0, b1)
    ((4, 0, 28), (7, 3, 31))
    """
    s = np.asarray(box.size, float) / np.asarray(lbox.size, float)   # level-0 voxels per voxel
    rel = np.asarray(v, float) - np.asarray(lbox.offset, float)
    off, size = np.asarray(box.offset), np.asarray(box.size)
    lo = np.clip(off + np.floor(rel * s + 1e-9).astype(np.int64), off, off + size - 1)
    hi = np.clip(off + np.ceil((rel + 1) * s - 1e-9).astype(np.int64) - 1, lo, off + size - 1)
    return tuple(int(x) for x in lo), tuple(int(x) for x in hi)


def preview_roi(roi, box: Box, lbox: Box):
    """``roi`` (level-0 voxels) in the preview's voxels (``lbox`` over ``box``): a cylinder
    scaled, a detected sample's footprint sampled at the preview's voxel centres; None for a
    mask (the preview then shows the box's voxels: said by the note)."""
    if roi is None:
        return None
    s = np.asarray(box.size, float) / np.asarray(lbox.size, float)   # level-0 voxels per voxel

    def to_level(x, axis):
        return lbox.offset[axis] + (np.asarray(x, float) - box.offset[axis]) / s[axis]

    if isinstance(roi, Cylinder):
        return Cylinder(float(to_level(roi.cx, 0)), float(to_level(roi.cy, 1)),
                        float(roi.r / min(s[0], s[1])), roi.fitted)
    if isinstance(roi, SampleRoi):
        xs = np.arange(lbox.offset[0], lbox.offset[0] + lbox.size[0])
        ys = np.arange(lbox.offset[1], lbox.offset[1] + lbox.size[1])
        fx = np.floor(box.offset[0] + (xs - lbox.offset[0] + 0.5) * s[0]).astype(np.int64)
        fy = np.floor(box.offset[1] + (ys - lbox.offset[1] + 0.5) * s[1]).astype(np.int64)
        gy, gx = np.meshgrid(fy, fx, indexing="ij")
        z = np.full(gx.shape, roi.z0 if roi.z0 is not None else 0)
        foot = roi.contains(gx, gy, z)
        z0 = z1 = None
        if roi.z0 is not None:
            z0, z1 = (int(np.floor(to_level(v, 2))) for v in (roi.z0, roi.z1))
            z1 = max(z1, z0 + 1)
        return SampleRoi(foot, int(lbox.offset[1]), int(lbox.offset[0]), roi.threshold, z0, z1)
    return None


__all__ = ["PREVIEW_VOXELS", "level_box", "preview_level", "preview_roi", "preview_volume",
           "store_path"]
