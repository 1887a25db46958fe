"""``geoshade info PATH`` and ``geoshade info --gl``.

Before anything is read, the memory plan (:func:`geoshade.api.plan`) is made from the file's
header: every route's RAM, address space and GPU bytes and whether it fits this machine (``plan``
section; ``--memory`` and ``--gpu-memory`` set the budgets).  A file whose reading would not fit
is not read: its header and the plan are shown instead.

A deck or GRDECL file is always read with ``skip_missing``, so that one run lists everything
that could be read (size, geometry, units, faults, properties, wells, skipped keywords) and
*every* missing INCLUDE; without ``--skip-missing`` the command then ends with the error a
render would give (exit code 2), with it with one warning.
"""

from __future__ import annotations

import inspect
import json
import warnings
from pathlib import Path

from geoshade.api import plan as make_plan
from geoshade.cli.main import add_volume_args, volume_hints
from geoshade.cli.params import add_param_arg, param_hint
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import add_skip_missing_arg
from geoshade.core import auto_select, thresholds
from geoshade.errors import InputError, MissingExtraError
from geoshade.grid.plan import device_memory, format_plans, gpu_plans, parse_bytes
from geoshade.io import formats, load
from geoshade.io.describe import STATS_MAX_BYTES, describe, format_description
from geoshade.io.fields import load_field
from geoshade.io.layers.dem import describe_georeferenced, is_georeferenced
from geoshade.io.paths import NotEnoughMemoryError
from geoshade.models import VoxelVolume
from geoshade.models.grid import CornerPointGrid


def register(sub) -> None:
    p = sub.add_parser("info", help="describe a data file, or the OpenGL renderer (--gl)")
    p.add_argument("path", nargs="?", metavar="PATH", help="any file geoshade.load reads")
    p.add_argument("--gl", action="store_true", help="print the OpenGL renderer and its limits")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.add_argument("--gpu", action="store_true",
                   help="corner-point grids: the GPU bytes each approach needs for the visible "
                        "faces, and whether they fit the device (nothing is allocated)")
    p.add_argument("--gpu-memory", metavar="SIZE", default=None,
                   help="the device's memory (8G, 512M, bytes) for --gpu and the plan; "
                        "default: nvidia-smi's free memory where there is one")
    p.add_argument("--memory", metavar="SIZE", default=None,
                   help="the RAM budget of the plan (8G, 512M, bytes); default: what this "
                        "machine has available")
    p.add_argument("--keyword", default=None, metavar="NAME",
                   help="describe the field over time NAME as the iso part reads it (a netCDF "
                        "or zarr variable, an npz array, an ECLIPSE restart keyword): its "
                        "nodes, where the file's coordinates place them, its steps and dates")
    add_volume_args(p)
    add_skip_missing_arg(p)
    add_param_arg(p)
    p.set_defaults(func=run)


def _reads_includes(path) -> bool:
    """The reader of ``path``'s row of the format table takes the ``skip_missing`` hint (decks,
    GRDECL files)."""
    fmt = formats.find(path)
    if fmt is None or fmt.domain != "grid":
        return False
    return "skip_missing" in inspect.signature(fmt.function()).parameters


def _volume_thresholds(model) -> dict:
    """``{"threshold": ...}``: the suggested thresholds of a grey-value volume (Otsu and
    multi-Otsu, :func:`geoshade.core.thresholds`), or a note why there are none; ``{}`` for
    other models and labelled volumes."""

    if not isinstance(model, VoxelVolume) or (model.meta or {}).get("legend"):
        return {}
    size = model.data.size * model.dtype.itemsize
    if model.is_lazy and size > STATS_MAX_BYTES:  # declared sizes are not read whole
        return {"threshold": {"note": f"not suggested: {size / 2**30:,.1f} GiB is more than the "
                                      f"{STATS_MAX_BYTES >> 30} GiB info reads"}}

    try:
        with progress_bar("suggesting thresholds", unit="steps") as cb:
            t = thresholds(model, progress=cb)
            d = t.to_dict()
            if t.labels is None:  # what --select auto takes (inside a sample found in air)
                sel, how = auto_select(model, progress=cb)
                d.update(pore_select=list(sel), pore_text=how["text"])
    except (MissingExtraError, InputError) as exc:
        return {"threshold": {"note": str(exc)}}
    return {"threshold": d}


