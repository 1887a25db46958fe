"""``geoshade stacks convert|render``: stack-based geological models."""

from __future__ import annotations

import time

from geoshade import stacks
from geoshade.cli.main import finite_float
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import add_render_args, run_render
from geoshade.errors import InputError
from geoshade.io.layers.stackfile import SUFFIX, write_stacks
from geoshade.io.output import Outputs, json_bytes


def register(sub) -> None:
    p = sub.add_parser("stacks", help="layered geological models as stacks: convert, render")
    ssub = p.add_subparsers(dest="stacks_command", metavar="ACTION")
    ssub.required = True

    c = ssub.add_parser("convert", help="voxels (GeoTOP netCDF, .npy labels, ...) or DEMs -> "
                        "stacks")
    c.add_argument("input", metavar="INPUT", nargs="?",
                   help=".nc (GeoTOP), .npy/.npz/TIFF/zarr labels, or a DEM (a georeferenced "
                        "one-band GeoTIFF: a terrain model); optional with --surface")
    c.add_argument("-o", "--output", required=True, metavar="MODEL.stacks.npz",
                   help="the stack model to write (versioned .stacks.npz)")
    _add_source_args(c)
    c.add_argument("--no-octree", action="store_true",
                   help="skip building the octree for bytes_octree (large models; always "
                        "skipped for models made from DEMs)")
    c.add_argument("--stats", metavar="FILE.json",
                   help="write statistics (columns, intervals, bytes_voxels, bytes_octree, "
                        "bytes_stacks, ...) as JSON")
    c.set_defaults(func=run_convert)

    r = ssub.add_parser("render", help="ray-cast a stack model (Section 4 of the paper)")
    r.add_argument("model", metavar="MODEL|INPUT",
                   help=".stacks.npz, or anything convert reads (converted on the fly)")
    _add_source_args(r)
    add_render_args(r, "stacks")
    r.set_defaults(func=run_render_cmd)


def _add_source_args(p) -> None:
    p.add_argument("--surface", action="append", default=[], metavar="SURFACE.tif",
                   help="a surface (GeoTIFF DEM) under INPUT, top to bottom, repeatable: a "
                        "layered model, one unit per interval between consecutive surfaces "
                        "(resampled to the first one's grid; a surface above the one before "
                        "it is clamped to it, with a warning)")
    p.add_argument("--base", type=finite_float, default=None, metavar="Z",
                   help="bottom of a terrain model (default: the DEM's lowest height minus 10 "
                        "%% of its relief, at least one level); with several surfaces one more "
                        "unit down to Z")
    p.add_argument("--dz", type=finite_float, default=1.0, metavar="DZ",
                   help="level height of a model made from DEMs (1, in the DEM's height unit)")
    p.add_argument("--top", dest="top_dem", default=None, metavar="DEM.tif",
                   help="a DEM that becomes the top of a voxel model's columns (cut or extended "
                        "to it; placed by its georeference)")
    p.add_argument("--positive", choices=("down", "up"), default=None,
                   help="IRAP surfaces (.gri, .irap, .fgr), whose values state no sign: down "
                        "(depths, RMS's horizons; the default, said as assumed) or up "
                        "(heights)")
    p.add_argument("--variable", default=None,
                   help="netCDF variable: lithok (default) or strat")
    p.add_argument("--empty", type=finite_float, default=None,
                   help="label value meaning empty (NaN always does)")
    p.add_argument("--logs", default="auto", metavar="FILE.parquet|none",
                   help="borehole logs to place into the columns (auto: a boreholes*.parquet "
                        "next to a GeoTOP file)")


def _logs(args):
    v = args.logs
    return None if v is None or str(v).lower() == "none" else v


def _load(args, progress=None):
    empty = args.empty
    if empty is not None and float(empty).is_integer():
        empty = int(empty)
    source = args.__dict__.get("input") or args.__dict__.get("model")
    if source is None and not args.surface:
        raise InputError("stacks convert: give INPUT, or the surfaces with --surface")
    if args.top_dem is not None and (args.surface or (source and _is_dem(source))):
        raise InputError("--top: a DEM top is for a voxel model (GeoTOP, labels); a model made "
                         "from surfaces already has its top")
    return stacks.convert(source, variable=args.variable, empty=empty, boreholes=_logs(args),
                          progress=progress, surfaces=args.surface or None, base=args.base,
                          dz=args.dz, top=args.top_dem, positive=args.positive)


