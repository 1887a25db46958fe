"""Depth compositing of tiles drawn apart, and the bookkeeping of parts on workers (no GL).

A picture drawn across workers (:mod:`geoshade.render.distributed`) comes back as *tiles*: each
worker draws the parts it holds (a core's bricks, later a grid's chunked face sets) and returns
colour, depth and the *rank* of the part that won each pixel, for its screen footprint only.
:func:`composite` merges them.

**The tie rule.** A pixel shows the fragment with the smallest ``(depth, rank)``, compared
lexicographically: the nearest depth wins, and on equal depth the part with the lower rank.
The rank of a part is its place in the order a single process draws the parts in
(:func:`front_to_back`: nearest part centre first, ties by part index), so the rule is exactly
what one process's depth test (``GL_LESS``: a later fragment of equal depth loses) leaves after
drawing the parts in that order. Pixels no part drew keep depth 1.0 and the background (a
fragment of depth 1.0 never passes ``GL_LESS`` against the cleared depth, so depth < 1.0 means
drawn). The rule is commutative: tiles may arrive in any order.

**Direct-send** (IceT's simplest scheme): instead of every tile travelling to the client, the
picture is cut into :func:`bands`, one per worker; each worker fetches the pieces of its band
from its peers (:func:`crop`) and composites them (:func:`composite_band`), so the client
receives one picture (colour and depth) per frame whatever the number of workers.

Other pieces: :func:`footprint` (the pixel rectangle a box can cover, from its projected
corners), :func:`spatial_order` and :func:`assign` (parts to workers, balanced by weight, each
worker a compact run of a space-filling curve so its footprint stays small), :func:`reassign`
(a lost worker's parts to the survivors).

Examples
--------
>>> import numpy as np
>>> a = Tile.empty((0, 0, 2, 1), 2); b = Tile.empty((0, 0, 2, 1), 2)
>>> a.depth[:] = 0.5; a.rank[:] = 1; a.color[:] = 10
>>> b.depth[:] = (0.5, 0.2); b.rank[:] = 0; b.color[:] = 20
>>> color, depth, rank = composite([a, b], (2, 1))
>>> color[0, :, 0].tolist(), depth[0].tolist(), rank[0].tolist()
([20, 20], [0.5, 0.20000000298023224], [0, 0])
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: depth of a pixel nothing was drawn into (the cleared depth buffer)
FAR = np.float32(1.0)


def rank_dtype(n_parts: int) -> np.dtype:
    """The smallest unsigned dtype holding ranks ``0 .. n_parts - 1`` and the empty mark.

    >>> rank_dtype(10), rank_dtype(70000)
    (dtype('uint16'), dtype('uint32'))
    """
    return np.dtype(np.uint16) if n_parts < np.iinfo(np.uint16).max else np.dtype(np.uint32)


def empty_rank(dtype) -> int:
    """The rank of a pixel nothing was drawn into: the dtype's largest value."""
    return int(np.iinfo(np.dtype(dtype)).max)


