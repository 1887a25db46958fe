"""A picture at once: a View with ``progressive=True`` shows a coarse preview first.

Opening a 50 G-voxel core or a 1e9-cell grid store takes minutes to the full picture. A
progressive View (the core's and the grid's) opens a small *preview View* of the same part
instead — the core from an overview level of its store, the grid from its coarse level of
detail — with the same options (selection, colours fixed to the full picture's range,
annotations) and draws it through the full View's camera, so the framing is the full picture's.
The picture carries a visible note (:data:`PREVIEW_NOTE`) and its stats say ``"coarse": true``
and the level; it is never presented as final.

:meth:`Progressive.refine_job` builds the full picture (CPU half on any thread, GL half after:
a viewer keeps showing the preview meanwhile, with a progress line); once applied the preview
is released and :meth:`~geoshade.render.view.View.draw` draws the full picture. A change of
options while loading makes a new preview at once and a new refine job with the same key,
which supersedes (cancels) the old one. :meth:`Progressive.pictures` is the script's form:
the preview, then the full picture.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from geoshade.render.view import Job, Progress

#: the visible one-line note of a preview picture
PREVIEW_NOTE = "coarse preview, {what} (1/{ratio:g} resolution) — full picture loading"
#: the key of the refine job (with the View's id: a newer one supersedes an older one)
REFINE_KEY = "refine"
#: what a progress line says while the full picture is built
REFINE_LABEL = "coarse preview — full picture"


@dataclass
class Preview:
    """The coarse View shown until the full picture is ready.

    view:  the part's View of the coarse model (same GL context)
    level: the overview level (core) or the merge factor's level (grid: 1)
    ratio: the linear resolution ratio (2**level for the core, ``f`` for the grid)
    note:  the visible one-line note
    cells: maps a preview pick's index (a coarse cell or voxel) to the first and last
           full-resolution indices it merges (None: the pick is returned as it is)
    """

    view: Any
    level: int
    ratio: float
    note: str
    cells: Callable[[tuple], tuple[tuple, tuple]] | None = None

    def stats(self) -> dict:
        """What a preview frame's stats add."""
        return {"coarse": True, "level": int(self.level), "coarse_ratio": float(self.ratio),
                "coarse_note": self.note}

    def mark(self, pick):
        """A pick on the preview, said as what it is: the full-resolution cells (or voxels)
        the picked coarse one merges (``I=5–8 J=1–4 K=3``; the index: the first of them) and
        a read-out line that its value is the merged one, never a cell's own.

        >>> from geoshade.render.pick import Pick
        >>> p = Preview(None, 1, 4, "", lambda i: ((4, 0, 8), (7, 3, 9)))
        >>> m = p.mark(Pick("grid", (1, 0, 2), (0.0, 0.0, 0.0), 0.0, 0.2, "PORO"))
        >>> m.index, m.label, m.extra[-1][0]
        ((4, 0, 8), 'I=5–8 J=1–4 K=9–10', 'preview')
        """
        if self.cells is None:
            return pick
        lo, hi = (tuple(int(v) for v in x)
                  for x in self.cells(tuple(int(v) for v in pick.index[:3])))
        grid = pick.kind == "grid"
        names, base = ("IJK", 1) if grid else ("xyz", 0)   # the grid's read-out is 1-based
        span = " ".join(f"{a}={a0 + base}" if a1 <= a0 else f"{a}={a0 + base}–{a1 + base}"
                        for a, a0, a1 in zip(names, lo, hi, strict=True))
        what = "cell" if grid else "voxel"
        r = f"{self.ratio:g}"
        line = f"the merged value of {r}×{r}×{r} {what}s (exact in the full picture)"
        return replace(pick, index=tuple(lo) + tuple(pick.index[3:]),
                       label=span if grid else f"voxels {span}",
                       ijk_label=span if grid else pick.ijk_label,
                       extra=(*pick.extra, ("preview", line)))


class Progressive:
    """What a progressive View adds to :class:`~geoshade.render.view.View` (mixed in before
    it). A part sets :attr:`preview` in its set-up and implements :meth:`_open_preview`
    (a new :class:`Preview` for the current options, or None) and :meth:`refine_job`.
    """

    #: the preview shown now (None: the full picture is drawn)
    preview: Preview | None = None
    #: set on a preview View: the note its title carries
    preview_note: str = ""

    @property
    def loading(self) -> bool:
        """True while the full picture is still to be built (a preview is drawn)."""
        return self.preview is not None

    def draw(self, camera=None, **kw) -> tuple[np.ndarray, dict]:
        """:meth:`View.draw`; while :attr:`loading`, the preview through this View's camera
        (the full picture's framing), its stats with ``coarse``, ``level`` and the note."""
        p = self.preview
        if p is None:
            return super().draw(camera, **kw)  # type: ignore[misc]
        cam = self._camera_for(camera)  # type: ignore[attr-defined]
        p.view.options = p.view.options.replace(p.view.model, size=self.size)  # type: ignore
        img, stats = p.view.draw(cam, **kw)
        stats.update(p.stats())
        return img, stats

    def pick(self, x: float, y: float, camera=None):
        """:meth:`View.pick`; while :attr:`loading`, what the preview shows there: the
        full-resolution cells or voxels its coarse one merges (:meth:`Preview.mark`)."""
        if self.preview is not None:
            hit = self.preview.view.pick(x, y, camera)
            return None if hit is None else self.preview.mark(hit)
        return super().pick(x, y, camera)  # type: ignore[misc]

    def refine(self, progress: Progress | None = None) -> None:
        """Build the full picture now, on this thread (scripts, the CLI)."""
        if self.preview is not None:
            self.refine_job().run(progress)

    def pictures(self, camera=None, **kw) -> Iterator[tuple[np.ndarray, dict]]:
        """The preview's picture (while :attr:`loading`), then the full one."""
        if self.preview is not None:
            yield self.draw(camera, **kw)
            self.refine(getattr(self, "progress", None))
        yield self.draw(camera, **kw)

    def refine_job(self) -> Job:
        """A :class:`Job` that builds the full picture and drops the preview."""
        raise NotImplementedError

    def refine_key(self) -> str:
        """The refine jobs' key: one per View (a viewer shows several)."""
        return f"{REFINE_KEY} {id(self)}"

    def _drop_preview(self) -> None:
        if self.preview is not None:
            self.preview.view.release()
            self.preview = None

    def _preview_subtitle(self, subtitle: str) -> str:
        """``subtitle`` under the preview note (a preview View's title carries it)."""
        if not self.preview_note:
            return subtitle
        return self.preview_note + ("\n" + subtitle if subtitle else "")


def preview_note(what: str, ratio: float) -> str:
    """The note of a preview: ``coarse preview, level 2 (1/4 resolution) — full picture
    loading``.

    >>> preview_note("level 3", 8)
    'coarse preview, level 3 (1/8 resolution) — full picture loading'
    """
    return PREVIEW_NOTE.format(what=what, ratio=ratio)


__all__ = ["PREVIEW_NOTE", "REFINE_KEY", "REFINE_LABEL", "Preview", "Progressive",
           "preview_note"]
