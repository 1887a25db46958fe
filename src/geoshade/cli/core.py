"""``geoshade core render|porosity``."""

from __future__ import annotations

from geoshade.cli import ingest as _big  # issue 6: ingest, --scheduler, --bricks, --level
from geoshade.cli.main import add_render_args, add_volume_args
from geoshade.cli.progress import progress_bar


def register(sub) -> None:
    p = sub.add_parser("core", help="digital core: render a box of a micro-CT volume, porosity")
    csub = p.add_subparsers(dest="core_command", metavar="ACTION")
    csub.required = True

    r = csub.add_parser("render", help="render the voxels of a box inside an absorption range")
    r.add_argument("volume", metavar="VOLUME", help="raw, TIFF (file or folder), .npy, zarr")
    add_volume_args(r)
    r.add_argument("--range", type=float, nargs=2, metavar=("LO", "HI"),
                   help="absorption range in the data's units (default: the whole dtype)")
    r.add_argument("--box", type=int, nargs=6, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"),
                   help="sub-volume: offset and size in voxels (default: whole volume)")
    r.add_argument("--method", default="auto",
                   choices=("auto", "raycast", "trefoil", "gs", "cubes"),
                   help="auto picks the fastest for this renderer (raycast on llvmpipe)")
    r.add_argument("--colormap", default="viridis", help="matplotlib colour map (viridis)")
    r.add_argument("--no-cull", action="store_true",
                   help="draw hidden voxels too (reproduces the paper's trefoil counts)")
    r.add_argument("--paper-trefoil", action="store_true",
                   help="one trefoil per frame from the view direction, Eq. (1), instead of per "
                        "voxel from the eye position")
    r.add_argument("--frames", type=int, default=5, help="frames timed for frame_ms (5)")
    r.add_argument("--gpu-memory", type=float, metavar="GiB",
                   help="GPU memory to plan for when the driver does not say (default: unknown)")
    add_render_args(r)
    _big.add_scale_args(r, render=True)
    r.set_defaults(func=run_render)

    q = csub.add_parser("porosity", help="pore fraction of a box, total and as a profile")
    q.add_argument("volume", metavar="VOLUME")
    add_volume_args(q)
    q.add_argument("--range", type=float, nargs=2, metavar=("LO", "HI"), required=True,
                   help="pore range in the data's units")
    q.add_argument("--box", type=int, nargs=6, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"))
    q.add_argument("--axis", choices=("x", "y", "z"), default="z", help="profile axis (z)")
    q.add_argument("-o", "--output", required=True, metavar="PLOT.png")
    q.add_argument("--csv", metavar="FILE.csv")
    q.add_argument("--json", metavar="FILE.json")
    _big.add_scale_args(q, render=False)
    q.set_defaults(func=run_porosity)
    _big.register(csub)


def run_render(args) -> int:
    from geoshade import core
    from geoshade.io.output import write_json, write_png

    vol = _big.load_volume(args)
    with progress_bar("selecting voxels") as cb:
        img, stats = core.render(
            vol, range=args.range, box=args.box, method=args.method, size=args.size,
            view=args.view, azimuth=args.azimuth, elevation=args.elevation, zoom=args.zoom,
            ortho=args.ortho, transparent=args.transparent, colormap=args.colormap,
            cull=not args.no_cull, trefoil_mode="paper" if args.paper_trefoil else "eye",
            frames=args.frames, progress=cb,
            gpu_memory_limit=None if args.gpu_memory is None else args.gpu_memory * 2**30,
            **_big.scale_kwargs(args))
    write_png(args.output, img)
    if args.stats:
        write_json(args.stats, stats)
    print(f"{args.output}: {stats['width']}x{stats['height']} {stats['method']}, "
          f"{stats['voxels_selected']} voxels selected, {stats['voxels_drawn']} drawn, "
          f"{stats['frame_ms']:.1f} ms/frame, {stats['gpu_bytes'] / 2**20:.2f} MiB on the GPU")
    return 0


def run_porosity(args) -> int:
    from geoshade import core
    from geoshade.compute.porosity import csv_text
    from geoshade.core.plots import porosity_plot
    from geoshade.io.output import write_json, write_text

    vol = _big.load_volume(args)
    with progress_bar("porosity") as cb:
        res = core.porosity(vol, args.range, box=args.box, axis=args.axis, progress=cb,
                            **_big.scale_kwargs(args))
    porosity_plot(res, args.output, title=f"{vol.name or args.volume}")
    if args.csv:
        write_text(args.csv, csv_text(res))
    if args.json:
        write_json(args.json, res.to_dict())
    print(f"porosity {res.porosity:.4f} ({res.count} of {res.total} voxels in "
          f"[{args.range[0]:g}, {args.range[1]:g}]); profile along {args.axis} -> {args.output}")
    return 0
