"""One ingest at a time per store: ``CORE.zarr.lock`` beside the store.

The lock is an ``flock`` on that file (released by the kernel when its process ends, however it
ends), and the file says who holds it (pid, host, start time) for the message a second ingest
gives::

    CORE.zarr: another ingest is writing CORE.zarr (pid 4242 on host node7, since 12:03:55)

A lock file whose process has died holds no ``flock``: the next ingest takes it over (and says so
in its report).  The holder removes the file when it ends; the second ingest creates nothing.

The lock file is never followed or written through a link: it is created with ``O_EXCL`` and
opened with ``O_NOFOLLOW``, and ``fstat`` must show a regular file owned by this user with one
link (anyone who can write in a shared folder could plant ``CORE.zarr.lock -> ~/precious``);
anything else is refused in one line naming the file.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import stat
import time
from pathlib import Path

from geoshade.errors import EXIT_BUSY, GeoshadeError, InputError
from geoshade.io.output import check_replace

try:  # POSIX; elsewhere the lock falls back to O_EXCL and the holder's pid
    import fcntl
except ImportError:  # pragma: no cover
    fcntl = None  # type: ignore[assignment]

#: suffix of the lock file beside the store (``CORE.zarr.lock``)
LOCK_SUFFIX = ".lock"


class StoreBusyError(GeoshadeError):
    """Another ingest is writing the same store (exit code 75, 'try again later')."""

    exit_code = EXIT_BUSY


def lock_path(store) -> Path:
    """``CORE.zarr.lock`` for ``CORE.zarr``.

    >>> lock_path("out/CORE.zarr").name
    'CORE.zarr.lock'
    """
    p = Path(store)
    if not p.name or p.name == "..":   # "." or "..": the folder's own name, beside it
        p = p.absolute().resolve()
    return p.with_name(p.name + LOCK_SUFFIX)


_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)


class UnsafePathError(InputError):
    """A path geoshade would write is a link, not a regular file or not this user's own."""


def refuse_link(path, what: str = "output") -> None:
    """Refuse ``path`` when it is a symbolic link (a planted link must never be written through).

    Raises
    ------
    UnsafePathError
        One line naming the file and where the link points.

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp(); os.symlink("/etc/hostname", os.path.join(d, "x.partial"))
    >>> try:
    ...     refuse_link(os.path.join(d, "x.partial"), "unfinished store")
    ... except UnsafePathError as err:
    ...     print(str(err).split(": ", 1)[1][:52])
    is a symbolic link (to /etc/hostname), not an unfini
    """
    p = Path(path)
    if p.is_symlink():
        try:
            target = os.readlink(p)
        except OSError:
            target = "?"
        raise UnsafePathError(f"{p}: is a symbolic link (to {target}), not an {what} geoshade "
                              "made: remove it, then run again")


def _check_fd(fd: int, path: Path) -> None:
    """fstat checks on an opened lock file: a regular file, owned by this user, one link."""
    st = os.fstat(fd)
    why = ("is not a regular file" if not stat.S_ISREG(st.st_mode) else
           f"belongs to another user (uid {st.st_uid})"
           if hasattr(os, "geteuid") and st.st_uid != os.geteuid() else
           f"has {st.st_nlink} hard links" if st.st_nlink != 1 else "")
    if why:
        os.close(fd)
        raise UnsafePathError(f"{path}: {why}, not a lock file geoshade made: remove it, then "
                              "run again")


def _open_lock(path: Path) -> tuple[int, bool]:
    """Open the lock file without following a link: (fd, existed)."""
    flags = os.O_RDWR | _NOFOLLOW | _CLOEXEC
    try:
        return os.open(path, flags | os.O_CREAT | os.O_EXCL, 0o644), False
    except FileExistsError:
        pass
    refuse_link(path, "ingest lock")
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:  # removed meanwhile: try again from the start
        return -1, False
    except OSError as err:  # ELOOP: a link planted between the two opens
        raise UnsafePathError(f"{path}: cannot be opened safely as a lock file "
                              f"({(err.strerror or type(err).__name__).lower()}): remove it, "
                              "then run again") from None
    return fd, True


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


def _read_owner_fd(fd: int) -> dict:
    """The holder's record read through the already opened (and checked) descriptor."""
    for _ in range(20):
        try:
            text = os.pread(fd, 65536, 0).decode("utf-8", "replace")
        except OSError:
            return {}
        if text.strip():
            try:
                d = json.loads(text)
                return d if isinstance(d, dict) else {}
            except (ValueError, RecursionError):
                return {}
        time.sleep(0.01)
    return {}


def _busy(store, owner: dict) -> StoreBusyError:
    pid = owner.get("pid", "unknown")
    host = owner.get("host")
    where = f" on host {host}" if host and host != socket.gethostname() else ""
    since = f", since {owner['since']}" if owner.get("since") else ""
    task = owner.get("task")
    task = f"{task}, " if isinstance(task, str) and task and len(task) < 80 else ""
    return StoreBusyError(f"{store}: another ingest is writing {Path(store).name} ({task}pid "
                          f"{pid}{where}{since}); wait for it to end, or stop it")


class IngestLock:
    """Hold the ingest lock of ``store`` (a context manager).

    Every writer of a store holds it: an ingest (core or grid), ``grid ingest --index-only``
    and ``--coarse`` (``task`` names what it does, for the second writer's message).  An ingest
    (``input_path`` given) about to replace an existing ``store`` has it checked first
    (:func:`geoshade.io.output.check_replace`: only a store geoshade wrote, never a folder
    holding other things or the input), before anything is written.

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

    def __init__(self, store, input_path: str = "", task: str = ""):
        self.store, self.path = Path(store), lock_path(store)
        self.input, self.task = str(input_path), str(task)
        self.took_over: dict | None = None
        self._fd: int | None = None

    def acquire(self) -> IngestLock:
        if self.input and (self.store.exists() or self.store.is_symlink()):
            check_replace(self.store, [self.input])   # what an ingest would replace
        for _ in range(50):
            fd, existed = _open_lock(self.path)
            if fd < 0:
                continue
            _check_fd(fd, self.path)
            owner = _read_owner_fd(fd) if existed else {}
            if not self._flock(fd):
                os.close(fd)
                raise _busy(self.store, owner or _read_owner_fd(fd))
            try:  # the file may have been removed (and re-created) while we waited
                same = os.path.samestat(os.fstat(fd), os.lstat(self.path))
            except FileNotFoundError:
                same = False
            if not same:
                os.close(fd)
                continue
            if existed and owner.get("pid") not in (None, os.getpid()):
                self.took_over = owner
            self._fd = fd
            record = {"pid": os.getpid(), "host": socket.gethostname(),
                      "since": time.strftime("%Y-%m-%d %H:%M:%S"), "input": self.input,
                      **({"task": self.task} if self.task else {})}
            os.ftruncate(fd, 0)
            os.pwrite(fd, json.dumps(record).encode(), 0)
            return self
        raise _busy(self.store, {})  # pragma: no cover

    def _flock(self, fd: int) -> bool:
        if fcntl is None:  # pragma: no cover
            owner = _read_owner_fd(fd)
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
            if os.path.samestat(os.fstat(self._fd), os.lstat(self.path)):
                os.unlink(self.path)
        with contextlib.suppress(OSError):
            os.close(self._fd)  # closing releases the flock
        self._fd = None

    def __enter__(self) -> IngestLock:
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()
