"""The one job runner of every viewer (no GUI toolkit).

A View's long work comes as :class:`~geoshade.render.view.Job` s: a CPU half (``compute``) for
any thread and a GL half (``apply``) for the thread that owns the GL context. :class:`JobRunner`
runs the CPU halves on one worker thread and hands each GL half to ``post``, the front end's way
of running a function on its GL thread: the Qt window posts through a queued signal, the
notebook widget queues it for its event loop (:meth:`JobRunner.run_posted`), the browser server
submits it to its GL thread. A newer job with the same key supersedes an older one (a queued one
is cancelled, a running one's result dropped), and a job is never applied inside
:meth:`JobRunner.submit`, even when it is done before ``submit`` returns.

>>> from geoshade.render.view import Job
>>> done = []
>>> r = JobRunner()                      # post: queue for run_posted()
>>> r.submit(Job("k", "adding", lambda p: 1 + 1, done.append))
>>> r.wait(), r.run_posted(), done
(True, 1, [2])
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

#: ``state(label, done, total)``: what a progress line shows (label "" when idle)
State = Callable[[str, int, int], Any]


class JobRunner:
    """Runs jobs: CPU half on a worker, GL half through ``post`` (see the module).

    Parameters
    ----------
    post : callable(fn), optional
        Runs ``fn()`` later on the GL thread. Default: queue it for :meth:`run_posted`.
    state : callable(label, done, total), optional
        Told when a job starts, progresses and when the runner is idle again (any thread for
        progress; the GL thread for the rest).
    name : str
        The worker thread's name.
    """

    def __init__(self, post: Callable[[Callable[[], None]], Any] | None = None,
                 state: State | None = None, name: str = "geoshade-jobs"):
        self._pool = ThreadPoolExecutor(1, name)
        self._posted: list[Callable[[], None]] = []
        self._post = post if post is not None else self._posted.append
        self._state = state
        self._latest: dict[str, int] = {}
        self._futures: dict[int, Future] = {}
        self._serial = 0
        self._lock = threading.Lock()
        # its own lock: cancelling a future (under _lock) runs its done-callback at once
        self._settled = threading.Condition(threading.Lock())
        self._unposted = 0   # CPU halves submitted whose GL half is not posted yet

    def busy(self) -> bool:
        """True while a job is computing or waiting to be applied."""
        return bool(self._futures)

    def submit(self, job, then: Callable[[], Any] | None = None,
               error: Callable[[BaseException], Any] | None = None) -> None:
        """Run ``job``; on the GL thread call ``then()`` after its apply, ``error(exc)`` when
        either half fails (without ``error`` the exception is raised there)."""
        with self._lock:
            self._serial += 1
            n = self._serial
            old = self._latest.get(job.key)
            if old is not None and old in self._futures and self._futures[old].cancel():
                del self._futures[old]
            self._latest[job.key] = n
        label = job.label

        def progress(done, total) -> None:
            if self._state is not None:
                self._state(label, int(done), int(total))

        def work():
            try:
                return job.compute(progress), None
            except Exception as exc:   # delivered to the GL thread
                return None, exc

        def posted(f: Future) -> None:
            try:
                if not f.cancelled():
                    self._post(lambda: self._finish(n, job, then, error, *f.result()))
            finally:
                with self._settled:
                    self._unposted -= 1
                    self._settled.notify_all()

        with self._settled:
            self._unposted += 1
        fut = self._pool.submit(work)
        with self._lock:
            self._futures[n] = fut
        if self._state is not None:
            self._state(label, 0, 0)
        fut.add_done_callback(posted)

    def _finish(self, n: int, job, then, error, value, exc) -> None:
        with self._lock:
            self._futures.pop(n, None)
            current = self._latest.get(job.key) == n
        try:
            if not current:
                return   # superseded by a newer job of its key
            if exc is None:
                try:
                    job.apply(value)
                except Exception as e:
                    exc = e
            if exc is not None:
                if error is None:
                    raise exc
                error(exc)
                return
            if then is not None:
                then()
        finally:
            if not self._futures and self._state is not None:
                self._state("", 0, 0)

    def run_posted(self) -> int:
        """Run the GL halves queued by the default ``post`` (call it on the GL thread); how
        many ran."""
        ran = 0
        while self._posted:
            self._posted.pop(0)()
            ran += 1
        return ran

    def wait(self, timeout: float | None = None) -> bool:
        """Block until every submitted CPU half is done and its GL half posted (tests,
        screenshots); False when ``timeout`` seconds passed first."""
        with self._settled:
            return self._settled.wait_for(lambda: self._unposted == 0, timeout)

    def shutdown(self, wait: bool = True) -> None:
        self._pool.shutdown(wait=wait, cancel_futures=True)


__all__ = ["JobRunner", "State"]
