"""``geoshade serve``: the viewer in a web browser (needs the ``[web]`` extra)."""

from __future__ import annotations

from geoshade.errors import InputError
from geoshade.scheduler import Scheduler
from geoshade.styles.image import parse_size
from geoshade.web import serve

KINDS = ("core", "grid", "iso", "stacks")


def register(sub) -> None:
    p = sub.add_parser(
        "serve", help="show files in a web browser, drawn on this machine's GPU",
        description="Serve PATH... to web browsers: pictures are drawn here (EGL, no display "
                    "needed) and streamed to the page. Listens on 127.0.0.1 unless --host says "
                    "otherwise; the address printed at start carries a random token, and "
                    "requests without it are refused. Only the files named here (and, with "
                    "--root, the files under that folder) can be opened from the browser. "
                    "Tabs share the loaded data; each has its own camera and options.")
    p.add_argument("paths", nargs="*", metavar="PATH", help="files or stores to show")
    p.add_argument("--root", metavar="DIR", help="a folder whose files may be opened too")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (127.0.0.1: this machine only; 0.0.0.0: every "
                        "network; anyone with the token can then see the files)")
    p.add_argument("--port", type=int, default=8765, help="port (8765; 0: a free one)")
    p.add_argument("--as", dest="kind", choices=KINDS, help="the part to open every PATH with")
    p.add_argument("--size", default="900x650", metavar="WxH",
                   help="picture size until the page says its own (900x650)")
    p.add_argument("--distributed", action="store_true",
                   help="draw cores and grids on the --scheduler's dask cluster")
    p.add_argument("--scheduler", metavar="ADDRESS|local:N",
                   help="the dask cluster of --distributed")
    p.set_defaults(func=run)


def run(args) -> int:

    if not 0 <= args.port <= 65535:
        raise InputError(f"--port: expected 0..65535, got {args.port}")
    settings: dict = {}
    if args.distributed or args.scheduler:
        if not (args.distributed and args.scheduler):
            raise InputError("--distributed and --scheduler ADDRESS|local:N go together (the "
                             "core or grid drawn on a dask cluster)")

        Scheduler.parse(args.scheduler)   # a bad address is refused before serving
        settings.update(distributed=True, scheduler=args.scheduler)
    serve(args.paths, root=args.root, host=args.host, port=args.port,
          size=parse_size(args.size), settings=settings, kind=args.kind)
    return 0
