"""Client side of distributed rendering: parts on workers, frames composited by depth.

:class:`DistributedRenderer` owns one :class:`~geoshade.render.distributed.worker.RenderActor`
per worker of a ``dask.distributed`` cluster. :meth:`~DistributedRenderer.load` assigns the
parts of a scene to the workers (:func:`geoshade.compute.composite.assign`: runs of a Morton
curve over the parts' grid cells, balanced by weight, e.g. voxels; the same parts on the same
workers every time) and has each worker make its parts resident from a picklable spec (sent
once). :meth:`~DistributedRenderer.frame` then sends each worker the camera and its parts'
ranks (a few hundred bytes). How the tiles (colour + depth + rank of each worker's screen
footprint) become one picture is :attr:`DistributedRenderer.compositing`:

- ``"workers"`` (the default, *direct-send* as IceT does it): the tiles stay on the workers, the
  picture is cut into one band of rows per worker, each worker fetches its band's pieces from its
  peers worker to worker and composites them, and the client receives the bands: one picture
  (colour + depth) per frame whatever the number of workers;
- ``"client"`` (the first implementation, kept as the reference and for a cluster whose workers
  cannot reach each other): every tile travels to the client, which composites alone
  (:func:`geoshade.compute.composite.composite`); the bytes into the client grow with the
  workers.

Both give the same picture pixel for pixel (the tie rule is per pixel).

A worker that fails during a frame (its process died, it was retired, it did not answer within
``timeout`` seconds) is reported (a :class:`WorkerLostWarning` naming it, in :attr:`events`
until read) and its parts are given to the surviving workers, made resident there and drawn in
the same frame: a picture never silently misses a part. Workers that join later are not used
until the next :meth:`~DistributedRenderer.load` (the assignment stays stable).
"""

from __future__ import annotations

import pickle
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.compute.composite import (
    assign,
    bands,
    composite,
    front_to_back,
    reassign,
    spatial_order,
)
from geoshade.errors import GeoshadeError
from geoshade.render.distributed.worker import RenderActor
from geoshade.scheduler import SchedulerSession, client_for, live_workers

#: seconds a worker may take for one call before it is taken as lost
DEFAULT_TIMEOUT_S = 300.0


class WorkerLostWarning(UserWarning):
    """A worker failed during distributed rendering; its parts were redone elsewhere."""


class ClusterLostError(GeoshadeError, RuntimeError):
    """No worker of the cluster is left to draw on."""


def _is_loss(err: BaseException) -> bool:
    """True when ``err`` from an actor call means its worker is gone (not a bug or bad input
    on the worker, which are raised as they are)."""
    if isinstance(err, GeoshadeError):
        return False
    if isinstance(err, OSError | TimeoutError):
        return True   # includes distributed's CommClosedError and "Unable to contact Actor"
    name = type(err).__name__
    return name in ("CommClosedError", "CancelledError", "KilledWorker") or (
        isinstance(err, RuntimeError) and "lost" in str(err).lower())


def _first_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return f"{type(err).__name__}: {text[0]}" if text else type(err).__name__


@dataclass
class Scene:
    """The parts of one scene: how they are made (``make_spec``), weighed and ordered."""

    key: str
    make_spec: Callable[[list[int]], Any]
    weights: np.ndarray
    centres: np.ndarray          # (n, 3) part centres in the model's index space
    model: np.ndarray            # (4, 4) index space -> world
    order: str = "front_to_back"  # the single process's drawing order of the parts
    counts: dict = field(default_factory=dict)   # part -> info from the worker
    pieces: int = 1              # the most pieces a part is drawn in (producer.pieces)


