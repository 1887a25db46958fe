"""The full picture of a progressive View, built while its coarse preview is shown.

Toolkit-free: :class:`Refiner` runs a loading View's refine job (:mod:`geoshade.render.progressive`)
with its CPU half on a worker thread and its GL half on the caller's thread (:meth:`Refiner.poll`,
called from the notebook's event loop); a newer job supersedes the running one (its result is
dropped: a change made while loading cancels the old load). :meth:`Refiner.line` is the progress
line shown under the preview (``coarse preview — full picture 40 %``). The desktop window runs
the same job through its :class:`~geoshade.viewer.qt.TaskRunner`, whose progress bar says the
same.
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor

from geoshade.render.progressive import REFINE_LABEL
from geoshade.render.view import Job


class Refiner:
    """Builds a loading View's full picture in the background (see the module).

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
        self.future: Future | None = None
        self.fraction = 0.0
        self.error: BaseException | None = None
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="geoshade-refine")
        self._generation = 0

    @property
    def loading(self) -> bool:
        return bool(getattr(self.view, "loading", False))

    def start(self, job: Job | None = None) -> None:
        """Run ``job`` (default: the View's refine job) in the background; a job started
        before and not yet applied is superseded."""
        if job is None and not self.loading:
            return
        self._generation += 1
        gen = self._generation
        self.job = job if job is not None else self.view.refine_job()
        self.fraction, self.error = 0.0, None

        def progress(done, total) -> None:
            if gen == self._generation and total:
                self.fraction = min(1.0, done / total)

        self.future = self._pool.submit(self.job.compute, progress)

    def poll(self) -> bool:
        """On the GL thread: apply a finished job's result; True when the full picture is
        now the View's (draw again)."""
        f, job = self.future, self.job
        if f is None or job is None or not f.done():
            return False
        self.future = None
        try:
            result = f.result()
        except Exception as err:   # shown by the front end as one line
            self.error = err
            return False
        job.apply(result)
        self.fraction = 1.0
        return True

    def busy(self) -> bool:
        return self.future is not None

    def line(self) -> str:
        """``coarse preview — full picture 40 %`` while loading, else empty."""
        if not self.loading:
            return ""
        if self.error is not None:
            return f"coarse preview — the full picture failed: {self.error}"
        return f"{REFINE_LABEL} {100 * self.fraction:.0f} %"

    def close(self) -> None:
        self._generation += 1
        self._pool.shutdown(wait=False, cancel_futures=True)


__all__ = ["Refiner"]
