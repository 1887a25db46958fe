"""What a View drawn on a cluster adds to its part's View (``DistributedCoreView``,
``DistributedGridView``): the composited frame, the loss reports, the read-outs and closing the
renderer. A mixin, listed before the part's View: ``class DistributedCoreView(ClusterDrawing,
CoreView)``; the View keeps its :class:`~geoshade.render.distributed.client.DistributedRenderer`
in ``self._renderer``."""

from __future__ import annotations

import time
from typing import Any

from geoshade.render.distributed.client import WorkerLostWarning, cleared_color, write_target


class ClusterDrawing:
    """Mixin of the distributed Views (see the module's description)."""

    #: what the parts are called in the summary line ("bricks", "parts")
    part_word = "parts"
    _renderer: Any
    _frame_stats: dict

    def _composite_frame(self, camera, target, count: bool, model) -> dict:
        """Draw the parts on the workers for ``camera`` and ``model`` (index space to world),
        composite the tiles into ``target`` (colour and depth, so passes over the picture and
        other geometry see it); the GPU counts with ``count``."""
        color, depth, st = self._renderer.frame(camera, target.size, count=count,
                                                background=cleared_color(target), model=model)
        t0 = time.perf_counter()
        write_target(target, color, depth)
        st["write_ms"] = round((time.perf_counter() - t0) * 1000, 3)
        self._frame_stats = st
        return dict(st.pop("counts", {})) if count else {}

    def _notes(self, stats: dict) -> list[tuple[str, type[Warning]]]:
        return [*super()._notes(stats),  # type: ignore[misc]
                *((m, WorkerLostWarning) for m in self._renderer.take_events())]

    def _release_part(self) -> None:
        renderer = getattr(self, "_renderer", None)
        if renderer is not None:
            renderer.close()
        super()._release_part()  # type: ignore[misc]

    def readout(self, stats: dict) -> str:
        d = stats.get("distributed", {})
        return (super().readout(stats)  # type: ignore[misc]
                + f" · {len(d.get('bricks_per_worker', {}))} workers, "
                f"{d.get('bytes_moved', 0) / 1024:.0f} KiB/frame, slowest "
                f"{d.get('slowest_worker_ms', 0):.0f} ms")

    def summary(self, stats: dict) -> str:
        d = stats.get("distributed", {})
        per = d.get("bricks_per_worker", {})
        return (super().summary(stats)  # type: ignore[misc]
                + f"; {len(per)} workers, {self.part_word} "
                f"{'/'.join(str(v) for v in per.values())}, "
                f"{d.get('bytes_moved', 0) / 2**20:.2f} MiB moved per frame")


__all__ = ["ClusterDrawing"]