@dataclass
class Tile:
    """Colour, depth and rank of one worker's screen footprint.

    rect:  (x0, y0, w, h)  pixels, origin at the top left (as the image array)
    color: (h, w, 4) uint8 RGBA, row 0 at the top
    depth: (h, w) float32  window depth in [0, 1]; 1.0 where nothing was drawn
    rank:  (h, w) uint16 or uint32  rank of the part that won (see the module's tie rule);
           the dtype's largest value where nothing was drawn
    """

    rect: tuple[int, int, int, int]
    color: np.ndarray
    depth: np.ndarray
    rank: np.ndarray

    def __post_init__(self) -> None:
        x0, y0, w, h = (int(v) for v in self.rect)
        self.rect = (x0, y0, w, h)
        shapes = {"color": ((h, w, 4), np.uint8), "depth": ((h, w), np.float32),
                  "rank": ((h, w), None)}
        for name, (shape, dtype) in shapes.items():
            a = getattr(self, name)
            if a.shape != shape or (dtype is not None and a.dtype != dtype):
                raise ValueError(f"tile.{name}: expected {shape} {dtype or 'uint'}, got "
                                 f"{a.shape} {a.dtype}")
        if self.rank.dtype not in (np.uint16, np.uint32):
            raise ValueError(f"tile.rank: expected uint16 or uint32, got {self.rank.dtype}")

    @classmethod
    def empty(cls, rect, n_parts: int = 1) -> Tile:
        """A tile of ``rect`` with nothing drawn."""
        _, _, w, h = (int(v) for v in rect)
        dt = rank_dtype(n_parts)
        return cls(tuple(rect), np.zeros((h, w, 4), np.uint8), np.full((h, w), FAR, np.float32),
                   np.full((h, w), empty_rank(dt), dt))

    @property
    def nbytes(self) -> int:
        """Bytes of the tile's arrays (what crosses the network)."""
        return int(self.color.nbytes + self.depth.nbytes + self.rank.nbytes)

    def merge(self, color, depth, rank: int, rect) -> None:
        """Merge one part's pixels (``color (h, w, 4)``, ``depth (h, w)`` of ``rect``, inside
        this tile's rect) drawn with ``rank``, by the tie rule."""
        x0, y0, w, h = (int(v) for v in rect)
        tx, ty = x0 - self.rect[0], y0 - self.rect[1]
        sub = (slice(ty, ty + h), slice(tx, tx + w))
        _merge(self.color[sub], self.depth[sub], self.rank[sub], color, depth,
               np.asarray(rank, self.rank.dtype))


def _merge(color, depth, rank, new_color, new_depth, new_rank) -> None:
    """In place: where the new pixel was drawn (depth < 1) and ``(new_depth, new_rank) <
    (depth, rank)``, take it."""
    win = ((new_depth < depth) | ((new_depth == depth) & (new_rank < rank))) & (new_depth < FAR)
    np.copyto(depth, new_depth, where=win)
    np.copyto(rank, new_rank, where=win, casting="unsafe")
    np.copyto(color, new_color, where=win[..., None])


def _key(depth: np.ndarray, rank: np.ndarray) -> np.ndarray:
    """``(depth, rank)`` as one uint64 that orders as the pair does: depths in [0, 1] order as
    their float32 bit patterns, the rank fills the low 32 bits."""
    key = depth.view(np.uint32).astype(np.uint64)
    key <<= np.uint64(32)
    key |= rank
    return key


