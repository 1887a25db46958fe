"""A real region octree over labelled voxels: node counts and bytes, for Table 1 of the paper.

The labels are padded to a cube of ``N = 2^D`` voxels with EMPTY (a hierarchy needs power-of-two
sides, as the paper notes: Dataset A of 200×250×320 becomes 512³). A node is a leaf when its
region holds one label; otherwise it has 8 children. The tree is built bottom-up, level by
level, in blocks of ``block³`` voxels (vectorised numpy; blocks outside the data are one empty
leaf each), so models far larger than memory as dense voxels (800×1000×800) can be counted.

Byte accounting (one 32-bit word per node, as a pointer octree stores it compactly): an inner
node holds the index of the first of its 8 children (siblings are contiguous), a leaf holds its
label, a flag bit tells which. With ``max_depth = d`` (the paper's "Octree (6 levels)") the tree
stops at level ``d``; a non-uniform node there is a leaf brick of ``(N / 2^d)³`` voxels stored
densely at ``voxel_bytes`` each.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from geoshade.compute.stacks import stacks_to_voxels
from geoshade.models.stacks import EMPTY, StackModel

#: bytes per octree node (child pointer or leaf label)
NODE_BYTES = 4


def _reduce(uniform: np.ndarray, label: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One level up: (n, n, n) -> (n/2, n/2, n/2) uniform flags and labels."""
    h = label.shape[0] // 2

    def kids(a):
        return a.reshape(h, 2, h, 2, h, 2).transpose(0, 2, 4, 1, 3, 5).reshape(h, h, h, 8)

    lab = kids(label)
    uni = kids(uniform).all(axis=-1) & (lab == lab[..., :1]).all(axis=-1)
    return uni, np.ascontiguousarray(lab[..., 0])


def octree_counts(labels_of: Callable, shape_xyz, block: int = 128, progress=None) -> dict:
    """Count the non-uniform nodes per level of the octree over a labelled box.

    Parameters
    ----------
    labels_of : callable(region) -> (z1-z0, y1-y0, x1-x0) int array
        Labels of ``region = (x0, x1, y0, y1, z0, z1)`` (inside the data), z first.
    shape_xyz : (nx, ny, nz)
    block : int
        Side of the blocks built at once (a power of two).

    Returns
    -------
    dict
        ``side`` (N), ``depth`` (D), ``nonuniform`` (list: non-uniform nodes at level 0 (root)
        … D-1).

    Examples
    --------
    >>> a = np.zeros((4, 4, 4), np.int32); a[0, 0, 0] = 1
    >>> c = octree_counts(lambda r: a[r[4]:r[5], r[2]:r[3], r[0]:r[1]], (4, 4, 4))
    >>> c["side"], c["nonuniform"]
    (4, [1, 1])
    """
    nx, ny, nz = (int(v) for v in shape_xyz)
    side = 1 << max(0, math.ceil(math.log2(max(nx, ny, nz, 1))))
    depth = int(math.log2(side))
    b = min(side, 1 << max(0, math.ceil(math.log2(max(1, block)))))
    nb = side // b
    bdepth = int(math.log2(b))
    nonuni = np.zeros(depth + 1, np.int64)  # index: level (0 = root)
    top_u = np.ones((nb, nb, nb), bool)
    top_l = np.full((nb, nb, nb), EMPTY, np.int32)
    blocks = [(i, j, k) for k in range(nb) for j in range(nb) for i in range(nb)
              if i * b < nx and j * b < ny and k * b < nz]
    for done, (i, j, k) in enumerate(blocks, start=1):
        x0, y0, z0 = i * b, j * b, k * b
        x1, y1, z1 = min(nx, x0 + b), min(ny, y0 + b), min(nz, z0 + b)
        lab = np.full((b, b, b), EMPTY, np.int32)
        lab[: z1 - z0, : y1 - y0, : x1 - x0] = labels_of((x0, x1, y0, y1, z0, z1))
        lab = lab.transpose(2, 1, 0).copy()  # (x, y, z): any axis order gives the same tree
        uni = np.ones(lab.shape, bool)
        for lev in range(depth - 1, depth - bdepth - 1, -1):  # levels inside the block
            uni, lab = _reduce(uni, lab)
            nonuni[lev] += int(np.count_nonzero(~uni))
        top_u[i, j, k], top_l[i, j, k] = bool(uni[0, 0, 0]), int(lab[0, 0, 0])
        if progress is not None:
            progress(done, len(blocks))
    uni, lab = top_u, top_l
    for lev in range(depth - bdepth - 1, -1, -1):
        uni, lab = _reduce(uni, lab)
        nonuni[lev] += int(np.count_nonzero(~uni))
    return {"side": side, "depth": depth, "nonuniform": nonuni[:depth].tolist()}


def octree_memory(counts: dict, max_depth: int | None = None, voxel_bytes: int = 4) -> dict:
    """Nodes and bytes of the octree (full depth, or stopped at ``max_depth`` with dense bricks).

    Examples
    --------
    >>> octree_memory({"side": 4, "depth": 2, "nonuniform": [1, 1]})
    {'nodes': 17, 'leaves': 15, 'brick_voxels': 0, 'bytes': 68, 'depth': 2, 'side': 4}
    >>> octree_memory({"side": 4, "depth": 2, "nonuniform": [1, 1]}, max_depth=1)["bytes"]
    68
    """
    side, depth, nonuni = counts["side"], counts["depth"], list(counts["nonuniform"])
    d = depth if max_depth is None else max(0, min(int(max_depth), depth))
    inner = int(sum(nonuni[:d]))
    nodes = 1 + 8 * inner
    bricks = int(nonuni[d]) if d < depth else 0
    brick_vox = bricks * (side >> d) ** 3
    return {"nodes": nodes, "leaves": nodes - inner, "brick_voxels": brick_vox,
            "bytes": nodes * NODE_BYTES + brick_vox * voxel_bytes, "depth": d, "side": side}


def octree_of_labels(labels: np.ndarray, block: int = 128) -> dict:
    """:func:`octree_counts` of an in-memory ``(nz, ny, nx)`` integer label array.

    >>> octree_of_labels(np.ones((3, 5, 2), np.int8))["nonuniform"]
    [1, 2, 4]
    """
    a = np.asarray(labels)
    nz, ny, nx = a.shape
    return octree_counts(lambda r: a[r[4]:r[5], r[2]:r[3], r[0]:r[1]], (nx, ny, nz), block)


def octree_of_stacks(model: StackModel, block: int = 128, progress=None) -> dict:
    """:func:`octree_counts` of a stack model's voxels, made block by block from the stacks.

    >>> from geoshade.compute.stacks import voxels_to_stacks
    >>> octree_of_stacks(voxels_to_stacks(np.ones((3, 5, 2), np.int8)))["nonuniform"]
    [1, 2, 4]
    """

    nx, ny = model.shape
    return octree_counts(lambda r: stacks_to_voxels(model, np.int32, region=r),
                         (nx, ny, model.nlevels), block, progress=progress)
