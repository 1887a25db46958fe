"""What every part adapter offers the front ends (toolkit-free)."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from geoshade.errors import InputError

#: ``progress(done, total)`` as the compute functions take it
Progress = Callable[[int, int], Any]


@dataclass
class Job:
    """Long work split in two: ``compute`` (CPU only, any thread) and ``apply`` (GL thread).

    key:     jobs with the same key supersede each other (only the newest is applied)
    label:   what the progress bar says
    compute: ``compute(progress) -> result``; never touches OpenGL
    apply:   ``apply(result)``; runs on the thread that owns the GL context
    """

    key: str
    label: str
    compute: Callable[[Progress | None], Any]
    apply: Callable[[Any], None]

    def run(self, progress: Progress | None = None) -> None:
        """Both halves on this thread (notebooks, scripts, ``--screenshot``)."""
        self.apply(self.compute(progress))


def run_now(job: Job | None) -> None:
    """Run ``job`` synchronously if there is one."""
    if job is not None:
        job.run()


class Part:
    """A part adapter: the part's View plus what the viewer needs around it.

    Subclasses set ``kind`` / ``title``, make ``self.view`` in ``__init__`` and implement
    :meth:`accepts`, :meth:`readout`, :meth:`settings`, :meth:`apply` and :meth:`demo`.

    Attributes
    ----------
    view : the part's ``*View`` (``CoreView``, ``GridView``, ``IsoView``, ``StacksView``)
    exaggeration : bool
        The part supports vertical exaggeration.
    """

    kind = ""
    title = ""
    exaggeration = False

    view: Any = None

    @classmethod
    def accepts(cls, model) -> bool:
        raise NotImplementedError

    @classmethod
    def demo(cls) -> tuple[Any, dict]:
        """A small synthetic model of this part and the settings to open it with."""
        raise NotImplementedError

    # --- the View -------------------------------------------------------------------------------
    def camera(self, view: str = "iso", azimuth=None, elevation=None, zoom: float = 1.0,
               ortho: bool = False):
        return self.view.camera(view=view, azimuth=azimuth, elevation=elevation, zoom=zoom,
                                ortho=ortho)

    def set_size(self, size) -> None:
        """Picture size in pixels; the View re-makes its target on the next draw."""
        w, h = (max(1, int(v)) for v in size)
        self.view.size = (w, h)

    def _draw(self, camera, count: bool):
        return self.view.draw(camera, frames=1, count=count)

    def draw(self, camera, count: bool = True) -> tuple[np.ndarray, dict]:
        """One frame: ``(rgba (h, w, 4) uint8, stats)``; warnings go to ``stats['warning']``."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            return self._draw(camera, count)

    def set_exaggeration(self, factor: float) -> None:
        if not self.exaggeration:
            raise InputError(f"exaggeration: the {self.kind} view has no vertical exaggeration")
        self.view.set_exaggeration(float(factor))

    def release(self) -> None:
        if self.view is not None:
            self.view.release()
            self.view = None

    # --- settings -------------------------------------------------------------------------------
    def settings(self) -> dict:
        """The current settings, by the names :meth:`apply` takes."""
        return {}

    def apply(self, **settings) -> list[Job]:
        """Change settings by name; returns the long jobs still to run (possibly none)."""
        if settings:
            raise InputError(f"{', '.join(sorted(settings))}: not a setting of the {self.kind} "
                             f"view; it takes {', '.join(sorted(self.settings())) or 'none'}")
        return []

    def readout(self, stats: dict) -> str:
        """Part-specific counts for the status line."""
        return ""


#: exaggerations :func:`auto_exaggeration` picks from
NICE_EXAGGERATIONS = (1, 2, 5, 10, 20, 50, 100, 200)


def auto_exaggeration(bounds, ratio: float = 0.2) -> float:
    """A round vertical exaggeration that makes a flat model about ``ratio`` as tall as wide.

    >>> auto_exaggeration([[0, 0, 0], [10000, 8000, 50]])
    20.0
    >>> auto_exaggeration([[0, 0, 0], [10, 10, 10]])
    1.0
    """
    b = np.asarray(bounds, float)
    width, height = float(max(b[1, 0] - b[0, 0], b[1, 1] - b[0, 1])), float(b[1, 2] - b[0, 2])
    if not (height > 0 and width > 0):
        return 1.0
    want = ratio * width / height
    return float(max([n for n in NICE_EXAGGERATIONS if n <= want], default=1))


def unknown_settings(part: Part, names) -> InputError:
    return InputError(f"{', '.join(sorted(names))}: not a setting of the {part.kind} view; it "
                      f"takes {', '.join(sorted(part.settings()))}")


def fmt_int(v) -> str:
    return "?" if v is None else f"{int(v):,}"
