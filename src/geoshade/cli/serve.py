"""``geoshade serve``: the viewer in a web browser (needs the ``[web]`` extra).

It opens files with the same input options as ``geoshade view`` (:mod:`geoshade.cli.inputs`):
the part, raw-volume and deck hints, the camera and the part settings every tab starts from.
"""

from __future__ import annotations

from geoshade.cli.inputs import add_open_args, open_hints, open_settings
from geoshade.errors import InputError
from geoshade.styles.image import parse_size
from geoshade.web import serve


def register(sub) -> None:
    p = sub.add_parser(
        "serve", help="show files in a web browser, drawn on this machine's GPU",
        description="Serve PATH... to web browsers: pictures are drawn here (EGL, no display "
                    "needed) and streamed to the page. Listens on 127.0.0.1 unless --host says "
                    "otherwise; the address printed at start carries a random token, and "
                    "requests without it are refused (the page then drops it from the address "
                    "and keeps a cookie only this server receives). Only the files named here "
                    "(and, with --root, the files under that folder) can be opened from the "
                    "browser; FIFOs, devices and link loops never. Ctrl-C or SIGTERM stops it. "
                    "Threat model and limits: the user guide, 'In the browser'. "
                    "Tabs share the loaded data; each has its own camera and options. The "
                    "input options are those of geoshade view; they apply to every file "
                    "opened (a hint a file type does not take is refused when it is opened).")
    p.add_argument("paths", nargs="*", metavar="PATH", help="files or stores to show")
    p.add_argument("--root", metavar="DIR", help="a folder whose files may be opened too")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (127.0.0.1: this machine only; 0.0.0.0: every "
                        "network; anyone with the token can then see the files)")
    p.add_argument("--port", type=int, default=8765, help="port (8765; 0: a free one)")
    add_open_args(p, size="900x650")
    p.set_defaults(func=run)


def run(args) -> int:

    if not 0 <= args.port <= 65535:
        raise InputError(f"--port: expected 0..65535, got {args.port}")
    kind, hints = open_hints(args)
    settings = open_settings(args)
    size = parse_size(settings.pop("size", "900x650"))   # until the page says its own
    camera = {"view": settings.pop("view", "iso"), "ortho": bool(settings.pop("ortho", False))}
    serve(args.paths, root=args.root, host=args.host, port=args.port, size=size,
          settings=settings, kind=kind, hints=hints, camera=camera, demo=args.demo)
    return 0
