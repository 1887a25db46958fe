"""The stacks block of ``geoshade demo``: a small synthetic layered model, rendered."""

from __future__ import annotations

from pathlib import Path

from geoshade.compute.stacks import synthetic_layers
from geoshade.io.output import write_json, write_png
from geoshade.stacks.convert import memory_stats
from geoshade.stacks.view import StacksView


def run_demo(out: Path, size="1024x768") -> tuple[list[Path], list[str]]:
    """Render a synthetic 64×48×40 layered model (ssbo layout), plain and with a cut.

    Returns the files written and the lines to print.

    >>> files, lines = run_demo(Path("/tmp/geoshade-demo"), size="96x72")  # doctest: +SKIP
    """

    model = synthetic_layers(64, 48, 40, max_intervals=6, seed=3, spacing=(50.0, 50.0, 2.0))
    mem = memory_stats(model, octree=False)
    written, stats = [], {}
    with StacksView(model, layout="ssbo", size=size, exaggeration=4.0, legend=True) as view:
        # the plane keeps x - y <= 400 (the side its normal (-1, 1, 0) points to)
        for name, plane in (("plain", None), ("section", (-1.0, 1.0, 0.0, -400.0))):
            view.update(plane=plane)
            img, st = view.draw(frames=2)
            written.append(write_png(Path(out) / f"stacks-{name}.png", img))
            stats[name] = st
    written.append(write_json(Path(out) / "stacks-stats.json", {**stats, "memory": mem}))
    lines = [f"  stacks {k:<17s} {s['method']:8s} {s['intervals']:>9,d} intervals "
             f"{s['frame_ms']:8.1f} ms/frame  {s['gpu_bytes'] / 2**20:7.2f} MiB GPU"
             for k, s in stats.items()]
    lines.append(f"  stacks memory: voxels {mem['bytes_voxels'] / 2**20:.2f} MiB, stacks "
                 f"{mem['bytes_stacks'] / 2**20:.3f} MiB "
                 f"({100 * mem['saving_vs_voxels']:.1f} % less)")
    return written, lines
