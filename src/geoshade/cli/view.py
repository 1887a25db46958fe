"""``geoshade view``: the interactive desktop viewer (needs the ``[viewer]`` extra)."""

from __future__ import annotations

from geoshade.api import KINDS
from geoshade.cli.inputs import add_open_args, open_hints, open_settings
from geoshade.errors import InputError
from geoshade.io.formats import case_files
from geoshade.io.output import Outputs
from geoshade.styles.image import parse_size
from geoshade.viewer.app import require_qt


def register(sub) -> None:
    p = sub.add_parser(
        "view", help="interactive viewer: turn, zoom, change range/box/step/strata live",
        description="Open PATH (anything geoshade.load reads) in the interactive viewer. Mouse: "
                    "left drag orbit, right/middle drag pan, wheel zoom. Keys: 1-7 or "
                    "I/T/B/F/K/L/R named views, 0 reset, O ortho, +/- zoom, [ ] vertical "
                    "exaggeration, S or Ctrl+S screenshot, H help.")
    p.add_argument("path", nargs="?", metavar="PATH", help="file or folder to open")
    p.add_argument("--screenshot", metavar="OUT.png",
                   help="draw the first frame, save it as PNG and exit (no display needed)")
    add_open_args(p, size="900x650")
    p.set_defaults(func=run)


def run(args) -> int:

    if not args.path and not args.demo:
        raise InputError("view: give a PATH to open, or --demo")
    if args.demo not in (True, False) and args.demo not in KINDS:
        raise InputError(f"--demo: unknown part {args.demo!r}; expected one of {', '.join(KINDS)}")
    settings = open_settings(args)
    size = parse_size(settings.pop("size", "900x650"))   # the 3D view's size
    view, ortho = settings.pop("view", "iso"), bool(settings.pop("ortho", False))
    if args.screenshot:  # checked before any work: not an input, a writable folder, .png

        Outputs({"--screenshot": args.screenshot}, case_files(args.path),
                {"--screenshot": (".png",)})
    kind, hints = open_hints(args)
    require_qt()
    from geoshade.viewer.window import run_viewer

    sources = []
    if args.path:
        sources.append({"source": args.path, "kind": kind, "hints": hints,
                        "settings": settings})
    rc = run_viewer(sources, demo=args.demo, screenshot=args.screenshot, size=size,
                    view=view, ortho=ortho)
    if args.screenshot and rc == 0:
        print(f"{args.screenshot}: {size[0]}x{size[1]} first frame")
    return rc
