"""``geoshade info PATH`` and ``geoshade info --gl``."""

from __future__ import annotations

import json
from pathlib import Path

from geoshade.cli.main import add_volume_args, volume_hints
from geoshade.cli.progress import progress_bar
from geoshade.errors import InputError


def register(sub) -> None:
    p = sub.add_parser("info", help="describe a data file, or the OpenGL renderer (--gl)")
    p.add_argument("path", nargs="?", metavar="PATH", help="any file geoshade.load reads")
    p.add_argument("--gl", action="store_true", help="print the OpenGL renderer and its limits")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    add_volume_args(p)
    p.set_defaults(func=run)


def run(args) -> int:
    if args.gl:
        from geoshade.render.context import capabilities, format_capabilities, get_context

        caps = capabilities(get_context())
        print(json.dumps(caps, indent=2) if args.json else format_capabilities(caps))
        if not args.path:
            return 0
    if not args.path:
        raise InputError("info: give a PATH to describe, or --gl")
    from geoshade.io import load
    from geoshade.io.describe import describe, format_description

    # GRDECL and decks report bytes read, EGRID cases the report steps they load
    unit = "steps" if Path(args.path).suffix.lower() == ".egrid" else "bytes"
    with progress_bar(f"reading {Path(args.path).name}", unit=unit) as cb:
        model = load(args.path, progress=cb, **volume_hints(args))
    d = describe(model)
    print(json.dumps(d, indent=2) if args.json else format_description(d))
    return 0