def _is_dem(path) -> bool:
    from geoshade.io.layers.dem import is_georeferenced

    return is_georeferenced(path)


def _source_files(args, source) -> list:
    logs = _logs(args)
    return ([source] if source else []) + list(args.surface) \
        + ([args.top_dem] if args.top_dem else []) + ([logs] if logs not in (None, "auto") else [])


def run_convert(args) -> int:
    inputs = _source_files(args, args.input)
    with Outputs({"-o": args.output, "--stats": args.stats}, inputs,
                 {"-o": (SUFFIX,), "--stats": (".json",)}) as out:
        t0 = time.perf_counter()
        with progress_bar("converting") as cb:
            model = _load(args, cb)
        convert_ms = (time.perf_counter() - t0) * 1000
        with progress_bar("octree") as cb:
            mem = stacks.memory_stats(model, octree=not (args.no_octree
                                                         or model.meta.get("terrain")),
                                      progress=cb)
        write_stacks(out.path("-o"), model)
        stats = _convert_stats(model, mem, convert_ms)
        out.put("--stats", json_bytes(stats))
        out.commit()
    _print_convert(args.output, model, mem, stats)
    return 0


def _convert_stats(model, mem: dict, convert_ms: float) -> dict:
    bh = model.meta.get("boreholes") or {}
    stats = {
        "width": None, "height": None, "method": "convert", "frame_ms": None,
        "gpu_bytes": mem["bytes_stacks"], "columns": model.ncols,
        "intervals": model.nintervals, "max_intervals": model.max_intervals,
        "mrays_per_s": None, "gpu_intervals": mem["gpu_intervals"],
        "bytes_voxels": mem["bytes_voxels"], "bytes_octree": mem.get("bytes_octree"),
        "bytes_stacks": mem["bytes_stacks"], "octree_nodes": mem.get("octree_nodes"),
        "bytes_octree_6_levels": mem.get("bytes_octree_6_levels"),
        "saving_vs_voxels": round(mem["saving_vs_voxels"], 6),
        "convert_ms": round(convert_ms, 3), "borehole_columns": int(model.borehole.sum()),
        "boreholes": bh, "variable": model.meta.get("variable"), "shape": list(model.shape),
        "nlevels": model.nlevels, "crs": model.crs,
    }
    for k in ("base", "dz", "surfaces", "nodata_columns", "crossing_cells", "filled_cells",
              "top_source", "top_columns"):
        if k in model.meta:
            stats[k] = model.meta[k]
    return stats


def _print_convert(output, model, mem: dict, stats: dict) -> None:
    bh = model.meta.get("boreholes") or {}
    oct_txt = ("" if stats["bytes_octree"] is None else
               f", octree {stats['bytes_octree'] / 2**20:.2f} MiB")
    logs_txt = (f"; {bh.get('placed', 0)} borehole logs placed" if bh else "")
    if model.meta.get("terrain") and "base" in model.meta:
        logs_txt += (f"; {len(model.legend)} unit(s) from {model.meta.get('base'):g} up, "
                     f"{model.meta.get('nodata_columns', 0)} nodata columns empty")
    print(f"{output}: {model.shape[0]}×{model.shape[1]} columns, {model.nintervals} "
          f"intervals (max {model.max_intervals}){logs_txt}; voxels "
          f"{stats['bytes_voxels'] / 2**20:.2f} MiB{oct_txt}, stacks "
          f"{stats['bytes_stacks'] / 2**20:.3f} MiB ({100 * mem['saving_vs_voxels']:.1f} % less "
          "than the voxels)")


def run_render_cmd(args) -> int:
    def load():
        with progress_bar("converting") as cb:
            return _load(args, cb)

    return run_render(args, "stacks", load, inputs=_source_files(args, args.model))
