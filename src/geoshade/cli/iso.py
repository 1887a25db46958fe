"""``geoshade iso render|animate``: the saturation isosurface of a field, one step or all."""

from __future__ import annotations

from tqdm import tqdm

from geoshade import iso
from geoshade.cli.main import finite_float
from geoshade.cli.options import add_option_args, given_options
from geoshade.cli.params import add_param_arg, param_hint
from geoshade.cli.progress import progress_bar
from geoshade.cli.render import (
    add_animation_args,
    add_render_args,
    add_skip_missing_arg,
    model_inputs,
    run_render,
    skip_missing_hint,
)
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.fields import is_bare_deck, load_field
from geoshade.io.formats import case_files
from geoshade.io.interop.mesh import write_mesh
from geoshade.io.output import Outputs, json_bytes
from geoshade.iso.api import field_of
from geoshade.iso.options import IsoOptions
from geoshade.models.grid import CornerPointGrid


def _field_args(p) -> None:
    """How the field is read (the drawing options are the View's, generated)."""
    g = p.add_argument_group("input")
    g.add_argument("--keyword", metavar="NAME",
                   help="array / variable / restart keyword to show (ECLIPSE default SWAT; "
                        "e.g. SGAS, PRESSURE)")
    g.add_argument("--spacing", type=finite_float, nargs=3, metavar=("DX", "DY", "DZ"),
                   help="node spacing of a regular grid (overrides the file's)")
    add_skip_missing_arg(g)  # a .DATA deck read as grid render reads it
    add_param_arg(g)


#: options an animation sets itself (every step, one frame each)
ANIMATE_SKIPS = ("step", "prefetch", "mesh_cache", "camera")


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
    r.add_argument("--mesh", metavar="OUT.ply",
                   help="also write the drawn triangles (.ply, .obj or .stl)")
    add_render_args(r, "iso")
    r.set_defaults(func=run_render_cmd)

    a = isub.add_parser("animate", help="render every time step into an .mp4 or .gif")
    a.add_argument("field", metavar="CASE", help="a field with time steps (as for render)")
    _field_args(a)
    add_option_args(a, {"iso": IsoOptions}, skip=ANIMATE_SKIPS,
                    defaults={"size": "1920x1080"})
    add_animation_args(a)
    a.set_defaults(func=run_animate)


def _load(args, step=None):
    """The field of the command: a field file or ECLIPSE/OPM run (``load_field``), or a
    ``.DATA`` deck without its run read as ``grid render`` reads it (``geoshade.io.load``: a
    corner-point grid of static properties) and shown by ``--keyword`` (``field_of``)."""

    if is_bare_deck(args.field):
        if args.spacing:
            raise InputError(f"{args.field}: --spacing does not apply to a deck (its geometry "
                             "comes from the deck)")
        with progress_bar(f"reading {args.field}", unit="bytes") as cb:
            grid = load(args.field, progress=cb, **skip_missing_hint(args),
                        **param_hint(args))
        if not isinstance(grid, CornerPointGrid):
            raise InputError(f"{args.field}: not a corner-point grid (got "
                             f"{type(grid).__name__})")

        return field_of(grid, args.keyword, getattr(args, "color_by", None))
    if getattr(args, "param", None):
        raise InputError(f"{args.field}: --param applies to a .DATA deck read without its run "
                         "(a field file or an ECLIPSE case carries its own keywords)")
    return load_field(args.field, keyword=args.keyword, step=step,
                      color_by=getattr(args, "color_by", None),
                      spacing=tuple(args.spacing) if args.spacing else None)


def run_render_cmd(args) -> int:
    def export(view, stats, out) -> None:
        if args.mesh:
            m = view.mesh()

            write_mesh(out.path("--mesh"), m)
            stats["mesh"] = str(args.mesh)
            stats["mesh_vertices"], stats["mesh_faces"] = m.n_vertices, m.n_faces

    # one picture: nothing to prepare ahead (the picture is the same with it)
    return run_render(args, "iso", lambda: _load(args), {"prefetch": False},
                      inputs=[args.field], after=export, outputs={"--mesh": args.mesh},
                      suffixes={"--mesh": (".ply", ".obj", ".stl")})


def run_animate(args) -> int:
    with Outputs({"-o": args.output, "--stats": args.stats}, case_files(args.field),
                 {"-o": (".mp4", ".gif"), "--stats": (".json",)}) as out:
        field = _load(args)
        out.protect(model_inputs(field))
        bar = tqdm(total=field.nsteps, desc="rendering steps", unit="step", disable=None)

        def progress(done: int, total: int) -> None:
            bar.n = done
            bar.refresh()

        opts = {"size": "1920x1080", **given_options(args, IsoOptions)}
        try:
            res = iso.animate(field, opts.pop("level", None), out.path("-o"), fps=args.fps,
                              steps=args.steps, progress=progress,
                              **opts)
        finally:
            bar.close()
        res["output"] = str(args.output)
        out.put("--stats", json_bytes(res))
        out.commit()
    print(f"{args.output}: {res['frames']} steps at {res['width']}x{res['height']}, "
          f"{res['fps']:g} fps, median {res['frame_ms']:.1f} ms/frame, step switch "
          f"{res['step_switch_ms']:.1f} ms, {res['seconds']:.1f} s in all")
    return 0
