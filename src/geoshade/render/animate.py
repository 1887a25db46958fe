"""Time-lapse pictures: a View drawn at every report step into an MP4 or GIF, with one fixed
camera and one colour scale, and optionally the case's summary curves as a strip under each
frame, its cursor at the frame's date (issue 33: "one time cursor").

:func:`animate_steps` draws any View that has a ``step`` option (the grid's; the isosurface has
its own loop in :mod:`geoshade.iso.tasks` that prepares the next step ahead and takes the same
``strip``); :func:`summary_strip` makes the strip from the case's SMSPEC/UNSMRY.

>>> STRIP_HEIGHT
200
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.summary import read_summary
from geoshade.models.steps import dated_steps
from geoshade.render.video import VideoWriter
from geoshade.styles.summary_plot import SummaryPlot

#: pixels of the summary strip under an animation's frames
STRIP_HEIGHT = 200

#: ``strip(step) -> (h, w, 4) uint8``: what is drawn under the frame of a step
Strip = Callable[[int], np.ndarray]


def summary_strip(case, vectors: Sequence[str], width: int, dates: Sequence,
                  reports: Sequence[int] = (), height: int = STRIP_HEIGHT) -> Strip:
    """The summary vectors ``vectors`` (names or wildcards) of the case of file ``case`` as a
    strip ``width`` pixels wide, its cursor at the date of the step drawn (``dates``: the
    report steps' dates, ``reports`` their report numbers)."""
    if not vectors:
        raise InputError("summary: name the vectors to draw under the frames (--summary FOPR)")
    if not dates or not all(dates):
        raise InputError("summary: the steps have no dates; a summary strip follows dates")
    table = read_summary(case, list(vectors))
    plot = SummaryPlot(table, list(vectors), size=(int(width), int(height)),
                       report_dates=list(dates), reports=list(reports) or None)

    def strip(step: int) -> np.ndarray:
        return plot.draw(dates[step])

    return strip


def view_strip(view, height: int = STRIP_HEIGHT) -> Strip | None:
    """The strip of ``view``'s ``summary`` option, as wide as its picture (None: no vector
    chosen): what ``render`` draws under the picture."""
    vectors = getattr(view.options, "summary", None)
    if not vectors:
        return None
    meta = getattr(view.model, "meta", None) or {}
    source = meta.get("source") or getattr(view.model, "source", None)
    if not source:
        raise InputError(f"summary: {getattr(view.model, 'name', None) or 'the model'} was not "
                         "read from a case's files; it has no summary")
    dates, reports = dated_steps(view.model)
    return summary_strip(source, list(vectors), view.size[0], dates, reports or (), height)


def with_strip(img: np.ndarray, strip: Strip | None, step: int) -> np.ndarray:
    """The frame ``img`` with ``strip(step)`` under it (the frame as it is without one)."""
    if strip is None:
        return img
    s = strip(step)
    if s.shape[1] != img.shape[1]:
        raise InputError(f"summary strip: {s.shape[1]} pixels wide for a {img.shape[1]}-pixel "
                         "frame")
    return np.concatenate([img, s], axis=0)


def animate_steps(view, output, steps: Sequence[int], fps: float = 4.0,
                  progress: Callable[[int, int], object] | None = None,
                  strip: Strip | None = None) -> dict:
    """Draw ``view`` at each of ``steps`` (``update(step=k)``) into ``output`` (``.mp4`` or
    ``.gif``, written atomically), with the camera of its first frame; ``strip`` under each.

    Returns
    -------
    dict
        ``output frames width height fps frame_ms steps titles seconds``.
    """
    if not steps:
        raise InputError("steps: no step to animate")
    t0 = time.perf_counter()
    writer = VideoWriter(output, fps=fps)
    frame_ms, titles = [], []
    try:
        view.update(step=steps[0])
        cam = view.camera()
        for i, k in enumerate(steps):
            if i:
                view.update(step=k)
            img, st = view.draw(cam, frames=1, warn=False)
            img = with_strip(img, strip, k)
            writer.append(img)
            frame_ms.append(st["frame_ms"])
            titles.append([t["text"] for t in st.get("annotations", {}).get("title", [])])
            if progress is not None:
                progress(i + 1, len(steps))
        writer.close()
    except BaseException:
        writer.abort()
        raise
    return {"output": str(Path(output)), "frames": len(steps), "width": int(img.shape[1]),
            "height": int(img.shape[0]), "fps": float(fps),
            "frame_ms": float(np.median(frame_ms)), "steps": list(steps), "titles": titles,
            "strip_height": 0 if strip is None else STRIP_HEIGHT,
            "seconds": round(time.perf_counter() - t0, 3)}


__all__ = ["STRIP_HEIGHT", "Strip", "animate_steps", "summary_strip", "view_strip", "with_strip"]
