"""Checks every reader makes before it opens anything: the path is what it should be, the memory
a whole-array read needs is there, and a library's failure becomes one line.

- :func:`check_file` / :func:`check_folder` / :func:`check_input`: a FIFO, a device or a socket is
  refused before it is opened (opening a FIFO blocks until someone writes to it: a hang), and so
  is a folder where a file is expected and a file where a folder is expected.
- :func:`check_memory`: a reader about to hold ``nbytes`` in memory compares them with what the
  machine has (``MemAvailable`` of ``/proc/meminfo``, and a cgroup's limit) and refuses with one
  line giving both numbers, instead of failing half-way (or swapping the machine to a halt).
- :func:`one_line`: the first line of a library's exception, for messages.
- :func:`captured_logs`: silence a library's ``logging`` output (tifffile logs damaged files as
  errors) and keep the records, so that the reader can say what is wrong in its own line.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import os
import signal
import stat
import threading
from collections.abc import Iterator
from pathlib import Path

from geoshade.errors import EXIT_MEMORY, GeoshadeError, InputError

try:
    import resource
except ImportError:  # pragma: no cover - not on Windows
    resource = None  # type: ignore[assignment]

#: what each kind of special file is called in messages
_SPECIAL = (
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


class NotEnoughMemoryError(GeoshadeError, MemoryError):
    """A read would need more memory than the machine has available (exit code 6)."""

    exit_code = EXIT_MEMORY


def _stat(path) -> os.stat_result:
    try:
        return os.stat(path)
    except FileNotFoundError:
        what = "no such file (a broken symbolic link)" if os.path.islink(path) else "no such file"
        raise InputError(f"{path}: {what}") from None
    except NotADirectoryError:
        raise InputError(f"{path}: no such file (a part of the path is not a folder)") from None
    except PermissionError:
        raise InputError(f"{path}: permission denied") from None
    except OSError as err:
        raise InputError(f"{path}: cannot be read ({(err.strerror or str(err)).lower()})"
                         ) from None


def _special(mode: int) -> str | None:
    return next((name for test, name in _SPECIAL if test(mode)), None)


def check_input(path, what: str = "") -> Path:
    """``path`` as a :class:`~pathlib.Path` if it is a regular file or a folder; else one line.

    Examples
    --------
    >>> import os, tempfile
    >>> fifo = os.path.join(tempfile.mkdtemp(), "scan.tif")
    >>> os.mkfifo(fifo)
    >>> check_input(fifo)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: .../scan.tif: is a FIFO (named pipe), not a file; geoshade reads ...
    """
    mode = _stat(path).st_mode
    special = _special(mode)
    if special is not None:
        expected = f"expected {what}" if what else "geoshade reads regular files and folders"
        raise InputError(f"{path}: is {special}, not a file; {expected}")
    return Path(path)


def check_file(path, what: str = "a file") -> Path:
    """``path`` if it is a regular file (or a link to one); a folder or a special file is refused
    in one line naming ``what`` was expected.

    Examples
    --------
    >>> import tempfile
    >>> check_file(tempfile.mkdtemp(), "a .npy file")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: ...: is a folder; expected a .npy file
    """
    p = check_input(path, what)
    if stat.S_ISDIR(os.stat(p).st_mode):
        raise InputError(f"{path}: is a folder; expected {what}")
    return p


def check_folder(path, what: str = "a folder") -> Path:
    """``path`` if it is a folder; a file (or special file) is refused in one line.

    Examples
    --------
    >>> import tempfile
    >>> f = tempfile.mkstemp(suffix=".zarr")[1]
    >>> check_folder(f, "a zarr store (a folder)")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: ...zarr: is a file; expected a zarr store (a folder)
    """
    p = check_input(path, what)
    if not stat.S_ISDIR(os.stat(p).st_mode):
        raise InputError(f"{path}: is a file; expected {what}")
    return p


def one_line(err: BaseException, limit: int = 200) -> str:
    """``Type: first line of the message`` of an exception, at most ``limit`` characters.

    Examples
    --------
    >>> one_line(ValueError("bad\\nsecond line"))
    'ValueError: bad'
    """
    text = str(err).strip()
    first = text.splitlines()[0].strip() if text else ""
    name = type(err).__name__
    if name == "error":  # zlib.error, struct.error, ...
        name = f"{type(err).__module__}.error"
    out = f"{name}: {first}" if first else name
    return out if len(out) <= limit else out[: limit - 1] + "…"


# --------------------------------------------------------------------------------------------
# memory
# --------------------------------------------------------------------------------------------
def cgroup_free() -> int | None:
    """Bytes a cgroup v2 memory limit leaves to this process's group (None: no limit)."""
    base = Path("/sys/fs/cgroup")
    try:
        limit = (base / "memory.max").read_text().strip()
        if limit == "max":
            return None
        used = int((base / "memory.current").read_text().strip())
        return max(0, int(limit) - used)
    except (OSError, ValueError):
        return None


