"""The render actor: one per ``dask.distributed`` worker, holding its tile producers.

A :class:`RenderActor` is created on each worker as a dask *actor*: its methods run on the
worker's one actor thread, which holds its own headless OpenGL context (:func:`thread_context`:
one per thread, made on first use in that thread and made current around every call that draws).
A worker process has one such thread; the workers of a ``local:N`` cluster that runs as threads
of the client's process (no ``cryptography``) each have theirs, never the client's context,
which is current on another thread. Producers are kept between frames under a key
(the client's scene: store, box, selection, palette, method), so a frame sends only a camera.

Direct-send compositing: a frame drawn with ``keep=`` a frame token keeps the tiles on the
worker; then every worker composites its band of the picture (:meth:`RenderActor.composite_band`,
an ``async`` method on the worker's event loop, so no actor thread waits on a peer) from the
pieces its peers crop for it (:meth:`RenderActor.piece`, worker to worker), and only the bands
reach the client.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import threading
import time
from typing import Any

from geoshade.compute.composite import Tile, composite_band, crop
from geoshade.render.distributed.producer import render_tile

_THREAD = threading.local()


def thread_context():
    """This thread's headless OpenGL context (made here on first use): a context is current on
    one thread, so every thread that draws needs its own (the threads of one process included).

    >>> ctx = thread_context()  # doctest: +SKIP
    >>> ctx is thread_context()  # doctest: +SKIP
    True
    """
    ctx = getattr(_THREAD, "ctx", None)
    if ctx is None:
        from geoshade.render.context import create_context

        ctx = _THREAD.ctx = create_context()
    return ctx


class RenderActor:
    """Worker-resident GPU state of distributed scenes (see the module's description)."""

    def __init__(self) -> None:
        self.ctx: Any = None
        self.target: Any = None
        self.producers: dict[str, Any] = {}
        self.kept: tuple[Any, list[Tile]] = (None, [])   # (frame token, its tiles here)

    @contextlib.contextmanager
    def _current(self):
        """The actor's context, current on the thread that runs this call."""
        if self.ctx is None:
            self.ctx = thread_context()
        with self.ctx:
            yield self.ctx

    def hello(self) -> dict:
        """The worker's process id and renderer (makes the context)."""
        with self._current() as ctx:
            return {"pid": os.getpid(), "renderer": ctx.info.get("GL_RENDERER")}

    def ensure(self, key: str, spec, parts) -> dict:
        """Make ``parts`` of scene ``key`` resident (built from ``spec``); drop the scene's
        other parts. Returns ``{"parts": {part: info}, "ms": ..., "gpu_bytes": ...}``."""
        t0 = time.perf_counter()
        with self._current() as ctx:
            prod = self.producers.get(key)
            if prod is None:
                prod = self.producers[key] = spec.make(ctx)
            keep = {int(p) for p in parts}
            prod.remove([p for p in prod.held() if p not in keep])
            info = prod.add(sorted(keep), spec)
        return {"parts": info, "ms": (time.perf_counter() - t0) * 1000,
                "gpu_bytes": int(prod.gpu_bytes), "pid": os.getpid()}

    def render(self, key: str, camera, model, size, ranks: dict, n_parts: int,
               count: bool = False, n_pieces: int = 1, keep=None) -> dict:
        """Draw scene ``key``'s parts ``ranks`` (part -> rank) for ``camera`` and ``model``
        (index space to world) at ``size``.

        Returns ``{"tile": Tile or None, "ms": total, "draw_ms" ..., "pid"}``; with ``keep`` (a
        frame token) the tile stays here for :meth:`composite_band` and ``"tile"`` is None
        (``"kept_bytes"`` says its size)."""
        from geoshade.render.target import Offscreen

        t0 = time.perf_counter()
        prod = self.producers.get(key)
        if prod is None:
            raise KeyError(f"scene {key} is not resident on this worker")
        size = (int(size[0]), int(size[1]))
        with self._current() as ctx:
            if self.target is None or self.target.size != size:
                if self.target is not None:
                    self.target.release()
                self.target = Offscreen(ctx, size)
            tile, info = render_tile(prod, self.target, camera, model,
                                     {int(p): int(r) for p, r in ranks.items()}, n_parts,
                                     count, n_pieces)
        info.update(tile=tile, ms=(time.perf_counter() - t0) * 1000, pid=os.getpid())
        if keep is not None:
            if self.kept[0] != keep:
                self.kept = (keep, [])
            if tile is not None:
                self.kept[1].append(tile)
            info.update(tile=None, kept_bytes=0 if tile is None else tile.nbytes,
                        tile_pixels=0 if tile is None else tile.rect[2] * tile.rect[3])
        return info

    def piece(self, token, rect) -> list[Tile]:
        """This worker's kept tiles of frame ``token`` cropped to ``rect`` (a peer's band)."""
        if self.kept[0] != token:
            return []
        return [c for c in (crop(t, rect) for t in self.kept[1]) if c is not None]

    async def composite_band(self, token, rect, peers, background, n_parts: int) -> dict:
        """Composite band ``rect`` of frame ``token`` from this worker's tiles and the pieces
        of ``peers`` (their actors), fetched worker to worker. Returns ``{"color", "depth",
        "peer_bytes", "ms"}``: the band's colour (h, w, 4) uint8 and depth (h, w) float32."""
        t0 = time.perf_counter()
        own = self.piece(token, rect)
        got = await asyncio.gather(*(p.piece(token, rect) for p in peers))
        pieces = own + [t for ts in got for t in ts]
        color, depth = await asyncio.get_running_loop().run_in_executor(
            None, composite_band, pieces, rect, background, n_parts)
        return {"color": color, "depth": depth, "ms": (time.perf_counter() - t0) * 1000,
                "peer_bytes": int(sum(t.nbytes for ts in got for t in ts))}

    def release(self, key: str | None = None) -> int:
        """Free scene ``key`` (None: every scene and the target); returns the GPU bytes left."""
        keys = list(self.producers) if key is None else [key]
        if self.ctx is None:
            return 0
        with self._current():
            for k in keys:
                prod = self.producers.pop(k, None)
                if prod is not None:
                    prod.release()
            if key is None and self.target is not None:
                self.target.release()
                self.target = None
        return int(sum(p.gpu_bytes for p in self.producers.values()))


__all__ = ["RenderActor", "thread_context"]
