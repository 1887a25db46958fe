"""The full picture of a progressive View, built while its coarse preview is shown.

Toolkit-free: :class:`Refiner` runs a loading View's refine job (:mod:`geoshade.render.progressive`)
on the viewers' one job runner (:class:`~geoshade.viewer.jobs.JobRunner`): its CPU half on a
worker thread, its GL half on the caller's thread (:meth:`Refiner.poll`, called from the
notebook's event loop); a newer job supersedes the running one (its result is dropped: a change
made while loading cancels the old load). :meth:`Refiner.line` is the progress
line shown under the preview (``coarse preview — full picture 40 %``). The desktop window runs
the same job through its :class:`~geoshade.viewer.qt.TaskRunner`, whose progress bar says the
same.
"""

from __future__ import annotations

from geoshade.render.progressive import REFINE_LABEL
from geoshade.render.view import Job
from geoshade.viewer.jobs import JobRunner


class Refiner:
    """Builds a loading View's full picture in the background (see the module), through the
    viewers' one :class:`~geoshade.viewer.jobs.JobRunner` (its GL halves queued for
    :meth:`poll`).

    Examples
    --------
    >>> import geoshade
    >>> from geoshade.core import CoreView
    >>> r = Refiner(CoreView(geoshade.synthetic_core(8), size=(32, 24)))   # not loading
    >>> r.line(), r.poll()
    ('', False)
    """

    def __init__(self, view):
        self.view = view
        self.job: Job | None = None
        self.fraction = 0.0
        self.error: BaseException | None = None
        self._applied = False
        self._runner = JobRunner(state=self._state, name="geoshade-refine")

    def _state(self, label: str, done: int, total: int) -> None:
        if label and total:
            self.fraction = min(1.0, done / total)

    @property
    def loading(self) -> bool:
        return bool(getattr(self.view, "loading", False))

    def start(self, job: Job | None = None) -> None:
        """Run ``job`` (default: the View's refine job) in the background; a job started
        before and not yet applied is superseded."""
        if job is None and not self.loading:
            return
        self.job = job if job is not None else self.view.refine_job()
        self.fraction, self.error = 0.0, None
        self._runner.submit(self.job, then=self._done, error=self._failed)

    def _done(self) -> None:
        self.fraction, self._applied = 1.0, True

    def _failed(self, err: BaseException) -> None:
        self.error = err   # shown by the front end as one line

    def poll(self) -> bool:
        """On the GL thread: apply a finished job's result; True when the full picture is
        now the View's (draw again)."""
        self._applied = False
        self._runner.run_posted()
        return self._applied

    def busy(self) -> bool:
        return self._runner.busy()

    def line(self) -> str:
        """``coarse preview — full picture 40 %`` while loading, else empty."""
        if not self.loading:
            return ""
        if self.error is not None:
            return f"coarse preview — the full picture failed: {self.error}"
        return f"{REFINE_LABEL} {100 * self.fraction:.0f} %"

    def close(self) -> None:
        self._runner.shutdown(wait=False)


__all__ = ["Refiner"]