def status_bytes(field: str, source: str = "/proc/self/status") -> int | None:
    """A ``kB`` field of ``/proc/self/status`` (VmRSS, VmSize, VmData) or of ``source``
    (``/proc/meminfo``: MemAvailable) in bytes; None where the system does not say."""
    try:
        with open(source) as fh:
            for line in fh:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def give_back_freed() -> bool:
    """Hand the memory this process has freed back to the system where the C library keeps it
    (glibc's ``malloc_trim``: freed blocks of the heaps' arenas stay resident otherwise; a
    1e9 filter made on threads left ~1.5 GiB so); True where it was done, False elsewhere
    (another C library, another system: nothing to do).

    >>> give_back_freed() in (True, False)
    True
    """
    global _TRIM
    if _TRIM is None:
        try:
            _TRIM = ctypes.CDLL(None).malloc_trim
            _TRIM.argtypes, _TRIM.restype = [ctypes.c_size_t], ctypes.c_int
        except (OSError, AttributeError):
            _TRIM = False
    if _TRIM is False:
        return False
    _TRIM(0)
    return True


_TRIM = None
#: allocations of this size and more are mapped apart by glibc and returned when freed
BIG_ALLOCATION = 4 << 20
_MAPPED_APART = False


def map_big_allocations() -> bool:
    """Have glibc map every allocation of :data:`BIG_ALLOCATION` bytes or more apart, given
    back to the system when freed (``mallopt(M_MMAP_THRESHOLD)``, set once for the process):
    glibc otherwise raises that threshold to 32 MiB after the first large free, so the
    layers' arrays of a grid drawn out of core (a few to 30 MB each) stay on the heaps once
    freed. At 1e9 cells: the held memory after the first picture 1.70 -> 1.42 GiB, the
    filter's peak 4.06 -> 3.79 GiB, its time unchanged. True where it was done.

    >>> map_big_allocations() in (True, False)
    True
    """
    global _MAPPED_APART
    if _MAPPED_APART:
        return True
    try:
        mallopt = ctypes.CDLL(None).mallopt
        mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    except (OSError, AttributeError):
        return False
    _MAPPED_APART = bool(mallopt(-3, BIG_ALLOCATION))   # M_MMAP_THRESHOLD
    return _MAPPED_APART


def _rlimit_free() -> tuple[int, str] | None:
    """Bytes the process's ``RLIMIT_AS`` (``ulimit -v``) and ``RLIMIT_DATA`` leave beyond what
    it has mapped now, and which limit binds (None: no limit)."""
    if resource is None:  # pragma: no cover
        return None
    best = None
    for name, field in (("RLIMIT_AS", "VmSize"), ("RLIMIT_DATA", "VmData")):
        try:
            soft = resource.getrlimit(getattr(resource, name))[0]
        except (AttributeError, OSError, ValueError):
            continue
        if soft == resource.RLIM_INFINITY or soft < 0:
            continue
        used = status_bytes(field) or 0
        free = max(0, int(soft) - used)
        if best is None or free < best[0]:
            best = (free, f"{name} {format_bytes(soft)}")
    return best


#: the address space (``ulimit -v``) a software OpenGL renderer (llvmpipe: LLVM, its threads)
#: and the math libraries need to start: below it they die with SIGSEGV, "LLVM ERROR: out of
#: memory" or an OpenBLAS error instead of a line (about 0.9 GiB was measured)
GL_MIN_ADDRESS_SPACE = 1 << 30


