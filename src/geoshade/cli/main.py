"""``geoshade`` command line: parse, call one public function, turn errors into one line."""

from __future__ import annotations

import argparse
import ctypes
import importlib
import logging
import math
import os
import re
import sys
import tempfile
import threading
import time
import traceback
import warnings
from pathlib import Path

try:
    import resource
except ImportError:  # pragma: no cover  (not on Unix)
    resource = None  # type: ignore[assignment]

from geoshade.errors import (
    EXIT_BUG,
    EXIT_INTERRUPTED,
    EXIT_MEMORY,
    EXIT_OS,
    EXIT_PIPE,
    GeoshadeError,
    exit_codes_text,
    terminal_safe,
)
from geoshade.scheduler import quiet_cluster_logs


def add_volume_args(p: argparse.ArgumentParser) -> None:
    """Hints for headerless raw volumes."""
    p.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                   help="raw files: voxels along x, y, z (x varies fastest); default: the cube "
                        "the file size allows, or a .nhdr/.mhd header beside the file")
    p.add_argument("--dtype", help="raw files: uint8, uint16, int16, float32, ...")
    p.add_argument("--endian", choices=("little", "big"), default="little",
                   help="raw files: byte order (little)")
    p.add_argument("--spacing", type=float, nargs=3, metavar=("DX", "DY", "DZ"),
                   help="voxel size (overrides the file's)")
    p.add_argument("--unit", default=None, metavar="UNIT",
                   help="length unit of the spacing (um, mm, ...; overrides the file's): the "
                        "porosity plot's axis, the CSV's column and the JSON use it")


def volume_hints(args) -> dict:
    hints = {}
    if getattr(args, "shape", None):
        hints["shape"] = tuple(args.shape)
    if getattr(args, "dtype", None):
        hints["dtype"] = args.dtype
    if getattr(args, "shape", None) or getattr(args, "dtype", None):
        hints["endian"] = args.endian
    if getattr(args, "spacing", None):
        hints["spacing"] = tuple(args.spacing)
    if getattr(args, "unit", None):
        hints["unit"] = args.unit
    return hints


#: subcommand modules of geoshade.cli, each with ``register(subparsers)``; a new part adds its
#: module name here
SUBCOMMANDS = ("demo", "info", "core", "bench", "iso", "grid", "stacks", "view", "serve",
               "summary")


