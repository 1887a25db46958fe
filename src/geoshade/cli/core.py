"""``geoshade core render|porosity`` (and ``ingest``, see :mod:`geoshade.cli.ingest`)."""

from __future__ import annotations

import math
import warnings

from geoshade import core
from geoshade.cli import ingest as _big  # ingest, --scheduler, --bricks, --level
from geoshade.cli.main import add_volume_args
from geoshade.cli.options import add_option_args, given_options
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import add_render_args, run_render
from geoshade.compute.voxels.porosity import csv_text
from geoshade.core.options import CoreOptions as C
from geoshade.errors import GeoshadeDeprecationWarning, InputError
from geoshade.io.output import Outputs, json_bytes

#: the core's options ``core porosity`` takes (declared with the View's, one meaning)
POROSITY_OPTIONS = ("select", "box", "roi", "mask", "sample", "scheduler")


def add_store_args(p, render: bool) -> None:
    """How a volume is read beyond its file's own header: an HDF5 dataset, a store's level."""
    p.add_argument("--dataset", metavar="PATH", help="HDF5 files: the dataset to read")
    if render:
        p.add_argument("--level", default=None, metavar="K|auto",
                       help="pyramid level of an ingested store (auto: the finest that fits, "
                            "an overview of the whole core); --box is in that level's voxels")


def parse_select(values, flag: str = "--select"):
    """``--select`` words -> ``(lo, hi)``, ``"auto"`` or None.

    >>> parse_select(["0", "80"]), parse_select(["auto"]), parse_select(None)
    ((0.0, 80.0), 'auto', None)
    """
    if values is None:
        return None
    if len(values) == 1 and str(values[0]).strip().lower() in ("auto", "otsu"):
        return "auto"
    try:
        nums = tuple(float(v) for v in values)
    except ValueError:
        nums = ()
    if len(nums) != 2 or not all(math.isfinite(v) for v in nums):
        raise InputError(f"{flag}: expected two finite numbers LO HI or 'auto', got "
                         f"{' '.join(map(str, values))!r}")
    return nums


def register(sub) -> None:
    p = sub.add_parser("core", help="digital core: render a box of a micro-CT volume, porosity")
    csub = p.add_subparsers(dest="core_command", metavar="ACTION")
    csub.required = True

    r = csub.add_parser("render", help="render the voxels of a box whose values are selected")
    r.add_argument("volume", metavar="VOLUME", help="raw, TIFF (file or folder), .npy, zarr")
    add_volume_args(r)
    add_store_args(r, render=True)
    add_render_args(r, "core")
    r.set_defaults(func=run_render_cmd)

    q = csub.add_parser("porosity", help="pore fraction of a box, total and as a profile")
    q.add_argument("volume", metavar="VOLUME")
    add_volume_args(q)
    add_option_args(q, {"core": C}, only=POROSITY_OPTIONS)
    q.add_argument("--axis", choices=C.choices("porosity"), default="z",
                   help="profile axis (z)")
    q.add_argument("-o", "--output", required=True, metavar="PLOT.png")
    q.add_argument("--csv", metavar="FILE.csv")
    q.add_argument("--json", metavar="FILE.json")
    add_store_args(q, render=False)
    q.set_defaults(func=run_porosity)
    _big.register(csub)


def run_render_cmd(args) -> int:
    with progress_bar("selecting voxels") as cb:
        return run_render(args, "core", lambda: _big.load_volume(args), inputs=[args.volume],
                          progress=cb)


def run_porosity(args) -> int:
    from geoshade.core.plots import porosity_plot

    opts = given_options(args, C)
    if "range" in opts:
        warnings.warn("--range is deprecated for the core: use --select (the values selected)",
                      GeoshadeDeprecationWarning, stacklevel=2)
    select = opts.pop("select", None) or opts.pop("range", None)
    if select is None:
        raise InputError("--select: give the pore values LO HI (e.g. --select 0 80) or auto "
                         "(Otsu's threshold)")
    select = parse_select(select)
    inputs = [args.volume, *([opts["mask"]] if opts.get("mask") else [])]
    with Outputs({"-o": args.output, "--csv": args.csv, "--json": args.json},
                 inputs=inputs, suffixes={"-o": (".png",), "--csv": (".csv",),
                                                 "--json": (".json",)}) as out:
        vol = _big.load_volume(args)
        with progress_bar("porosity") as cb:
            res = core.porosity(vol, select, axis=args.axis, progress=cb, **opts)
        lo, hi = res.range
        porosity_plot(res, out.path("-o"), title=f"{vol.name or args.volume} — {res.quantity}"
                                                 f", values [{lo:g}, {hi:g}]")
        out.put("--csv", csv_text(res).encode("utf-8"))
        out.put("--json", json_bytes(res.to_dict()))
        out.commit()
    print(f"{core.porosity_line(res)}; profile along {args.axis} -> {args.output}")
    for note in res.notes():
        print(f"  {note}")
    return 0