def check_address_space(need: int = GL_MIN_ADDRESS_SPACE, what: str = "OpenGL") -> None:
    """Refuse in one line (exit 4) when ``RLIMIT_AS`` (``ulimit -v``) is below ``need`` bytes.

    Examples
    --------
    >>> check_address_space(1)
    """
    if resource is None:  # pragma: no cover
        return
    try:
        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    except (AttributeError, OSError, ValueError):  # pragma: no cover
        return
    if soft == resource.RLIM_INFINITY or soft < 0 or soft >= need:
        return
    raise NotEnoughMemoryError(
        f"{what}: the address-space limit (ulimit -v, RLIMIT_AS) of {format_bytes(soft)} is "
        f"below the {format_bytes(need)} it needs to start; raise the limit")


#: which limit :func:`mem_available` found smallest ("MemAvailable", "cgroup", "RLIMIT_AS ...")
_LIMIT = ["MemAvailable"]


def mem_available() -> int | None:
    """Bytes of memory available to a new allocation without swapping (``MemAvailable`` of
    ``/proc/meminfo``, or less under a cgroup limit or the process's ``RLIMIT_AS`` /
    ``RLIMIT_DATA`` (``ulimit -v``)); None where the system does not say.

    Examples
    --------
    >>> n = mem_available()
    >>> n is None or n > 0
    True
    """
    found = status_bytes("MemAvailable", "/proc/meminfo")
    _LIMIT[0] = "MemAvailable"
    cg = cgroup_free()
    if cg is not None and (found is None or cg < found):
        found, _LIMIT[0] = cg, "cgroup memory.max"
    rl = _rlimit_free()
    if rl is not None and (found is None or rl[0] < found):
        found, _LIMIT[0] = rl[0], rl[1]
    return found


def format_bytes(n: float) -> str:
    """``n`` bytes in B, KiB, MiB, GiB or TiB.

    Examples
    --------
    >>> format_bytes(3 * 2**30), format_bytes(512)
    ('3.0 GiB', '512 B')
    """
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024 or unit == "PiB":
            return f"{int(n)} B" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n} B"  # pragma: no cover


def check_memory(nbytes: int, path, what: str, hint: str = "") -> None:
    """Refuse a read that would hold ``nbytes`` in memory when the machine has less available.

    Parameters
    ----------
    nbytes : int
        Bytes the reader is about to allocate.
    path : str or Path
        The file, for the message.
    what : str
        What is read (``"the array 'data'"``).
    hint : str
        What to do instead (``"use lazy=True"``), appended to the message.

    Raises
    ------
    NotEnoughMemoryError
        One line with both numbers (exit code 4).

    Examples
    --------
    >>> check_memory(1, "small.npz", "the array")
    >>> check_memory(2**62, "huge.npz", "the array")
    Traceback (most recent call last):
    ...
    geoshade.io.paths.NotEnoughMemoryError: huge.npz: reading the array needs 4096.0 PiB ...
    """
    avail = mem_available()
    if avail is None or int(nbytes) <= avail:
        return
    tail = f"; {hint}" if hint else ""
    raise NotEnoughMemoryError(
        f"{path}: reading {what} needs {format_bytes(nbytes)} of memory and "
        f"{format_bytes(avail)} are available ({_LIMIT[0]}){tail}")


# --------------------------------------------------------------------------------------------
# mapped files that shrink
# --------------------------------------------------------------------------------------------
#: environment variable holding the line the SIGBUS handler prints (set by :func:`guard_mapped`)
SIGBUS_ENV = "GEOSHADE_SIGBUS_LINE"
_MAPPED: list[str] = []
_SIGBUS_INSTALLED: list[bool] = []