def composite(tiles: Sequence[Tile], size, background=(0, 0, 0, 0), n_parts: int | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge ``tiles`` into one picture of ``size`` (width, height) by the tie rule.

    Parameters
    ----------
    tiles : sequence of Tile
        In any order (the result does not depend on it). A tile's pixels of depth 1.0 are
        holes (nothing drawn) and never win.
    size : (int, int)
        Width and height of the picture.
    background : 4 ints
        RGBA (uint8) of pixels no tile drew.
    n_parts : int, optional
        Number of parts (for the rank dtype; default: from the tiles).

    Returns
    -------
    color : (h, w, 4) uint8
    depth : (h, w) float32
        1.0 where nothing was drawn.
    rank : (h, w) uint16 or uint32
        The winning part's rank (the dtype's largest value where nothing was drawn).

    Examples
    --------
    >>> t = Tile.empty((1, 0, 1, 1)); t.depth[:] = 0.3; t.rank[:] = 0; t.color[:] = 255
    >>> c, d, r = composite([t], (3, 1), background=(9, 9, 9, 255))
    >>> c[0, :, 0].tolist(), d[0].tolist()
    ([9, 255, 9], [1.0, 0.30000001192092896, 1.0])
    """
    w, h = (int(v) for v in size)
    if n_parts is None:
        dt = max((t.rank.dtype for t in tiles), key=lambda d: d.itemsize, default=np.uint16)
    else:
        dt = rank_dtype(n_parts)
    color = np.empty((h, w), np.uint32)   # RGBA8 as one word per pixel: one copy per pixel
    color.fill(np.frombuffer(np.asarray(background, np.uint8).tobytes(), np.uint32)[0])
    key = np.empty((h, w), np.uint64)
    key.fill((int(np.float32(FAR).view(np.uint32)) << 32) | empty_rank(dt))
    for t in tiles:
        x0, y0, tw, th = t.rect
        if x0 < 0 or y0 < 0 or x0 + tw > w or y0 + th > h:
            raise ValueError(f"tile rect {t.rect} outside the {w}x{h} picture")
        sub = (slice(y0, y0 + th), slice(x0, x0 + tw))
        tkey = _key(t.depth, t.rank)
        win = tkey < key[sub]
        win &= t.depth < FAR   # a hole never wins, whatever rank it carries
        np.copyto(key[sub], tkey, where=win)
        np.copyto(color[sub], np.ascontiguousarray(t.color).view(np.uint32)[..., 0], where=win)
    if sys.byteorder == "little":   # the two halves of each key as views, no arithmetic
        halves = key.view(np.uint32).reshape(h, w, 2)
        depth = np.ascontiguousarray(halves[..., 1]).view(np.float32)
        rank = halves[..., 0].astype(dt)
    else:
        depth = (key >> np.uint64(32)).astype(np.uint32).view(np.float32)
        rank = (key & np.uint64(0xFFFFFFFF)).astype(dt)
    return color.view(np.uint8).reshape(h, w, 4), depth, rank


# --------------------------------------------------------------------------------------------
# direct-send compositing: each worker composites one band of the picture from its peers' pieces
# --------------------------------------------------------------------------------------------
def bands(size, n: int) -> list[tuple[int, int, int, int]]:
    """The picture of ``size`` (width, height) cut into at most ``n`` bands of whole rows,
    ``(x0, y0, w, h)`` top to bottom, heights differing by at most one row (direct-send
    compositing: band ``k`` is composited by worker ``k``).

    >>> bands((4, 5), 2)
    [(0, 0, 4, 2), (0, 2, 4, 3)]
    >>> bands((4, 2), 3)
    [(0, 0, 4, 1), (0, 1, 4, 1)]
    """
    w, h = (int(v) for v in size)
    n = max(1, min(int(n), h))
    edges = [round(i * h / n) for i in range(n + 1)]
    return [(0, edges[i], w, edges[i + 1] - edges[i]) for i in range(n)
            if edges[i + 1] > edges[i]]


def crop(tile: Tile, rect) -> Tile | None:
    """The part of ``tile`` inside ``rect`` (picture pixels), as a tile of its own (copies, so
    only those pixels travel); None when they do not overlap.

    >>> t = Tile.empty((1, 1, 3, 3)); crop(t, (0, 2, 10, 1)).rect
    (1, 2, 3, 1)
    >>> crop(t, (0, 0, 10, 1)) is None
    True
    """
    x0 = max(tile.rect[0], int(rect[0]))
    y0 = max(tile.rect[1], int(rect[1]))
    x1 = min(tile.rect[0] + tile.rect[2], int(rect[0]) + int(rect[2]))
    y1 = min(tile.rect[1] + tile.rect[3], int(rect[1]) + int(rect[3]))
    if x1 <= x0 or y1 <= y0:
        return None
    sub = (slice(y0 - tile.rect[1], y1 - tile.rect[1]), slice(x0 - tile.rect[0],
                                                              x1 - tile.rect[0]))
    return Tile((x0, y0, x1 - x0, y1 - y0), tile.color[sub].copy(), tile.depth[sub].copy(),
                tile.rank[sub].copy())


def composite_band(tiles: Sequence[Tile], band, background=(0, 0, 0, 0),
                   n_parts: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`composite` of ``tiles`` (in picture pixels, any that overlap ``band``) over the
    pixels of ``band`` only: ``(color (h, w, 4) uint8, depth (h, w) float32)`` of the band.
    Equal, pixel for pixel, to the same rows of :func:`composite` of the whole picture (the tie
    rule is per pixel), so bands composited on different workers make the one picture.

    >>> t = Tile.empty((0, 0, 2, 2)); t.depth[:] = 0.5; t.rank[:] = 0; t.color[:] = 7
    >>> c, d = composite_band([t], (0, 1, 3, 1))
    >>> c[..., 0].tolist(), d.tolist()
    ([[7, 7, 0]], [[0.5, 0.5, 1.0]])
    """
    bx, by, bw, bh = (int(v) for v in band)
    shifted = []
    for t in tiles:
        c = crop(t, band)
        if c is not None:
            c.rect = (c.rect[0] - bx, c.rect[1] - by, c.rect[2], c.rect[3])
            shifted.append(c)
    color, depth, _ = composite(shifted, (bw, bh), background, n_parts=n_parts)
    return color, depth


