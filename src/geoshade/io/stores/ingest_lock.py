"""One ingest at a time per store: ``CORE.zarr.lock`` beside the store.

The lock is an ``flock`` on that file (released by the kernel when its process ends, however it
ends), and the file says who holds it (pid, host, start time) for the message a second ingest
gives::

    CORE.zarr: another ingest is writing CORE.zarr (pid 4242 on host node7, since 12:03:55)

A lock file whose process has died holds no ``flock``: the next ingest takes it over (and says so
in its report).  The holder removes the file when it ends; the second ingest creates nothing.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import time
from pathlib import Path

from geoshade.errors import GeoshadeError

try:  # POSIX; elsewhere the lock falls back to O_EXCL and the holder's pid
    import fcntl
except ImportError:  # pragma: no cover
    fcntl = None  # type: ignore[assignment]

#: suffix of the lock file beside the store (``CORE.zarr.lock``)
LOCK_SUFFIX = ".lock"


class StoreBusyError(GeoshadeError):
    """Another ingest is writing the same store (exit code 75, 'try again later')."""

    exit_code = 75


def lock_path(store) -> Path:
    """``CORE.zarr.lock`` for ``CORE.zarr``.

    >>> lock_path("out/CORE.zarr").name
    'CORE.zarr.lock'
    """
    p = Path(store)
    return p.with_name(p.name + LOCK_SUFFIX)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return False
    return True


def _read_owner(f: Path) -> dict:
    for _ in range(20):  # the holder writes its record right after taking the lock
        try:
            text = f.read_text()
        except OSError:
            return {}
        if text.strip():
            try:
                d = json.loads(text)
                return d if isinstance(d, dict) else {}
            except ValueError:
                return {}
        time.sleep(0.01)
    return {}


def _busy(store, owner: dict) -> StoreBusyError:
    pid = owner.get("pid", "unknown")
    host = owner.get("host")
    where = f" on host {host}" if host and host != socket.gethostname() else ""
    since = f", since {owner['since']}" if owner.get("since") else ""
    return StoreBusyError(f"{store}: another ingest is writing {Path(store).name} (pid {pid}"
                          f"{where}{since}); wait for it to end, or stop it")


class IngestLock:
    """Hold the ingest lock of ``store`` (a context manager).

    Attributes
    ----------
    took_over : dict or None
        The record of a dead holder whose lock this one replaced.

    Examples
    --------
    >>> import tempfile, os
    >>> store = os.path.join(tempfile.mkdtemp(), "c.zarr")
    >>> with IngestLock(store):
    ...     with IngestLock(store):
    ...         pass
    Traceback (most recent call last):
    ...
    geoshade.io.stores.ingest_lock.StoreBusyError: ...c.zarr: another ingest is writing ...
    >>> os.path.exists(store + ".lock")
    False
    """

    def __init__(self, store, input_path: str = ""):
        self.store, self.path = Path(store), lock_path(store)
        self.input = str(input_path)
        self.took_over: dict | None = None
        self._fd: int | None = None

    def acquire(self) -> IngestLock:
        for _ in range(50):
            existed = self.path.exists()
            owner = _read_owner(self.path) if existed else {}
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError:
                raise
            if not self._flock(fd):
                os.close(fd)
                raise _busy(self.store, owner or _read_owner(self.path))
            try:  # the file may have been removed (and re-created) while we waited
                same = os.path.samestat(os.fstat(fd), os.stat(self.path))
            except FileNotFoundError:
                same = False
            if not same:
                os.close(fd)
                continue
            if existed and owner.get("pid") not in (None, os.getpid()):
                self.took_over = owner
            self._fd = fd
            record = {"pid": os.getpid(), "host": socket.gethostname(),
                      "since": time.strftime("%Y-%m-%d %H:%M:%S"), "input": self.input}
            os.ftruncate(fd, 0)
            os.pwrite(fd, json.dumps(record).encode(), 0)
            return self
        raise _busy(self.store, _read_owner(self.path))  # pragma: no cover

    def _flock(self, fd: int) -> bool:
        if fcntl is None:  # pragma: no cover
            owner = _read_owner(self.path)
            pid = owner.get("pid")
            return not (isinstance(pid, int) and pid != os.getpid() and _pid_alive(pid))
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return False
        return True

    def release(self) -> None:
        if self._fd is None:
            return
        with contextlib.suppress(OSError):
            if os.path.samestat(os.fstat(self._fd), os.stat(self.path)):
                os.unlink(self.path)
        with contextlib.suppress(OSError):
            os.close(self._fd)  # closing releases the flock
        self._fd = None

    def __enter__(self) -> IngestLock:
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()
