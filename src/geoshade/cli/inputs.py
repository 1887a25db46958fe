"""What the interactive commands open and how: one definition for ``geoshade view`` and
``geoshade serve``.

Both commands take the same input options, defined here once: ``--demo`` (every part's
synthetic data), the part to open with
(``--as``), the reader hints of headerless raw volumes (``--shape --dtype --endian --spacing
--unit``), of decks (``--skip-missing``), of grids (``--param``) and of fields over time
(``--keyword``); the camera they start from (``--view --azimuth --elevation --zoom --ortho``),
``--progressive`` (a coarse preview first);
and the part settings a View opens with (``--select --box --property --step --level`` …).
:func:`open_hints` and :func:`open_settings` turn the parsed arguments into
:func:`geoshade.load` hints and View options.

>>> import argparse
>>> p = argparse.ArgumentParser(); add_open_args(p)
>>> a = p.parse_args(["--shape", "4", "4", "2", "--dtype", "uint8", "--property", "PORO"])
>>> open_hints(a)
(None, {'shape': (4, 4, 2), 'dtype': 'uint8', 'endian': 'little'})
>>> open_settings(a)
{'property': 'PORO'}
"""

from __future__ import annotations

import argparse

from geoshade.api import KINDS
from geoshade.cli.core import parse_select
from geoshade.cli.grid import read_wells
from geoshade.cli.main import add_volume_args, finite_float, volume_hints
from geoshade.cli.params import add_param_arg, param_hint
from geoshade.cli.render import (
    RENDER_VIEWS,
    add_color_args,
    add_skip_missing_arg,
    color_options,
    deprecated_flag,
    skip_missing_hint,
)
from geoshade.core.options import CoreOptions
from geoshade.errors import InputError
from geoshade.grid.options import GridOptions
from geoshade.styles.options import CameraSpec


def add_open_args(p: argparse.ArgumentParser) -> None:
    """The input, camera and part-setting options of ``view`` and ``serve``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser (its ``PATH`` arguments are its own).
    """
    p.add_argument("--demo", nargs="?", const=True, default=False, metavar="PART",
                   help="the built-in synthetic data of every part, no file needed (PART "
                        f"first: {', '.join(KINDS)})")
    p.add_argument("--as", dest="kind", choices=KINDS,
                   help="the part to open with (iso: a field over time, via load_field)")
    p.add_argument("--view", default=CameraSpec().view, choices=RENDER_VIEWS,
                   help="named view (iso)")
    p.add_argument("--azimuth", type=finite_float, help="degrees, overrides the view")
    p.add_argument("--elevation", type=finite_float, help="degrees, overrides the view")
    p.add_argument("--zoom", type=finite_float, default=CameraSpec().zoom,
                   help="zoom factor (1 = whole model)")
    p.add_argument("--ortho", action="store_true", help="orthographic projection")
    p.add_argument("--progressive", action="store_true",
                   help="a picture at once: a big core box or grid shows a coarse preview first "
                        "(with a progress line), replaced by the full picture when it is ready")
    add_volume_args(p)
    add_skip_missing_arg(p)
    add_param_arg(p)
    g = p.add_argument_group("part settings (each applies to its part)")
    g.add_argument("--select", nargs="+", metavar=("LO|auto", "HI"),
                   help="core: values selected (default: the pore range the file names, else "
                        "every value of its data type); auto: the values up to Otsu's "
                        "threshold")
    g.add_argument("--range", dest="old_select", nargs="+", metavar=("LO|auto", "HI"),
                   help=argparse.SUPPRESS)  # the old name of --select
    g.add_argument("--roi", metavar="cylinder[:CX,CY,R]",
                   help="core: only voxels inside a cylinder along z ('cylinder': fitted to "
                        "the sample)")
    g.add_argument("--mask", metavar="FILE", help="core: only voxels where this mask volume is "
                                                  "nonzero")
    g.add_argument("--box", type=int, nargs=6, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"),
                   help="core: sub-volume")
    g.add_argument("--method", choices=CoreOptions.choices("method"),
                   help="core: drawing method")
    g.add_argument("--porosity", choices=CoreOptions.choices("porosity"), metavar="AXIS",
                   help="core: the porosity profile's axis (z)")
    g.add_argument("--filter", metavar="EXPR",
                   help="grid: show only cells where EXPR holds ('PORO > 0.2')")
    g.add_argument("--wells", metavar="FILE", action="append",
                   help="grid: well trajectories drawn as tubes (as grid render's --wells; "
                        "default: the deck's wells)")
    g.add_argument("--wells-coords", choices=GridOptions.choices("wells_coords"),
                   help="grid: coordinates of the --wells files (grid)")
    g.add_argument("--faults", choices=GridOptions.choices("faults"),
                   help="grid: fault faces shown, highlighted or hidden")
    g.add_argument("--property", help="grid: cell property or expression ('log10(PERMX)')")
    g.add_argument("--step", help="grid, iso: report/time step: index, -1 (last, the default), "
                                  "R36 or a date YYYY-MM-DD")
    g.add_argument("--level", type=finite_float, help="iso: isosurface level S*")
    g.add_argument("--keyword", help="iso: array/variable/restart keyword to read (SWAT)")
    g.add_argument("--color-by", help="iso: colour the surface by this quantity")
    g.add_argument("--drape", metavar="IMAGE", help="stacks: image draped on the top surface")
    add_color_args(g, what="the property (grid), colour-by quantity (iso) or selection (core)")
    g.add_argument("--exaggeration", type=finite_float, help="grid, stacks: vertical exaggeration")
    g.add_argument("--distributed", action="store_true",
                   help="core, grid: draw on the --scheduler cluster (a core's bricks or a "
                        "grid's layer ranges on the workers' GPUs, composited by depth)")
    g.add_argument("--scheduler", metavar="ADDRESS",
                   help="core, grid, with --distributed: the dask.distributed scheduler "
                        "(tcp://HOST:8786) or local:N")