def footprint(corners, pmv, size, pad: int = 1) -> tuple[int, int, int, int] | None:
    """The pixel rectangle ``(x0, y0, w, h)`` (top-left origin) that the convex hull of
    ``corners`` can cover on screen, clipped to the picture; None when it is off screen.

    Parameters
    ----------
    corners : (n, 3) float
        World points (a box's 8 corners).
    pmv : (4, 4) float
        Projection × view matrix.
    size : (int, int)
        Width, height.
    pad : int
        Pixels added on every side (rasterisation covers pixels whose centre is inside; the pad
        makes the rectangle safe against rounding).

    A corner at or behind the eye plane (w <= 0, perspective with the camera inside or beside
    the box) gives the whole picture: the projection of such points says nothing about the
    covered pixels. The rectangle only has to contain every pixel the part can draw: pixels
    outside it are taken as not drawn.

    Examples
    --------
    >>> c = np.array([[x, y, 0.0] for x in (-0.5, 0.5) for y in (-0.5, 0.5)])
    >>> footprint(c, np.eye(4), (100, 100), pad=0)
    (25, 25, 50, 50)
    >>> footprint(c + 5, np.eye(4), (100, 100)) is None
    True
    """
    w, h = (int(v) for v in size)
    p = np.c_[np.asarray(corners, float), np.ones(len(corners))] @ np.asarray(pmv, float).T
    if np.any(p[:, 3] <= 1e-9):
        return (0, 0, w, h)
    ndc = p[:, :2] / p[:, 3:4]
    px = (ndc[:, 0] + 1.0) * 0.5 * w
    py = (1.0 - ndc[:, 1]) * 0.5 * h
    x0 = max(0, int(np.floor(px.min())) - pad)
    x1 = min(w, int(np.ceil(px.max())) + pad)
    y0 = max(0, int(np.floor(py.min())) - pad)
    y1 = min(h, int(np.ceil(py.max())) + pad)
    if x1 <= x0 or y1 <= y0:
        return None
    return (x0, y0, x1 - x0, y1 - y0)


def union(rects) -> tuple[int, int, int, int] | None:
    """The bounding rectangle of ``rects`` (None entries skipped); None if there are none.

    >>> union([(0, 0, 2, 2), None, (5, 1, 1, 4)])
    (0, 0, 6, 5)
    """
    rs = [r for r in rects if r is not None]
    if not rs:
        return None
    x0 = min(r[0] for r in rs)
    y0 = min(r[1] for r in rs)
    x1 = max(r[0] + r[2] for r in rs)
    y1 = max(r[1] + r[3] for r in rs)
    return (x0, y0, x1 - x0, y1 - y0)


def front_to_back(centres, model, eye) -> np.ndarray:
    """Rank of each part in the single-process drawing order: nearest centre first (distance
    from ``eye`` of ``model @ centre``), ties by part index.

    ``centres``: (n, 3) part centres in the model's index space (a brick's centre relative to
    its box); the same arithmetic as :class:`geoshade.render.visuals.bricked.BrickedVisual`,
    so the ranks are the order it draws in.

    >>> front_to_back([[0, 0, 5], [0, 0, 1], [0, 0, 1]], np.eye(4), np.zeros(3)).tolist()
    [2, 0, 1]
    """
    c = np.asarray(centres, float)
    world = (np.c_[c, np.ones(len(c))] @ np.asarray(model).T)[:, :3]
    order = np.argsort(np.linalg.norm(world - eye, axis=1), kind="stable")
    ranks = np.empty(len(order), np.int64)
    ranks[order] = np.arange(len(order))
    return ranks


