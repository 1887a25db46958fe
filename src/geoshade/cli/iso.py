"""``geoshade iso render|animate``: the saturation isosurface of a field, one step or all."""

from __future__ import annotations

import argparse

from geoshade.cli.main import finite_float, positive_float
from geoshade.cli.params import add_param_arg, param_hint
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import (
    add_camera_args,
    add_color_args,
    add_render_args,
    add_skip_missing_arg,
    case_inputs,
    color_options,
    deprecated_flag,
    model_inputs,
    run_render,
    skip_missing_hint,
)
from geoshade.errors import InputError
from geoshade.iso import DEFAULT_PATCH_LEVEL, PAPER_PATCH_LEVEL
from geoshade.iso.api import field_of
from geoshade.iso.options import IsoOptions
from geoshade.models.grid import CornerPointGrid


def _field_args(p) -> None:
    p.add_argument("--level", type=finite_float, required=True, metavar="S",
                   help="the isosurface value S* (a node is below it when S < S*)")
    p.add_argument("--keyword", metavar="NAME",
                   help="array / variable / restart keyword to show (ECLIPSE default SWAT; "
                        "e.g. SGAS, PRESSURE)")
    p.add_argument("--color-by", metavar="NAME",
                   help="colour the surface by another quantity of the file (e.g. PRESSURE)")
    add_color_args(p, what="--color-by (default: its range at the step shown; animate: over "
                            "every step animated)")
    p.add_argument("--spacing", type=finite_float, nargs=3, metavar=("DX", "DY", "DZ"),
                   help="node spacing of a regular grid (overrides the file's)")
    p.add_argument("--exaggeration", type=finite_float, default=None,
                   help="vertical exaggeration (thin reservoirs), 1 = true geometry")
    p.add_argument("--z-scale", dest="z_scale", type=finite_float, default=None,
                   help=argparse.SUPPRESS)  # the old name of --exaggeration
    p.add_argument("--patch-level", type=int, default=None, metavar="L",
                   help="patch-quads of (L+1)² cells, 1..64 (default 8; the paper: 64)")
    p.add_argument("--no-skip", action="store_true",
                   help="march every patch, also those whose min/max cannot hold the level")
    p.add_argument("--slice-axis", choices=IsoOptions.choices("slice_axis"), default=None,
                   help="axis the slices of patch-quads are stacked along (default auto: the "
                        "one leaving the fewest cells to march; the paper: z)")
    p.add_argument("--no-mesh-cache", action="store_true",
                   help="march every frame instead of re-drawing the surface captured when it "
                        "was last marched (render; animate draws each step once anyway)")
    p.add_argument("--caps", action="store_true",
                   help="close the surface along inactive (ACTNUM 0), NaN and infinite cells, "
                        "halfway to them (default: open there, as at the grid's boundary)")
    p.add_argument("--paper", action="store_true",
                   help="the paper's method exactly: --patch-level 64 --no-skip --slice-axis z "
                        "--no-mesh-cache")
    add_skip_missing_arg(p)  # a .DATA deck read as grid render reads it
    add_param_arg(p)


def register(sub) -> None:
    p = sub.add_parser("iso", help="saturation isosurfaces over time (tessellation marching "
                                   "cubes)")
    isub = p.add_subparsers(dest="iso_command", metavar="ACTION")
    isub.required = True

    r = isub.add_parser("render", help="render the isosurface of one time step")
    r.add_argument("field", metavar="FIELD",
                   help=".npy/.npz (3D or time × 3D), .zarr, netCDF, or an ECLIPSE/OPM case "
                        "(.EGRID/.UNRST/.DATA)")
    _field_args(r)
    r.add_argument("--step", metavar="K",
                   help="time step: index (0-based), -1 for the last (default), R36 for report "
                        "36, or a date YYYY-MM-DD")
    r.add_argument("--mesh", metavar="OUT.ply",
                   help="also write the drawn triangles (.ply, .obj or .stl)")
    add_render_args(r)
    r.set_defaults(func=run_render_cmd)

    a = isub.add_parser("animate", help="render every time step into an .mp4 or .gif")
    a.add_argument("field", metavar="CASE", help="a field with time steps (as for render)")
    _field_args(a)
    a.add_argument("-o", "--output", required=True, metavar="OUT.mp4|.gif")
    a.add_argument("--size", default="1920x1080", metavar="WxH", help="frame size (1920x1080)")
    a.add_argument("--fps", type=positive_float, default=4.0,
                   help="frames (steps) per second (4)")
    add_camera_args(a)
    a.add_argument("--no-annotations", action="store_true",
                   help="bare frames: no title and date, colour bar, axes")
    a.add_argument("--stats", metavar="FILE.json", help="write animation statistics as JSON")
    a.set_defaults(func=run_animate)


