"""``geoshade`` command line: parse, call one public function, turn errors into one line."""

from __future__ import annotations

import argparse
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

from geoshade.errors import (
    EXIT_BUG,
    EXIT_INTERRUPTED,
    EXIT_OS,
    EXIT_PIPE,
    GeoshadeError,
    exit_codes_text,
    terminal_safe,
)


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
    escaped on a terminal (and always on stderr), so a file cannot clear the screen, set the
    window title or write the clipboard; an OS error writing it names the stream."""

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
        try:
            tty = stream.isatty()
        except (OSError, ValueError, AttributeError):
            tty = False
        if not isinstance(stream, _Stream):
            setattr(sys, name, _Stream(stream, label, tty or name == "stderr"))
    return saved


def _quiet_libraries(debug: bool) -> None:
    """Library loggers (dask.distributed's ERROR on a killed worker, asyncio's "Task was
    destroyed" on Ctrl-C) stay silent: geoshade says what happened in its own line."""

    if debug:
        return
    for name in ("distributed", "asyncio", "tornado", "bokeh", "numcodecs", "zarr"):
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


def main(argv=None) -> int:
    """Run one command; every failure ends in one ``geoshade: error:`` line and its own exit
    code (:data:`geoshade.errors.EXIT_CODES`, listed by ``geoshade --help``): 2 bad input, 3 no
    OpenGL, 4 not enough GPU memory, 6 not enough host memory, 74 an OS error, 75 a store
    another ingest is writing, 130 interrupted, 141 a closed stdout (quietly), 70 a bug (the
    traceback goes to a file, or to stderr with ``--debug``)."""
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
            print("geoshade: error: out of memory: the data does not fit into this machine's "
                  "memory (use a --box, a coarser --level, or a machine with more memory)",
                  file=sys.stderr)
            rc = 4
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
        except Exception as exc:  # a bug: one line, the traceback in a file
            if debug:
                traceback.print_exception(exc, file=sys.stderr)
            where = None if debug else _crash_report(exc, argv)
            first = (str(exc).strip().splitlines() or [""])[0][:200]
            tail = ("the traceback is above" if debug else
                    f"the traceback is in {where}" if where else "run with --debug to see it")
            print(f"geoshade: error: internal error ({type(exc).__name__}: "
                  f"{first}); this is a bug, please report it: {tail}",
                  file=sys.stderr)
            rc = EXIT_BUG
        finally:
            _print_warnings(caught)
    if rc == 130:  # interrupted: what dying tasks warn at exit (coroutines never awaited) is noise
        warnings.simplefilter("ignore")
    return rc


def _quiet_exit() -> None:
    """After Ctrl-C: what threads and event loops print while dying goes nowhere (the one
    ``interrupted`` line is already out)."""

    threading.excepthook = lambda args: None
    sys.unraisablehook = lambda unraisable: None


if __name__ == "__main__":
    sys.exit(main())