class DistributedRenderer:
    """Render the parts of a scene on the workers of a cluster (see the module's description).

    Parameters
    ----------
    scheduler : SchedulerSession, distributed.Client, Scheduler or str
        A session (its client, kept open: the session's owner closes it), a client (kept
        open), an address ``tcp://HOST:PORT`` or ``local:N``
        (:func:`geoshade.scheduler.client_for`; closed by :meth:`close`).
    timeout : float
        Seconds a worker may take for one call (building its parts or drawing a tile) before
        it is taken as lost.

    Examples
    --------
    >>> r = DistributedRenderer("local:2")                               # doctest: +SKIP
    >>> r.load("k", make_spec, weights, cells, centres, model)           # doctest: +SKIP
    >>> color, depth, stats = r.frame(camera, (640, 480))                # doctest: +SKIP
    """

    #: where tiles are composited: "workers" (direct-send) or "client" (see the module text)
    COMPOSITING = ("workers", "client")

    def __init__(self, scheduler, timeout: float = DEFAULT_TIMEOUT_S,
                 compositing: str = "workers"):
        if compositing not in self.COMPOSITING:
            raise GeoshadeError(f"compositing {compositing!r}: expected one of "
                                f"{', '.join(self.COMPOSITING)}")
        self.compositing = compositing
        self._frames = 0
        if isinstance(scheduler, SchedulerSession):   # its owner (a View) closes the cluster
            self.client, self.owned = scheduler.client(), False
        else:
            self.client, self.owned = client_for(scheduler)
        self.timeout = float(timeout)
        self.actors: dict[str, Any] = {}
        #: the futures of the actors: they keep each actor on its worker (a worker of this
        #: process hands back the actor itself, which holds no reference to its key)
        self._actor_futures: dict[str, Any] = {}
        self.workers: list[str] = []
        self.assignment: list[list[int]] = []
        self.scene: Scene | None = None
        self.events: list[str] = []
        self.lost: list[str] = []
        self.gpu_bytes_by_worker: dict[str, int] = {}
        self.renderers: dict[str, str] = {}
        self._pending_loss: list[tuple[str, str]] = []
        self.load_ms = 0.0
        self._start()

    # --- workers -------------------------------------------------------------------------------
    def _start(self) -> None:

        workers = live_workers(self.client)
        if not workers:
            raise ClusterLostError("distributed: the cluster has no worker")
        with self.client.as_current():  # an actor binds the current client
            futs = {w: self.client.submit(RenderActor, actor=True, workers=[w],
                                          allow_other_workers=False, pure=False)
                    for w in workers}
            for w, f in futs.items():
                try:
                    self.actors[w] = f.result(timeout=self.timeout)
                    self._actor_futures[w] = f
                except Exception as err:
                    if not _is_loss(err):
                        raise
                    self._pending_loss.append((w, _first_line(err)))
        self.workers = workers
        calls = {w: self._call(w, "hello") for w in self.actors}
        for w, res in self._collect(calls)[0].items():
            self.renderers[w] = res["renderer"]
        self.workers = [w for w in workers if w in self.renderers]
        self._flush_lost()

    def _call(self, worker: str, method: str, *args):
        """Start ``method(*args)`` on ``worker``'s actor: its future, or the exception when
        the call cannot even start (an actor whose worker is known to be gone)."""
        try:
            return getattr(self.actors[worker], method)(*args)
        except Exception as err:
            if not _is_loss(err):
                raise
            return err

    def _collect(self, calls: dict[str, Any]) -> tuple[dict[str, Any], list[str]]:
        """Wait for actor calls ``worker -> ActorFuture``; ``(results, lost workers)``."""
        deadline = time.monotonic() + self.timeout
        out, lost = {}, []
        for w, fut in calls.items():
            try:
                if isinstance(fut, BaseException):
                    raise fut
                out[w] = fut.result(timeout=max(0.01, deadline - time.monotonic()))
            except Exception as err:
                if not _is_loss(err):
                    raise
                lost.append(w)
                self._lose(w, err)
        return out, lost

    def _lose(self, worker: str, err: BaseException) -> None:
        self.lost.append(worker)
        self.actors.pop(worker, None)
        self._actor_futures.pop(worker, None)
        self.gpu_bytes_by_worker.pop(worker, None)
        self._pending_loss.append((worker, _first_line(err)))

    def _flush_lost(self) -> None:
        """Drop lost workers from the list (before any assignment exists)."""
        lost = [w for w, _ in self._pending_loss]
        self.workers = [w for w in self.workers if w not in lost]
        for w, why in self._pending_loss:
            self.events.append(f"distributed: worker {w} lost at start-up ({why})")
        self._pending_loss = []
        if not self.workers:
            raise ClusterLostError("distributed: every worker was lost")

    # --- scenes --------------------------------------------------------------------------------
    def load(self, key: str, make_spec: Callable[[list[int]], Any], weights, cells, centres,
             model, order: str = "front_to_back", pieces: int = 1) -> dict:
        """Assign the scene's parts to the workers and make them resident there.

        Parameters
        ----------
        key : str
            Names the scene on the workers (a new key replaces the old scene).
        make_spec : callable(parts) -> spec
            The picklable spec a worker builds ``parts`` from (``spec.make(ctx)`` is a
            :class:`~geoshade.render.distributed.producer.TileProducer`).
        weights : (n,) numbers
            Cost of each part (voxels): the assignment balances their sums.
        cells : (n, 3) ints
            Each part's cell in a grid of parts (the assignment follows a Morton curve of them).
        centres : (n, 3) floats
            Part centres in the model's index space (drawing order, hence the tie rule).
        model : (4, 4)
            Index space -> world.
        order : {'front_to_back', 'index'}
            The order one process draws the parts in, which the tie rule reproduces: nearest
            centre first (a core's bricks) or by part index (parts that one process draws in
            one buffer, in index order: a grid's chunked face sets).
        pieces : int
            The most pieces a part is drawn in (see
            :mod:`geoshade.render.distributed.producer`): ranks go up to ``n * pieces``.

        Returns
        -------
        dict
            part -> the worker's info (``count``, ``gpu_bytes``).
        """
        old = self.scene
        w = np.asarray(weights, float)
        if order not in ("front_to_back", "index"):
            raise ValueError(f"order: expected front_to_back or index, got {order!r}")
        self.scene = Scene(key, make_spec, w, np.asarray(centres, float),
                           np.asarray(model, float), order, pieces=max(1, int(pieces)))
        if old is None or len(old.weights) != len(w) or not np.array_equal(old.weights, w):
            self.assignment = assign(w, len(self.workers), spatial_order(cells))
        t0 = time.perf_counter()
        alive = {k: parts for k, parts in enumerate(self.assignment)
                 if self.workers[k] in self.actors}
        self._ensure(alive)
        self._heal("before the scene was loaded")
        self.load_ms = (time.perf_counter() - t0) * 1000
        if old is not None and old.key != key:
            self._call_all("release", old.key)
        return dict(self.scene.counts)

    def _ensure(self, which: dict[int, list[int]]) -> None:
        """Make the assignment's parts resident on workers ``which`` (index -> parts), moving
        the parts of workers lost meanwhile until every part is resident somewhere."""
        scene = self.scene
        assert scene is not None
        while which:
            calls = {}
            for k, parts in which.items():
                wk = self.workers[k]
                if wk in self.actors:
                    calls[wk] = self._call(wk, "ensure", scene.key,
                                           scene.make_spec(list(parts)), list(parts))
            res, lost = self._collect(calls)
            for wk, r in res.items():
                self.gpu_bytes_by_worker[wk] = int(r["gpu_bytes"])
                scene.counts.update({int(p): v for p, v in r["parts"].items()})
            which = self._moved(lost, "while making its parts resident") if lost else {}

    def _moved(self, lost: list[str], when: str) -> dict[int, list[int]]:
        """Re-assign the parts of ``lost`` workers; index -> full part list of the workers
        that received some."""
        idx = [self.workers.index(w) for w in lost]
        before = [list(a) for a in self.assignment]
        assert self.scene is not None
        alive = [w for w in self.workers if w in self.actors]
        if not alive:
            why = "; ".join(f"{w} ({e})" for w, e in self._pending_loss)
            self._pending_loss = []
            raise ClusterLostError(f"distributed: every worker was lost ({why})")
        self.assignment = reassign(self.assignment, idx, self.scene.weights)
        got = {k: self.assignment[k] for k in range(len(self.workers))
               if len(self.assignment[k]) > len(before[k])}
        for w, why in self._pending_loss:
            k = self.workers.index(w)
            to = sorted({self.workers[j] for j in got
                         if set(before[k]) & set(self.assignment[j])})
            self.events.append(f"distributed: worker {w} lost {when} ({why}); its "
                               f"{len(before[k])} parts were re-assigned to {', '.join(to)} "
                               "and redone")
        self._pending_loss = []
        return got

    def _heal(self, when: str) -> None:
        """Give the parts of workers found gone outside a frame (e.g. while releasing a scene)
        to the others before they are needed."""
        gone = [w for k, w in enumerate(self.workers)
                if k < len(self.assignment) and self.assignment[k] and w not in self.actors]
        if gone and self.scene is not None:
            self._ensure(self._moved(gone, when))

    def _call_all(self, method: str, *args) -> dict:
        calls = {w: self._call(w, method, *args) for w in self.actors}
        return self._collect(calls)[0]

    # --- frames --------------------------------------------------------------------------------
    def ranks(self, camera) -> np.ndarray:
        """Each part's rank in the single-process drawing order for ``camera``."""
        assert self.scene is not None
        if self.scene.order == "index":
            return np.arange(len(self.scene.weights))
        return front_to_back(self.scene.centres, self.scene.model, camera.eye)

    def frame(self, camera, size, count: bool = False, background=(0, 0, 0, 0), model=None,
              compositing: str | None = None) -> tuple[np.ndarray, np.ndarray, dict]:
        """One picture: ``(color (h, w, 4) uint8, depth (h, w) float32, stats)``.

        ``model``: a new index space to world matrix for the scene (an exaggeration change;
        it travels with the camera), default the one given to :meth:`load`.

        ``stats``: ``bytes_moved`` (tiles back + requests out), ``tile_bytes``,
        ``request_bytes``, ``slowest_worker`` and ``slowest_worker_ms`` (its own time for the
        tile), ``round_trip_ms`` (the slowest call as the client saw it), ``composite_ms``,
        ``bricks_per_worker`` (parts drawn per worker, by address), ``lost`` (workers lost in
        this frame), ``redone`` (parts drawn again elsewhere), ``counts`` (with ``count``),
        ``compositing``, ``client_bytes`` (what reached the client: the tiles, or with
        direct-send the bands) and ``peer_bytes`` (pieces sent worker to worker).
        ``compositing`` overrides :attr:`compositing` for this frame.
        """
        on_workers = (compositing or self.compositing) == "workers"
        self._frames += 1
        token = self._frames if on_workers else None
        scene = self.scene
        assert scene is not None, "load() a scene first"
        size = (int(size[0]), int(size[1]))
        if model is not None:
            scene.model = np.asarray(model, float)
        ranks = self.ranks(camera)
        n = len(ranks)
        t0 = time.perf_counter()
        self._heal("between frames")
        todo = {k: list(parts) for k, parts in enumerate(self.assignment) if parts}
        results: dict[str, list[dict]] = {}
        lost_now: list[str] = []
        request_bytes = redone = 0
        first = True
        while todo:
            calls = {}
            for k, parts in todo.items():
                wk = self.workers[k]
                req = {int(p): int(ranks[p]) for p in parts}
                args = (scene.key, camera, scene.model, size, req, n, count, scene.pieces,
                        token)
                request_bytes += len(pickle.dumps(args))
                calls[wk] = self._call(wk, "render", *args)
                if not first:
                    redone += len(parts)
            res, lost = self._collect(calls)
            for wk, r in res.items():
                results.setdefault(wk, []).append(r)
            first = False
            todo = {}
            if lost:
                lost_now += lost
                before = [list(a) for a in self.assignment]
                self._ensure(self._moved(lost, "during a frame"))
                # draw only what each survivor received (its own parts are in its tile)
                todo = {k: [p for p in self.assignment[k] if p not in before[k]]
                        for k, w in enumerate(self.workers) if w in self.actors}
                todo = {k: v for k, v in todo.items() if v}
        round_trip = (time.perf_counter() - t0) * 1000
        tiles = [r["tile"] for rs in results.values() for r in rs if r["tile"] is not None]
        t1 = time.perf_counter()
        peer_bytes = 0
        if on_workers:
            done = self._composite_on_workers(token, size, background, n * scene.pieces)
            if done is None:   # a worker was lost while compositing: this frame the old way
                return self.frame(camera, size, count, background, None, "client")
            color, depth, peer_bytes, composite_ms = done
            tile_bytes = sum(r.get("kept_bytes", 0) for rs in results.values() for r in rs)
            client_bytes = color.nbytes + depth.nbytes
        else:
            color, depth, _ = composite(tiles, size, background, n_parts=n * scene.pieces)
            composite_ms = (time.perf_counter() - t1) * 1000
            tile_bytes = client_bytes = sum(t.nbytes for t in tiles)
        per_worker_ms = {w: sum(r["ms"] for r in rs) for w, rs in results.items()}
        slowest = max(per_worker_ms, key=lambda w: per_worker_ms[w]) if per_worker_ms else None
        stats: dict = {
            "workers": len([w for w in self.workers if w in self.actors]),
            "compositing": "workers" if on_workers else "client",
            "bytes_moved": int(client_bytes + request_bytes),
            "client_bytes": int(client_bytes), "peer_bytes": int(peer_bytes),
            "tile_bytes": int(tile_bytes), "request_bytes": int(request_bytes),
            "tile_pixels": int(sum(r.get("tile_pixels", 0) for rs in results.values()
                                   for r in rs)) if on_workers else
            int(sum(t.rect[2] * t.rect[3] for t in tiles)),
            "slowest_worker": slowest,
            "slowest_worker_ms": round(per_worker_ms.get(slowest, 0.0), 3) if slowest else 0.0,
            "round_trip_ms": round(round_trip, 3),
            "composite_ms": round(composite_ms, 3),
            "bricks_per_worker": {w: len(self.assignment[k])
                                  for k, w in enumerate(self.workers) if w in self.actors},
            "draw_ms_per_worker": {w: round(sum(r["draw_ms"] for r in rs), 3)
                                   for w, rs in results.items()},
            "read_ms_per_worker": {w: round(sum(r["read_ms"] for r in rs), 3)
                                   for w, rs in results.items()},
            "part_pixels": int(sum(r["part_pixels"] for rs in results.values() for r in rs)),
            "lost": lost_now, "redone": redone,
        }
        if count:
            counts: dict = {}
            for rs in results.values():
                for r in rs:
                    for k, v in r.get("counts", {}).items():
                        counts[k] = counts.get(k, 0) + int(v)
            stats["counts"] = counts
        return color, depth, stats

    def _composite_on_workers(self, token, size, background, n_parts: int):
        """Direct-send: each live worker composites one band of the picture from its peers'
        pieces; ``(color, depth, peer bytes, slowest band ms)``, or None when a worker was lost
        (its loss is recorded; the caller draws the frame again with client compositing)."""
        live = [w for w in self.workers if w in self.actors]
        cut = bands(size, len(live))
        calls = {w: self._call(w, "composite_band", token, band,
                               [self.actors[o] for o in live if o != w], tuple(background),
                               n_parts)
                 for w, band in zip(live, cut, strict=False)}
        res, lost = self._collect(calls)
        if lost:
            self._ensure(self._moved(lost, "while compositing"))
            return None
        w, h = (int(v) for v in size)
        color = np.empty((h, w, 4), np.uint8)
        depth = np.empty((h, w), np.float32)
        for wk, band in zip(live, cut, strict=False):
            x0, y0, bw, bh = band
            color[y0:y0 + bh, x0:x0 + bw] = res[wk]["color"]
            depth[y0:y0 + bh, x0:x0 + bw] = res[wk]["depth"]
        return (color, depth, int(sum(r["peer_bytes"] for r in res.values())),
                max((r["ms"] for r in res.values()), default=0.0))

    # --- read-outs and lifetime ----------------------------------------------------------------
    @property
    def gpu_bytes(self) -> int:
        """GPU bytes the workers hold for the current scene (as they last said)."""
        return int(sum(self.gpu_bytes_by_worker.values()))

    def release_scene(self, key: str | None = None) -> None:
        """Free the workers' GPU objects of scene ``key`` (default: the current scene, which
        is then forgotten: :meth:`load` a new one before the next frame). Idempotent; the
        workers stay ready."""
        scene = self.scene
        key = key if key is not None else (scene.key if scene is not None else None)
        if key is None or not self.actors:
            return
        self._call_all("release", key)
        if scene is not None and scene.key == key:
            self.gpu_bytes_by_worker.clear()
            self.scene = None

    def take_events(self) -> list[str]:
        """The loss reports since the last call (each once)."""
        ev, self.events = self.events, []
        return ev

    def close(self) -> None:
        """Free the workers' GPU objects; close the client if it was made here."""
        if self.actors:
            try:
                self._call_all("release", None)
            except Exception:
                pass
        self.actors.clear()
        self._actor_futures.clear()
        self.gpu_bytes_by_worker.clear()
        self.scene = None
        if self.owned:
            self.client.close()
            self.owned = False


def write_target(target, color: np.ndarray, depth: np.ndarray) -> None:
    """Write a composited picture (row 0 at the top) into ``target``'s colour and depth
    textures, so passes that read the target (ambient occlusion) and its read-back see it."""
    target.color.write(np.ascontiguousarray(color[::-1]).tobytes())
    target.depth.write(np.ascontiguousarray(depth[::-1], dtype=np.float32).tobytes())


def cleared_color(target) -> tuple[int, int, int, int]:
    """The RGBA (uint8) the cleared ``target`` holds (its background, as GL stored it)."""
    data = target.fbo.read(viewport=(0, 0, 1, 1), components=4, dtype="f1", alignment=1)
    r, g, b, a = (int(v) for v in np.frombuffer(data, np.uint8)[:4])
    return r, g, b, a


__all__ = ["DEFAULT_TIMEOUT_S", "ClusterLostError", "DistributedRenderer", "WorkerLostWarning",
           "cleared_color", "write_target"]