#: the SIGBUS handler, in LLVM IR (compiled with llvmlite, numba's code generator, in ~0.1 s):
#: no Python runs in a signal handler; it prints the line in $GEOSHADE_SIGBUS_LINE, exits 74
_SIGBUS_IR = r"""
@.name = private constant [21 x i8] c"GEOSHADE_SIGBUS_LINE\00"
declare i8* @getenv(i8*)
declare i64 @strlen(i8*)
declare i64 @write(i32, i8*, i64)
declare void @_exit(i32)
define void @on_sigbus(i32 %sig) {
entry:
  %p = getelementptr [21 x i8], [21 x i8]* @.name, i64 0, i64 0
  %line = call i8* @getenv(i8* %p)
  %isnull = icmp eq i8* %line, null
  br i1 %isnull, label %done, label %say
say:
  %n = call i64 @strlen(i8* %line)
  %w = call i64 @write(i32 2, i8* %line, i64 %n)
  br label %done
done:
  call void @_exit(i32 74)
  unreachable
}
"""
_KEEP: list = []  # the compiled handler's engine lives as long as the process


def _install_sigbus() -> bool:
    """A C-level SIGBUS handler that prints the line in :data:`SIGBUS_ENV` and ends the
    process with exit status 74 (an OS error). A file truncated while it is mapped raises
    SIGBUS on the next read of a lost page; without this the process dies without a word."""
    if _SIGBUS_INSTALLED:
        return _SIGBUS_INSTALLED[0]
    ok = False
    try:
        import llvmlite.binding as llvm

        llvm.initialize_native_target()
        llvm.initialize_native_asmprinter()
        mod = llvm.parse_assembly(_SIGBUS_IR)
        mod.verify()
        engine = llvm.create_mcjit_compiler(
            mod, llvm.Target.from_default_triple().create_target_machine())
        engine.finalize_object()
        _KEEP.append(engine)
        sig = ctypes.CDLL(None).signal
        sig.argtypes, sig.restype = [ctypes.c_int, ctypes.c_void_p], ctypes.c_void_p
        sig(int(signal.SIGBUS), engine.get_function_address("on_sigbus"))
        ok = True
    except Exception:  # no llvmlite, another libc: the default (the process dies with SIGBUS)
        ok = False
    _SIGBUS_INSTALLED.append(ok)
    return ok


def guard_mapped(path) -> None:
    """Say "the file shrank while it was read" in one line (exit 74) if ``path``, about to be
    mapped with ``numpy.memmap``, is truncated while mapped (SIGBUS), instead of dying silently.

    Examples
    --------
    >>> guard_mapped("core.raw")
    >>> "core.raw" in os.environ[SIGBUS_ENV]
    True
    """
    name = str(path)
    if name not in _MAPPED:
        _MAPPED.append(name)
    del _MAPPED[:-8]
    what = (f"{_MAPPED[0]}: the file" if len(_MAPPED) == 1 else
            f"one of {', '.join(_MAPPED)}: a file")
    os.environ[SIGBUS_ENV] = (
        f"geoshade: error: {what} shrank while it was read (it was truncated or replaced while "
        "mapped); read it again once it is complete\n")
    _install_sigbus()


# --------------------------------------------------------------------------------------------
# libraries' log lines
# --------------------------------------------------------------------------------------------
_LOG_LOCK = threading.Lock()
_LOG_USERS: dict[str, int] = {}
_LOG_SAVED: dict[str, bool] = {}


class _Keep(logging.Handler):
    def __init__(self, records: list):
        super().__init__(logging.WARNING)
        self.records = records

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


@contextlib.contextmanager
def captured_logs(name: str) -> Iterator[list[logging.LogRecord]]:
    """Keep the WARNING+ records of logger ``name`` in a list instead of printing them.

    Nested and concurrent uses (threads) are counted: the logger prints again when the last one
    ends.

    Examples
    --------
    >>> with captured_logs("geoshade.example") as records:
    ...     logging.getLogger("geoshade.example").error("damaged page list")
    >>> [r.getMessage() for r in records]
    ['damaged page list']
    """
    records: list[logging.LogRecord] = []
    handler = _Keep(records)
    logger = logging.getLogger(name)
    with _LOG_LOCK:
        if _LOG_USERS.get(name, 0) == 0:
            _LOG_SAVED[name] = logger.propagate
            logger.propagate = False
        _LOG_USERS[name] = _LOG_USERS.get(name, 0) + 1
        logger.addHandler(handler)
    try:
        yield records
    finally:
        with _LOG_LOCK:
            logger.removeHandler(handler)
            _LOG_USERS[name] -= 1
            if _LOG_USERS[name] == 0:
                logger.propagate = _LOG_SAVED.pop(name, True)
