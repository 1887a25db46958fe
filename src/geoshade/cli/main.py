"""``geoshade`` command line: parse, call one public function, turn errors into one line."""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

from geoshade.errors import GeoshadeError

RENDER_VIEWS = ("iso", "top", "bottom", "front", "back", "left", "right")


def add_render_args(p: argparse.ArgumentParser) -> None:
    """The options every render subcommand takes (DESIGN.md, public surface)."""
    p.add_argument("-o", "--output", required=True, metavar="OUT.png", help="PNG to write")
    p.add_argument("--size", default="1024x768", metavar="WxH", help="image size (1024x768)")
    p.add_argument("--view", default="iso", choices=RENDER_VIEWS, help="named view (iso)")
    p.add_argument("--azimuth", type=float, default=None, help="degrees, overrides the view")
    p.add_argument("--elevation", type=float, default=None, help="degrees, overrides the view")
    p.add_argument("--zoom", type=float, default=1.0, help="zoom factor (1 = whole box)")
    p.add_argument("--ortho", action="store_true", help="orthographic projection")
    p.add_argument("--transparent", action="store_true", help="background alpha 0")
    p.add_argument("--stats", metavar="FILE.json", help="write render statistics as JSON")


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
SUBCOMMANDS = ("demo", "info", "core", "bench", "iso", "grid", "stacks", "view")


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
    import math

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
    import importlib

    parser = Parser(
        prog="geoshade",
        description="Real-time GPU visualization of very large subsurface data.")
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


#: exit codes of what is not bad input: a closed stdout (as SIGPIPE), an OS error, a bug
EXIT_PIPE, EXIT_OS, EXIT_BUG = 141, 74, 70


def _crash_report(exc: BaseException, argv) -> Path | None:
    """Write the traceback of an unexpected exception to a file; its path (None if that
    fails too)."""
    import tempfile
    import time
    import traceback

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
    what = err.strerror or type(err).__name__
    name = err.filename if err.filename is not None else ""
    return f"{name}: {what.lower()}" if name else what


def _quiet_stdout() -> None:
    """After a closed pipe: send what is left of stdout nowhere (no error at exit)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


def main(argv=None) -> int:
    """Run one command; every failure ends in one ``geoshade: error:`` line and an exit code:
    2 bad input (3 no OpenGL, 4 not enough GPU or host memory), 74 an OS error, 75 a store
    another ingest is writing, 130 interrupted, 141 a closed stdout (quietly), 70 a bug (the
    traceback goes to a file, or to stderr with ``--debug``)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    debug = bool(getattr(args, "debug", False))
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
        except KeyboardInterrupt:
            print("geoshade: interrupted", file=sys.stderr)
            rc = 130
        except MemoryError:
            print("geoshade: error: out of memory: the data does not fit into this machine's "
                  "memory (use a --box, a coarser --level, or a machine with more memory)",
                  file=sys.stderr)
            rc = 4
        except OSError as err:
            print(f"geoshade: error: {_os_error_line(err)}", file=sys.stderr)
            rc = EXIT_OS
        except Exception as exc:  # a bug: one line, the traceback in a file
            if debug:
                import traceback

                traceback.print_exception(exc, file=sys.stderr)
            where = None if debug else _crash_report(exc, argv)
            first = (str(exc).strip().splitlines() or [""])[0][:200]
            tail = ("the traceback is above" if debug else
                    f"the traceback is in {where}" if where else "run with --debug to see it")
            print(f"geoshade: error: internal error ({type(exc).__name__}: {first}); this is a "
                  f"bug, please report it: {tail}", file=sys.stderr)
            rc = EXIT_BUG
        finally:
            for w in caught:
                if issubclass(w.category, UserWarning | FutureWarning):
                    print(f"geoshade: warning: {w.message}", file=sys.stderr)
    return rc


if __name__ == "__main__":
    sys.exit(main())
