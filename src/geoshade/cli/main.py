"""``geoshade`` command line: parse, call one public function, turn errors into one line."""

from __future__ import annotations

import argparse
import sys
import warnings

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
                   help="raw files: voxels along x, y, z (x varies fastest)")
    p.add_argument("--dtype", help="raw files: uint8, uint16, int16, float32, ...")
    p.add_argument("--endian", choices=("little", "big"), default="little",
                   help="raw files: byte order (little)")
    p.add_argument("--spacing", type=float, nargs=3, metavar=("DX", "DY", "DZ"),
                   help="voxel size (overrides the file's)")


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
    return hints


#: subcommand modules of geoshade.cli, each with ``register(subparsers)``; a new part adds its
#: module name here
SUBCOMMANDS = ("demo", "info", "core", "bench", "iso", "grid", "stacks", "view")


def build_parser() -> argparse.ArgumentParser:
    import importlib

    parser = argparse.ArgumentParser(
        prog="geoshade",
        description="Real-time GPU visualization of very large subsurface data.")
    parser.add_argument("--version", action="version",
                        version=f"%(prog)s {importlib.import_module('geoshade').__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in SUBCOMMANDS:
        importlib.import_module(f"geoshade.cli.{name}").register(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            rc = args.func(args) or 0
        except GeoshadeError as err:
            print(f"geoshade: error: {err}", file=sys.stderr)
            rc = err.exit_code
        except KeyboardInterrupt:
            print("geoshade: interrupted", file=sys.stderr)
            rc = 130
        finally:
            for w in caught:
                if issubclass(w.category, UserWarning | FutureWarning):
                    print(f"geoshade: warning: {w.message}", file=sys.stderr)
    return rc


if __name__ == "__main__":
    sys.exit(main())