def _load(args, step=None):
    """The field of the command: a field file or ECLIPSE/OPM run (``load_field``), or a
    ``.DATA`` deck without its run read as ``grid render`` reads it (``geoshade.io.load``: a
    corner-point grid of static properties) and shown by ``--keyword`` (``field_of``)."""
    from geoshade.io.fields import is_bare_deck, load_field

    if is_bare_deck(args.field):
        from geoshade.io import load

        if args.spacing:
            raise InputError(f"{args.field}: --spacing does not apply to a deck (its geometry "
                             "comes from the deck)")
        with progress_bar(f"reading {args.field}", unit="bytes") as cb:
            grid = load(args.field, progress=cb, **skip_missing_hint(args),
                        **param_hint(args))
        if not isinstance(grid, CornerPointGrid):
            raise InputError(f"{args.field}: not a corner-point grid (got "
                             f"{type(grid).__name__})")

        return field_of(grid, args.keyword, args.color_by)
    if getattr(args, "param", None):
        raise InputError(f"{args.field}: --param applies to a .DATA deck read without its run "
                         "(a field file or an ECLIPSE case carries its own keywords)")
    return load_field(args.field, keyword=args.keyword, step=step, color_by=args.color_by,
                      spacing=tuple(args.spacing) if args.spacing else None)


def _exaggeration(args) -> dict:
    ex = deprecated_flag(args.exaggeration, args.z_scale, "--z-scale", "--exaggeration")
    return {} if ex is None else {"exaggeration": ex}


def _patch_kw(args) -> dict:

    if args.paper:
        level, skip, axis = PAPER_PATCH_LEVEL, False, "z"
    else:
        level, skip, axis = DEFAULT_PATCH_LEVEL, True, "auto"
    return {"patch_level": level if args.patch_level is None else args.patch_level,
            "skip_patches": skip and not args.no_skip,
            "slice_axis": axis if args.slice_axis is None else args.slice_axis,
            "caps": args.caps, **_exaggeration(args)}


def _options(args) -> dict:
    return {"level": args.level, "color_by": args.color_by, **color_options(args),
            **_patch_kw(args)}


def run_render_cmd(args) -> int:
    options = {**_options(args), "step": args.step, "prefetch": False,
               "mesh_cache": not (args.paper or args.no_mesh_cache)}

    def export(view, stats, out) -> None:
        if args.mesh:
            m = view.mesh()
            from geoshade.io.interop.mesh import write_mesh

            write_mesh(out.path("--mesh"), m)
            stats["mesh"] = str(args.mesh)
            stats["mesh_vertices"], stats["mesh_faces"] = m.n_vertices, m.n_faces

    return run_render(args, "iso", lambda: _load(args), options, inputs=[args.field],
                      after=export, outputs={"--mesh": args.mesh},
                      suffixes={"--mesh": (".ply", ".obj", ".stl")})


def run_animate(args) -> int:
    from tqdm import tqdm

    from geoshade import iso
    from geoshade.io.output import Outputs, json_bytes

    with Outputs({"-o": args.output, "--stats": args.stats}, case_inputs(args.field),
                 {"-o": (".mp4", ".gif"), "--stats": (".json",)}) as out:
        field = _load(args)
        out.protect(model_inputs(field))
        bar = tqdm(total=field.nsteps, desc="rendering steps", unit="step", disable=None)

        def progress(done: int, total: int) -> None:
            bar.n = done
            bar.refresh()

        try:
            res = iso.animate(field, args.level, out.path("-o"), size=args.size, fps=args.fps,
                              progress=progress, view=args.view, azimuth=args.azimuth,
                              elevation=args.elevation, zoom=args.zoom, ortho=args.ortho,
                              annotations=not args.no_annotations,
                              **{k: v for k, v in _options(args).items() if k != "level"})
        finally:
            bar.close()
        res["output"] = str(args.output)
        out.put("--stats", json_bytes(res))
        out.commit()
    print(f"{args.output}: {res['frames']} steps at {res['width']}x{res['height']}, "
          f"{res['fps']:g} fps, median {res['frame_ms']:.1f} ms/frame, step switch "
          f"{res['step_switch_ms']:.1f} ms, {res['seconds']:.1f} s in all")
    return 0
