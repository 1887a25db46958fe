"""``geoshade demo``: render built-in synthetic data, write pictures and plots, say where."""

from __future__ import annotations

import json
from pathlib import Path

from geoshade import core, iso
from geoshade import grid as grid_part
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.compute.voxels.porosity import csv_text
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.core.plots import porosity_plot
from geoshade.io.output import write_json, write_png, write_text
from geoshade.stacks.demo import run_demo as stacks_demo


def register(sub) -> None:
    p = sub.add_parser("demo", help="render built-in synthetic data (no files needed)")
    p.add_argument("-o", "--output", default="geoshade-demo", metavar="DIR",
                   help="folder for the pictures (./geoshade-demo)")
    p.add_argument("--size", default="1024x768", metavar="WxH")
    p.add_argument("--voxels", type=int, default=128, help="side of the synthetic core (128)")
    p.set_defaults(func=run)


def run(args) -> int:
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    n = int(args.voxels)
    vol = synthetic_core(n, porosity=0.2, seed=7)
    vals = vol.data
    pore_hi = float((int(vals.min()) + int(vals.max())) // 2)
    pore = (0, pore_hi)
    skeleton = (pore_hi + 1, float(vol.value_limits()[1]))
    written = []
    summary = {}
    vmin, vmax = float(vals.min()), float(vals.max())
    with core.CoreView(vol, select=pore, size=args.size, method="auto") as view:
        jobs = [
            ("pore-space", pore, None, "iso"),
            ("mineral-skeleton", skeleton, None, "iso"),
            ("pore-space-box", pore, [n // 4, n // 4, n // 4, n // 2, n // 2, n // 2], "iso"),
            ("pore-space-top", pore, None, "top"),
        ]
        for name, sel, box, vname in jobs:
            # colours over the values actually present in the selection
            view.update(select=sel, box=box,
                        color_range=(max(sel[0], vmin), min(sel[1], vmax)))
            img, stats = view.draw(view.camera(vname), frames=3)
            written.append(write_png(out / f"core-{name}.png", img))
            summary[name] = stats
        for method in ("trefoil",):
            view.update(select=pore, box=None, color_range=(vmin, pore_hi), method=method)
            img, stats = view.draw(frames=2)
            written.append(write_png(out / f"core-pore-space-{method}.png", img))
            summary[f"pore-space-{method}"] = stats
    res = core.porosity(vol, pore, axis="z")
    written.append(porosity_plot(res, out / "porosity-z.png", title="synthetic core, pore space"))
    written.append(write_text(out / "porosity-z.csv", csv_text(res)))
    written.append(write_json(out / "porosity-z.json", res.to_dict()))
    written.append(write_json(out / "stats.json", summary))
    # --- iso: the water-saturation isosurface of a synthetic unstable displacement ------------
    iso_field = displacement_field((96, 64, 64), steps=8, seed=0)
    iso_stats = {}
    with iso.IsoView(iso_field, 0.5, step=2, size=args.size, color_by="PRESSURE",
                     color_range=(200.0, 300.0)) as iso_view:
        for k in (2, 7):  # an early and a late step: the fingers grow
            iso_view.update(step=k)
            img, st = iso_view.draw(frames=2)
            written.append(write_png(out / f"iso-swat-step{k}.png", img))
            iso_stats[f"step{k}"] = st
    written.append(write_json(out / "iso-stats.json", iso_stats))
    # --- grid: a faulted corner-point grid coloured by porosity, cell edges on ---------------
    cpg = synthetic_grid(60, 40, 12, faults=True, seed=3)
    grid_stats = {}
    for name, kw in (("poro-edges", {"property": "PORO", "edges": True}),
                     ("swat-filter", {"property": "SWAT", "step": 3, "filter": "PORO > 0.2"})):
        img, st = grid_part.render(cpg, size=args.size, frames=2, exaggeration=5.0, **kw)
        written.append(write_png(out / f"grid-{name}.png", img))
        grid_stats[name] = st
    written.append(write_json(out / "grid-stats.json", grid_stats))

    stacks_files, stacks_lines = stacks_demo(out, size=args.size)
    written += stacks_files
    print(f"geoshade demo: synthetic core {n}³ uint16, pore range {pore[0]:g}..{pore[1]:g}, "
          f"porosity {res.porosity:.3f}")
    for k, s in summary.items():
        print(f"  {k:24s} {s['method']:8s} {s['voxels_selected']:>9d} voxels  "
              f"{s['frame_ms']:8.1f} ms/frame  {s['gpu_bytes'] / 2**20:7.2f} MiB GPU")
    print("synthetic corner-point grid 60×40×12 with faults, vertical exaggeration 5")
    for k, s in grid_stats.items():
        print(f"  grid {k:19s} {s['faces_drawn']:>9,d} faces     {s['frame_ms']:8.1f} ms/frame  "
              f"{s['gpu_bytes'] / 2**20:7.2f} MiB GPU")
    print("synthetic unstable displacement 64×64×96, 8 steps, colour = pressure")
    for k, s in iso_stats.items():
        print(f"  iso SWAT = 0.5 {k:<10s} {s['triangles']:>9,d} triangles "
              f"{s['frame_ms']:8.1f} ms/frame  {s['gpu_bytes'] / 2**20:7.2f} MiB GPU")
    print("\n".join(stacks_lines))
    print(f"wrote {len(written)} files to {out.resolve()}:")
    for p in written:
        print(f"  {Path(p).resolve()}")
    print(json.dumps({"porosity": res.porosity}))
    return 0