def _gpu_plans(model, args) -> dict:
    """``info --gpu``: every approach's GPU bytes for the grid's visible faces (none made)."""

    if not isinstance(model, CornerPointGrid):
        raise InputError(f"{args.path}: --gpu: expected a corner-point grid (EGRID, GRDECL, "
                         f"a deck), got {type(model).__name__}")
    if args.gpu_memory is not None:
        mem, source = parse_bytes(args.gpu_memory, "--gpu-memory"), "--gpu-memory"
    else:
        mem, source = device_memory()
    with progress_bar("visible faces", unit="steps"):
        plans = gpu_plans(model, gpu_memory=mem)
    plans["memory_source"] = source
    return plans


def _plan(args, hints: dict):
    """The memory plan of ``args.path`` from its header (None: its kind has none)."""
    memory = None if args.memory is None else parse_bytes(args.memory, "--memory")
    gpu = None if args.gpu_memory is None else parse_bytes(args.gpu_memory, "--gpu-memory")
    return make_plan(args.path, memory=memory, gpu_memory=gpu, **hints)


def _not_read(plan) -> bool:
    """Whether reading the file for ``info`` would not fit: its first route (reading it whole:
    a grid file, a stack model, a volume read into memory) does not fit this machine."""
    h = plan.header
    whole = h.kind in ("grid", "stacks") or (h.kind == "volume" and h.storage == "held")
    return whole and plan.first.fits is False


def run(args) -> int:
    if args.gl:
        from geoshade.render.context import capabilities, format_capabilities, get_context

        caps = capabilities(get_context())
        print(json.dumps(caps, indent=2) if args.json else format_capabilities(caps))
        if not args.path:
            return 0
    if not args.path:
        raise InputError("info: give a PATH to describe, or --gl")
    if args.keyword:   # a field over time, read as iso reads it
        field = load_field(args.path, keyword=args.keyword,
                           spacing=tuple(args.spacing) if args.spacing else None)
        d = describe(field)
        print(json.dumps(d, indent=2, default=str) if args.json else format_description(d))
        return 0
    if is_georeferenced(args.path):  # a raster of the terrain rows, or an orthophoto (rasterio)
        d = describe_georeferenced(args.path)
        print(json.dumps(d, indent=2) if args.json else format_description(d))
        return 0
    hints = {**volume_hints(args), **param_hint(args)}
    plan = _plan(args, hints)
    if plan is not None and _not_read(plan):
        d = {"path": args.path, "plan": plan.to_dict()}
        if all(r.fits is False for r in plan.routes):   # no route could ever fit: the
            # routes, then the refusal (exit 6; a route that fits once made is no refusal)
            print(json.dumps(d, indent=2, default=str) if args.json else plan.text())
            raise NotEnoughMemoryError(plan.refusal())
        print(json.dumps(d, indent=2, default=str) if args.json else
              f"{plan.refusal()} (not read)\n{plan.text()}")
        return 0
    lenient = not args.skip_missing and _reads_includes(args.path)
    if args.skip_missing or lenient:
        hints["skip_missing"] = True
    # GRDECL and decks report bytes read, ECLIPSE cases the report steps they load
    fmt = formats.find(args.path)
    unit = "steps" if fmt is not None and fmt.name == "eclipse" else "bytes"
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with progress_bar(f"reading {Path(args.path).name}", unit=unit) as cb:
            model = load(args.path, progress=cb, **hints)
    meta = getattr(model, "meta", None) or {}
    strict = meta.get("strict_error") if lenient else None
    for w in seen:  # what was skipped is said by the error below when it is one
        said = "missing and skipped" in str(w.message) or "IJK index space" in str(w.message)
        if not (strict and said):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    d = describe(model)
    d.update(_volume_thresholds(model))
    plans = _gpu_plans(model, args) if args.gpu else None
    if plans is not None:
        d["gpu_plan"] = plans
    if plan is not None:
        d["plan"] = plan.to_dict()
    print(json.dumps(d, indent=2, default=str) if args.json else format_description(
        {k: v for k, v in d.items() if k not in ("gpu_plan", "plan")}))
    if plan is not None and not args.json:
        print(plan.text())
    if plans is not None and not args.json:

        print(format_plans(plans, plans.get("memory_source", "")))
    if strict:
        raise InputError(strict)
    return 0
