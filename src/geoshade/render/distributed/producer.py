"""Worker side of distributed rendering: *tile producers* and the drawing of one tile.

A **tile producer** holds *parts* of a scene resident on one worker's GPU (a core's bricks:
:class:`geoshade.core.distributed.CoreBricksProducer`; a grid's layer ranges:
:class:`geoshade.grid.distributed.GridPartsProducer`, each beside its View's cluster backend)
and draws any of them for a camera. It is built on the worker
from a picklable **spec** (``spec.make(ctx) -> TileProducer``), so only the spec, once, and
then cameras cross the network. The protocol:

``add(parts, spec) -> {part: info}``
    make the parts resident (build and upload; ``info`` has ``count`` and ``gpu_bytes``);
``remove(parts)``
    free them; ``held()`` the parts resident now;
``corners(part, model) -> (8, 3) or None``
    world corners of the part's box under ``model`` (its screen footprint is their
    projection; None: the part draws nothing);
``draw(part, camera, model, count, size, piece) -> dict``
    draw the part (or one *piece* of it) into the bound, cleared framebuffer of ``size``
    with the depth test on (``GL_LESS``), exactly as the single-process View draws it; with
    ``count`` return the GPU counts;
``pieces(part) -> list[int]`` (optional)
    the pieces a part is drawn in, each with its own rank ``piece * n_parts + rank``: a part
    whose faces one process draws in several passes interleaved with the other parts' (a
    grid's plain and highlighted faces) is drawn piece by piece so the tie rule still
    reproduces that order; without it a part is one piece (0);
``gpu_bytes``, ``release()``.

:func:`render_tile` draws a worker's parts one at a time, each into its own cleared footprint,
reads colour and depth of that footprint back, and merges them into the worker's tile by the
tie rule of :mod:`geoshade.compute.composite` with the part's rank: the tile is what the
single-process depth test would leave of these parts, with the winning part's rank per pixel,
so the client's composite of all tiles is exactly the single-process picture.
"""

from __future__ import annotations

import time
from typing import Protocol

import numpy as np

from geoshade.compute.composite import Tile, footprint, union


class TileProducer(Protocol):
    """What a worker holds of a distributed scene (see the module's description)."""

    def add(self, parts, spec) -> dict: ...

    def remove(self, parts) -> None: ...

    def held(self) -> list[int]: ...

    def corners(self, part: int, model) -> np.ndarray | None: ...

    def draw(self, part: int, camera, model, count: bool = False, size=None,
             piece: int = 0) -> dict: ...

    @property
    def gpu_bytes(self) -> int: ...

    def release(self) -> None: ...


def box_corners(lo, hi, model) -> np.ndarray:
    """(8, 3) world corners of the box ``lo..hi`` (model space) under ``model`` (4, 4).

    >>> box_corners([0, 0, 0], [1, 2, 3], np.eye(4))[-1].tolist()
    [1.0, 2.0, 3.0]
    """
    b = np.array([lo, hi], float)
    c = np.array([[b[dx, 0], b[dy, 1], b[dz, 2]]
                  for dx in (0, 1) for dy in (0, 1) for dz in (0, 1)])
    return (np.c_[c, np.ones(8)] @ np.asarray(model, float).T)[:, :3]


def _gl_rect(rect, height: int) -> tuple[int, int, int, int]:
    """A top-left-origin ``(x0, y0, w, h)`` as OpenGL's bottom-left viewport."""
    x0, y0, w, h = rect
    return (x0, height - (y0 + h), w, h)


def read_rect(fbo, rect, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Colour ``(h, w, 4) uint8`` and depth ``(h, w) float32`` of ``rect`` (top-left origin,
    row 0 at the top) from ``fbo``."""
    _, _, w, h = rect
    vp = _gl_rect(rect, height)
    col = np.frombuffer(fbo.read(viewport=vp, components=4, dtype="f1", alignment=1),
                        np.uint8).reshape(h, w, 4)[::-1]
    dep = np.frombuffer(fbo.read(viewport=vp, components=1, attachment=-1, dtype="f4",
                                 alignment=1),
                        np.float32).reshape(h, w)[::-1]
    return col, dep


def render_tile(producer: TileProducer, target, camera, model, ranks: dict, n_parts: int,
                count: bool = False, n_pieces: int = 1) -> tuple[Tile | None, dict]:
    """Draw ``producer``'s parts ``ranks`` (part -> rank) for ``camera`` and ``model`` (the
    scene's index space to world matrix) into one tile.

    Each part (each of its pieces, when the producer has ``pieces``) is drawn alone into its
    cleared footprint of ``target`` (an :class:`~geoshade.render.target.Offscreen` of the
    picture's size), read back and merged by the tie rule with its rank (a piece's:
    ``piece * n_parts + rank``, ranks below ``n_parts * n_pieces``); parts off screen are
    skipped.

    Returns
    -------
    tile : Tile or None
        The footprint of all parts (None when all are off screen).
    info : dict
        ``draw_ms read_ms merge_ms parts_drawn part_pixels`` (the parts' footprints summed:
        the pixels drawn and read back) and, with ``count``, the summed GPU counts.
    """
    w, h = target.size
    pmv = camera.projection_matrix() @ camera.view_matrix()
    found = {}
    for p in ranks:   # a part with nothing to draw has no corners
        c = producer.corners(int(p), model)
        found[int(p)] = None if c is None else footprint(c, pmv, (w, h))
    rects = {p: r for p, r in found.items() if r is not None}   # off screen: not drawn
    live = sorted(rects, key=lambda p: ranks[p])
    info: dict = {"draw_ms": 0.0, "read_ms": 0.0, "merge_ms": 0.0, "parts_drawn": len(live),
                  "part_pixels": int(sum(r[2] * r[3] for r in rects.values()))}
    counts: dict = {}
    whole = union(rects[p] for p in live)
    if whole is None:
        return None, info
    tile = Tile.empty(whole, n_parts * max(1, int(n_pieces)))
    fbo = target.fbo
    pieces = getattr(producer, "pieces", None)
    for p in live:
        r = rects[p]
        for q in (pieces(p) if pieces is not None else (0,)):
            t0 = time.perf_counter()
            fbo.use()
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0, viewport=_gl_rect(r, h))
            res = producer.draw(p, camera, model, count=count, size=(w, h), piece=int(q))
            target.ctx.finish()
            t1 = time.perf_counter()
            col, dep = read_rect(fbo, r, h)
            t2 = time.perf_counter()
            tile.merge(col, dep, int(q) * n_parts + ranks[p], r)
            info["draw_ms"] += (t1 - t0) * 1000
            info["read_ms"] += (t2 - t1) * 1000
            info["merge_ms"] += (time.perf_counter() - t2) * 1000
            for k, v in (res or {}).items():
                counts[k] = counts.get(k, 0) + int(v or 0)
    if count:
        info["counts"] = counts
    return tile, info


__all__ = ["TileProducer", "box_corners", "read_rect", "render_tile"]