class Parser(argparse.ArgumentParser):
    """argparse, with a bad argument reported in one line (no usage block; ``--help`` has it)."""

    def error(self, message: str):
        self.exit(2, f"geoshade: error: {self.prog}: {message} (see {self.prog} --help)\n")


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1."""
    try:
        v = int(text)
    except ValueError:
        v = 0
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}")
    return v


def finite_float(text: str) -> float:
    """argparse type: a finite number (not nan or inf)."""

    try:
        v = float(text)
    except ValueError:
        v = math.nan
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return v


def positive_float(text: str) -> float:
    """argparse type: a finite number > 0."""
    v = finite_float(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return v


def build_parser() -> argparse.ArgumentParser:

    parser = Parser(
        prog="geoshade",
        description="Real-time GPU visualization of very large subsurface data.",
        epilog="exit codes:\n" + exit_codes_text(),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version",
                        version=f"%(prog)s {importlib.import_module('geoshade').__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="print the traceback of an unexpected error (a bug) instead of "
                             "writing it to a file")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in SUBCOMMANDS:
        importlib.import_module(f"geoshade.cli.{name}").register(sub)
    return parser




def _crash_report(exc: BaseException, argv) -> Path | None:
    """Write the traceback of an unexpected exception to a file; its path (None if that
    fails too)."""

    try:
        fd, name = tempfile.mkstemp(prefix=f"geoshade-traceback-{time.strftime('%Y%m%d-%H%M%S')}-",
                                    suffix=".txt")
        with os.fdopen(fd, "w") as fh:
            fh.write(f"geoshade {' '.join(str(a) for a in (argv or sys.argv[1:]))}\n\n")
            traceback.print_exception(exc, file=fh)
        return Path(name)
    except OSError:
        return None


def _os_error_line(err: OSError) -> str:
    """``FILE: what`` for an OS error (what it says when it names no file)."""
    what = err.strerror or (str(err).strip().splitlines() or [""])[0] or type(err).__name__
    name = err.filename if err.filename is not None else ""
    return f"{name}: {what[:1].lower()}{what[1:]}" if name else what


class _Stream:
    """The CLI's stdout/stderr: control characters (from well names, units, file text) are
    escaped, on a terminal and in a pipe (whose end is often one), so a file cannot clear the
    screen, set the window title or write the clipboard; an OS error writing it names the
    stream. The progress bar keeps its own carriage returns (its label is escaped where it is
    made, :mod:`geoshade.cli.progress`)."""

    def __init__(self, stream, label: str, escape: bool):
        self._stream, self._label, self._escape = stream, label, escape

    def _named(self, err: OSError) -> OSError:
        if err.filename is None:
            err.filename = self._label
        return err

    def write(self, text: str) -> int:
        escape = self._escape and not _from_progress_bar()
        try:
            self._stream.write(terminal_safe(text) if escape else text)
        except OSError as err:
            raise self._named(err) from None
        return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except OSError as err:
            raise self._named(err) from None

    def __getattr__(self, name):
        return getattr(self._stream, name)


def _from_progress_bar() -> bool:
    """Whether the write comes from the progress bar (tqdm: its own ``\\r`` and cursor
    moves, no text from files but the description geoshade gives it)."""
    frame = sys._getframe(2)
    for _ in range(3):
        if frame is None:
            return False
        if str(frame.f_globals.get("__name__", "")).startswith("tqdm"):
            return True
        frame = frame.f_back
    return False


def _guard_streams() -> tuple:
    """A closed stdout/stderr (``>&-``) goes to /dev/null; both are wrapped in :class:`_Stream`.
    Returns the streams to put back."""
    saved = (sys.stdout, sys.stderr)
    for name, label in (("stdout", "<standard output>"), ("stderr", "<standard error>")):
        if getattr(sys, name) is None:
            setattr(sys, name, open(os.devnull, "w"))  # lives for the process
        stream = getattr(sys, name)
        if not isinstance(stream, _Stream):  # escaped in a pipe too: `| head`, `| less -R` and
            setattr(sys, name, _Stream(stream, label, True))  # `| tee` reach a terminal
    return saved


def _quiet_libraries(debug: bool) -> None:
    """Library loggers (dask.distributed's ERROR on a killed worker, asyncio's "Task was
    destroyed" on Ctrl-C) stay silent: geoshade says what happened in its own line."""

    if debug:
        return
    quiet_cluster_logs()   # dask.distributed's, again after its import (which resets them)
    for name in ("asyncio", "tornado", "bokeh", "numcodecs", "zarr"):
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def _print_warnings(caught) -> None:
    """One line per warning; many alike (same category and first words) are counted in one."""

    groups: dict[tuple, list[str]] = {}
    for w in caught:
        if issubclass(w.category, UserWarning | FutureWarning):
            text = str(w.message)  # alike: the same but for numbers and quoted names
            shape = re.sub(r"\d+", "#", re.sub(r"'[^']*'|\"[^\"]*\"", "'…'", text))
            groups.setdefault((w.category, shape), []).append(text)
    for texts in groups.values():
        for text in texts[:3]:
            print(f"geoshade: warning: {text}", file=sys.stderr)
        if len(texts) > 3:
            print(f"geoshade: warning: ... and {len(texts) - 3} more warnings like these",
                  file=sys.stderr)


def _quiet_stdout() -> None:
    """After a closed pipe: send what is left of stdout nowhere (no error at exit)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


#: what the dynamic loader says when a library cannot be mapped for want of address space
_NO_MAP = re.compile(r"failed to map segment|cannot allocate memory", re.I)
#: glibc's mallopt parameter of the most malloc arenas (each thread's arena reserves 64 MiB)
_M_ARENA_MAX = -8


def _address_limit() -> str | None:
    """The address-space or data limit of this process (``ulimit -v``, ``ulimit -d``) as
    text, the smaller one; None when there is none."""
    if resource is None:  # pragma: no cover
        return None
    found = None
    for name, what in (("RLIMIT_AS", "ulimit -v"), ("RLIMIT_DATA", "ulimit -d")):
        try:
            soft = resource.getrlimit(getattr(resource, name))[0]
        except (AttributeError, OSError, ValueError):
            continue
        if soft != resource.RLIM_INFINITY and soft >= 0 and (found is None or soft < found[0]):
            found = (soft, f"{what}, {name}")
    if found is None:
        return None
    return f"the address-space limit ({found[1]}) of {found[0] / 2**20:,.0f} MiB"


def _fit_address_space() -> None:
    """Under an address-space limit, before numpy and the BLAS libraries load: at most two
    malloc arenas and one BLAS thread. Every thread's arena and stack take address space, and
    a BLAS library whose threads cannot start (scipy's OpenBLAS) hung in its loader instead
    of failing; nothing changes without a limit."""
    if _address_limit() is None:
        return
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(name, "1")
    try:
        ctypes.CDLL(None).mallopt(_M_ARENA_MAX, 2)
    except (OSError, AttributeError):  # not glibc
        pass


def _cgroup_limit() -> str | None:
    """The memory limit of this process's cgroup (``memory.max``) as text; None without one."""
    try:
        text = Path("/sys/fs/cgroup/memory.max").read_text().strip()
    except OSError:
        return None
    if not text.isdigit():   # "max": no limit
        return None
    return f"the cgroup memory limit (memory.max) of {int(text) / 2**20:,.0f} MiB"


def _memory_line(args, why: str) -> str:
    """The one line of an allocation or a thread that failed: the limit's figure (``ulimit
    -v``/``-d``, a cgroup's ``memory.max``) and what to do."""
    named = getattr(args, "input", None) or getattr(args, "path", None)
    head = f"{named}: " if isinstance(named, str) else ""
    limit = _address_limit() or _cgroup_limit()
    if limit is not None:
        return f"{head}out of memory ({why}) under {limit}; raise the limit"
    return (f"{head}out of memory ({why}): the data does not fit into this machine's memory "
            "(use a --box, a coarser --level, or a machine with more memory)")


def main(argv=None) -> int:
    """Run one command; every failure ends in one ``geoshade: error:`` line and its own exit
    code (:data:`geoshade.errors.EXIT_CODES`, listed by ``geoshade --help``): 2 bad input, 3 no
    OpenGL, 4 not enough GPU memory, 6 not enough host memory, 74 an OS error, 75 a store
    another ingest is writing, 130 interrupted, 141 a closed stdout (quietly), 70 a bug (the
    traceback goes to a file, or to stderr with ``--debug``)."""
    _fit_address_space()
    saved = _guard_streams()
    try:
        return _main(argv)
    finally:
        sys.stdout, sys.stderr = saved


def _main(argv) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    debug = bool(getattr(args, "debug", False))
    _quiet_libraries(debug)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            rc = args.func(args) or 0
            sys.stdout.flush()
        except GeoshadeError as err:
            print(f"geoshade: error: {err}", file=sys.stderr)
            rc = err.exit_code
        except BrokenPipeError:
            _quiet_stdout()
            rc = EXIT_PIPE
        except KeyboardInterrupt as exc:  # a command may say what is kept (an ingest)
            said = f"; {exc.args[0]}" if exc.args and isinstance(exc.args[0], str) else ""
            print(f"geoshade: interrupted{said}", file=sys.stderr)
            rc = EXIT_INTERRUPTED
            _quiet_exit()
        except MemoryError:
            print(f"geoshade: error: {_memory_line(args, 'an allocation failed')}",
                  file=sys.stderr)
            rc = EXIT_MEMORY
        except OSError as err:
            if err.filename == "<standard output>":
                _quiet_stdout()
            print(f"geoshade: error: {_os_error_line(err)}", file=sys.stderr)
            rc = EXIT_OS
        except RecursionError:  # a crafted input nested deeper than a reader guards
            named = getattr(args, "input", None) or getattr(args, "path", None)
            print(f"geoshade: error: {named + ': ' if isinstance(named, str) else ''}nested too "
                  "deeply to read (crafted or damaged: JSON or lists thousands of levels deep)",
                  file=sys.stderr)
            rc = 2
        except (RuntimeError, ImportError) as exc:
            # no address space left for a thread's stack and arena, or to map a library
            why = ("a thread could not start" if "can't start new thread" in str(exc) else
                   "a library could not be loaded" if _NO_MAP.search(str(exc)) else None)
            if why is None:
                rc = _bug(exc, argv, debug)
            else:
                print(f"geoshade: error: {_memory_line(args, why)}", file=sys.stderr)
                rc = EXIT_MEMORY
        except Exception as exc:  # a bug: one line, the traceback in a file
            rc = _bug(exc, argv, debug)
        finally:
            _print_warnings(caught)
    if rc == 130:  # interrupted: what dying tasks warn at exit (coroutines never awaited) is noise
        warnings.simplefilter("ignore")
    return rc


def _bug(exc: BaseException, argv, debug: bool) -> int:
    """One line for a bug, the traceback in a file (or on stderr with ``--debug``)."""
    if debug:
        traceback.print_exception(exc, file=sys.stderr)
    where = None if debug else _crash_report(exc, argv)
    first = (str(exc).strip().splitlines() or [""])[0][:200]
    tail = ("the traceback is above" if debug else
            f"the traceback is in {where}" if where else "run with --debug to see it")
    print(f"geoshade: error: internal error ({type(exc).__name__}: {first}); this is a bug, "
          f"please report it: {tail}", file=sys.stderr)
    return EXIT_BUG


def _quiet_exit() -> None:
    """After Ctrl-C: what threads and event loops print while dying goes nowhere (the one
    ``interrupted`` line is already out)."""

    threading.excepthook = lambda args: None
    sys.unraisablehook = lambda unraisable: None


if __name__ == "__main__":
    sys.exit(main())