def _spread_bits(v: np.ndarray) -> np.ndarray:
    """Bits of ``v`` (< 2**21) spread three apart (Morton interleaving)."""
    v = v.astype(np.uint64) & np.uint64(0x1FFFFF)
    for shift, mask in ((32, 0x1F00000000FFFF), (16, 0x1F0000FF0000FF), (8, 0x100F00F00F00F00F),
                        (4, 0x10C30C30C30C30C3), (2, 0x1249249249249249)):
        v = (v | (v << np.uint64(shift))) & np.uint64(mask)
    return v


def spatial_order(cells) -> np.ndarray:
    """Indices of parts sorted along a Morton (Z-order) curve of their integer grid cells
    ``(n, 3)``; ties by index. Runs of this order are compact on screen.

    >>> spatial_order([[1, 1, 0], [0, 0, 0], [1, 0, 0], [0, 1, 0]]).tolist()
    [1, 2, 3, 0]
    """
    c = np.asarray(cells, np.int64).reshape(-1, 3)
    code = _spread_bits(c[:, 0]) | (_spread_bits(c[:, 1]) << np.uint64(1)) | \
        (_spread_bits(c[:, 2]) << np.uint64(2))
    return np.argsort(code, kind="stable")


def assign(weights, n_workers: int, order=None) -> list[list[int]]:
    """Parts to workers: ``order`` (default: index order) cut into ``n_workers`` contiguous
    runs of about equal total weight. Deterministic (the same input gives the same runs).

    A run ends at the first part where the running total reaches the next multiple of
    ``total / n_workers``; every worker gets at least one part while parts remain.

    >>> assign([4, 1, 1, 1, 1, 4], 2)
    [[0, 1, 2], [3, 4, 5]]
    >>> assign([1, 1], 3)
    [[0], [1], []]
    """
    w = np.asarray(weights, float)
    idx = np.arange(len(w)) if order is None else np.asarray(order, np.int64)
    n = max(1, int(n_workers))
    if len(idx) == 0:
        return [[] for _ in range(n)]
    cum = np.cumsum(w[idx])
    total = cum[-1] if cum[-1] > 0 else 1.0
    # run k holds the parts whose cumulative weight's midpoint falls in [k, k+1) * total / n
    mid = cum - w[idx] / 2.0
    run = np.minimum((mid / total * n).astype(np.int64), n - 1)
    pos = np.arange(len(idx))
    if len(idx) <= n:
        run = pos  # one part each
    else:  # at least one part per run: no run ahead of its position or too far behind it
        run = np.maximum(np.minimum(run, pos), n - (len(idx) - pos))
    out: list[list[int]] = [[] for _ in range(n)]
    for k in range(n):
        out[k] = [int(i) for i in idx[run == k]]
    return out


def reassign(assignment: Sequence[Sequence[int]], lost: Sequence[int], weights
             ) -> list[list[int]]:
    """``assignment`` with the parts of the workers in ``lost`` given to the others: each part
    (in the lost workers' order) to the surviving worker with the least weight so far (ties:
    the lower worker index). The lost workers' lists become empty.

    >>> reassign([[0, 1], [2], [3]], [0], [5, 1, 1, 1])
    [[], [2, 0], [3, 1]]
    """
    w = np.asarray(weights, float)
    out = [list(a) for a in assignment]
    gone = {int(k) for k in lost}
    alive = [k for k in range(len(out)) if k not in gone]
    if not alive:
        raise ValueError("reassign: no worker left")
    load = {k: float(w[out[k]].sum()) if out[k] else 0.0 for k in alive}
    for k in sorted(gone):
        for part in out[k]:
            best = min(alive, key=lambda j: (load[j], j))
            out[best].append(int(part))
            load[best] += float(w[part])
        out[k] = []
    return out


__all__ = ["FAR", "Tile", "assign", "composite", "empty_rank", "footprint", "front_to_back",
           "rank_dtype", "reassign", "spatial_order", "union"]