def open_hints(args) -> tuple[str | None, dict]:
    """The part to open with and the :func:`geoshade.load` hints.

    ``--keyword`` reads fields over time, so it makes the part ``iso`` (and is refused with
    another ``--as``); ``--skip-missing`` is refused for fields over time.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed with :func:`add_open_args`.

    Returns
    -------
    kind : str or None
    hints : dict
    """
    kind = args.kind
    hints = {**volume_hints(args), **skip_missing_hint(args), **param_hint(args)}
    if args.keyword:
        if kind not in (None, "iso"):
            raise InputError("--keyword: applies to fields over time (--as iso)")
        kind = "iso"
        hints["keyword"] = args.keyword
    if args.skip_missing and kind == "iso":  # fields over time do not read INCLUDEs
        raise InputError("--skip-missing: applies to decks and GRDECL files opened as grids")
    return kind, hints


def open_settings(args) -> dict:
    """The View options the part settings and camera angles ask for (only those given).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed with :func:`add_open_args`.

    Returns
    -------
    dict
        ``{option: value}`` (``wells`` read from their files).
    """
    s = {}
    sel = deprecated_flag(args.select, args.old_select, "--range", "--select (the values "
                          "selected)", " for the core")
    if sel is not None:
        s["select"] = parse_select(sel, "--select" if args.select is not None else "--range")
    if args.roi is not None:
        s["roi"] = args.roi
    if args.mask is not None:
        s["mask"] = args.mask
    if args.box is not None:
        s["box"] = list(args.box)
    if args.method is not None:
        s["method"] = args.method
    if args.property is not None:
        s["property"] = args.property
    if args.step is not None:
        s["step"] = args.step
    if args.level is not None:
        s["level"] = args.level
    if args.color_by is not None:
        s["color_by"] = args.color_by
    for name in ("porosity", "filter", "faults", "wells_coords"):
        if getattr(args, name) is not None:
            s[name] = getattr(args, name)
    if args.wells:
        s["wells"] = [w for f in args.wells for w in read_wells(f)]
    s.update(color_options(args))
    cam = {k: getattr(args, k) for k in ("azimuth", "elevation")
           if getattr(args, k) is not None}
    if args.zoom != CameraSpec().zoom:
        cam["zoom"] = args.zoom
    s.update(cam)
    if args.drape is not None:
        s["drape"] = args.drape
    if args.exaggeration is not None:
        s["exaggeration"] = args.exaggeration
    if args.progressive:
        s["progressive"] = True
    if args.distributed or args.scheduler:
        if not (args.distributed and args.scheduler):
            raise InputError("--distributed and --scheduler ADDRESS|local:N go together (the "
                             "core or grid drawn on a dask cluster)")
        s.update(distributed=True, scheduler=args.scheduler)
    return s


__all__ = ["add_open_args", "open_hints", "open_settings"]
