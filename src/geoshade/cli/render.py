"""What every ``render`` subcommand shares: its part's drawing options as flags, generated from
their declarations (:mod:`geoshade.cli.options`), the picture file flags, and one generic run
over the part's View.

Every render subcommand takes ``-o OUT.png``, ``--size WxH``, the camera (``--view --azimuth
--elevation --zoom --ortho``, or ``--camera FILE.json`` saved by ``--save-camera FILE.json``),
``--transparent``, ``--stats FILE.json``, ``--frames N`` and every option of its part;
:func:`run_render` checks the options without the model (syntax, ranges), then the outputs,
then reads the model, checks the options against it, and only then asks for a GL context.
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

from geoshade.api import distributed_class, view_class
from geoshade.cli.main import finite_float, positive_float, positive_int
from geoshade.cli.options import add_option_args, flag_error, given_options
from geoshade.cli.plan import before_loading
from geoshade.errors import InputError
from geoshade.io.formats import case_files
from geoshade.io.output import Outputs, json_bytes, png_bytes


def add_render_args(p: argparse.ArgumentParser, kind: str, output: str = "OUT.png") -> None:
    """What every render subcommand takes: its part's drawing options (generated from their
    declarations, :mod:`geoshade.cli.options`) and the picture file flags."""
    add_option_args(p, {kind: view_class(kind).Options})
    add_output_args(p, output)


def add_output_args(p: argparse.ArgumentParser, output: str = "OUT.png") -> None:
    """The flags of the files a picture goes to (DESIGN.md, public surface)."""
    g = p.add_argument_group("output")
    g.add_argument("-o", "--output", required=True, metavar=output, help="file to write")
    g.add_argument("--save-camera", metavar="FILE.json",
                   help="write the camera of this picture (after framing) as JSON, for "
                        "--camera and the viewer's Load camera")
    g.add_argument("--stats", metavar="FILE.json", help="write render statistics as JSON")
    g.add_argument("--frames", type=positive_int, default=5,
                   help="frames timed for frame_ms (5)")
    g.add_argument("--pick", type=pixel_arg, metavar="X,Y",
                   help="print what pixel X,Y (from the top left) shows: cell/voxel, value, "
                        "depth; also under 'pick' in the stats JSON")


def add_animation_args(p: argparse.ArgumentParser) -> None:
    """The flags of an animation's file (``iso animate``, ``grid animate``)."""
    g = p.add_argument_group("animation")
    g.add_argument("-o", "--output", required=True, metavar="OUT.mp4|.gif")
    g.add_argument("--fps", type=positive_float, default=4.0,
                   help="frames (steps) per second (4)")
    g.add_argument("--steps", nargs="+", metavar="K",
                   help="the steps drawn, in this order (indices, R36 or dates; default: "
                        "every step)")
    g.add_argument("--stats", metavar="FILE.json", help="write animation statistics as JSON")


def pixel_arg(text: str) -> tuple[float, float]:
    """argparse type: ``X,Y`` pixel coordinates (finite, >= 0).

    >>> pixel_arg("12,5.5")
    (12.0, 5.5)
    """
    parts = str(text).replace(" ", "").split(",")
    try:
        x, y = (finite_float(v) for v in parts)
    except (ValueError, argparse.ArgumentTypeError):
        raise argparse.ArgumentTypeError(f"expected X,Y pixel coordinates, got {text!r}") \
            from None
    if x < 0 or y < 0:
        raise argparse.ArgumentTypeError(f"expected X,Y >= 0 (from the top left), got {text!r}")
    return x, y


def add_skip_missing_arg(p: argparse.ArgumentParser) -> None:
    """``--skip-missing``: read a deck or GRDECL file whose INCLUDEs are partly missing."""
    p.add_argument("--skip-missing", action="store_true",
                   help="decks and GRDECL files: read what is there when INCLUDE files are "
                        "missing (one warning names them); a grid whose geometry is missing is "
                        "shown in IJK index space (unit cells)")


def skip_missing_hint(args) -> dict:
    """``{"skip_missing": True}`` when ``--skip-missing`` was given (a load hint), else {}."""
    return {"skip_missing": True} if getattr(args, "skip_missing", False) else {}


def model_inputs(model) -> list[Path]:
    """The files a model says it was read from (GRDECL INCLUDEs, INIT, UNRST, ...)."""
    meta = getattr(model, "meta", None) or {}
    files = list(meta.get("files") or [])
    for key in ("source", "init", "unrst_path", "egrid"):
        if meta.get(key):
            files.append(meta[key])
    grid = getattr(model, "grid", None)  # a field over time keeps its grid
    return [Path(f) for f in files] + (model_inputs(grid) if grid is not None else [])


def check_outputs(outputs: dict[str, str | None], inputs=()) -> None:
    """Refuse, before any work, an output that names an input, a folder, or a missing or
    read-only folder (see :class:`geoshade.io.output.Outputs`)."""

    Outputs(outputs, inputs)


def coarse_path(output) -> str:
    """Where ``--progressive`` writes the preview: ``OUT.coarse.png`` beside ``OUT.png``.

    >>> coarse_path("shots/a.png")
    'shots/a.coarse.png'
    """
    p = Path(output)
    return str(p.with_name(p.stem + ".coarse" + (p.suffix or ".png")))


def cluster_view(kind: str, options: dict):
    """The View class of part ``kind`` for these options: its cluster View where
    ``distributed`` is on (one line where the cluster options do not go together), else its
    usual one."""
    if not options.get("distributed"):
        for name, flag in (("worker_timeout", "--worker-timeout"), ("parts", "--parts")):
            if options.get(name) is not None:
                raise InputError(f"{flag}: applies to --distributed rendering")
        return view_class(kind)
    if not options.get("scheduler"):
        raise InputError("--distributed: give the cluster with --scheduler ADDRESS "
                         "(tcp://HOST:8786) or --scheduler local:N")
    return distributed_class(kind)


def _progressive_preview(view, cam, out, path: str, t_start: float,
                         png: Callable) -> tuple[str, dict]:
    """Draw ``view``'s preview (while it is loading) into ``--progressive``'s file, then build
    the full picture; the line to print and the timings for the stats."""
    if not getattr(view, "loading", False):
        return (f"{path}: not written: no coarse preview for this model (small enough to draw "
                "at once, or no overview level)"), {"coarse_s": None}
    img, st = view.draw(cam, frames=1)
    seconds = time.perf_counter() - t_start
    out.put("--progressive", png(img))
    timing = {"coarse_s": round(seconds, 3), "level": st.get("level"),
              "coarse_ratio": st.get("coarse_ratio")}
    t0 = time.perf_counter()
    view.refine(view.progress)
    timing["refine_s"] = round(time.perf_counter() - t0, 3)
    return f"{path}: {st['coarse_note'].split(' — ')[0]} after {seconds:.1f} s", timing


def run_render(args, kind: str, load: Callable[[], Any], options: dict | None = None,
               inputs=(), after: Callable | None = None, outputs: dict | None = None,
               progress=None, suffixes: dict | None = None) -> int:
    """Check, read, render, write: the one body of every ``render`` subcommand.

    Parameters
    ----------
    kind : the part (``core grid iso stacks``)
    load : reads the model (called after the cheap checks); may return ``(model, options)``
    options : the command's own defaults of options (the flags given override them)
    inputs : paths the outputs must not name
    outputs : other output flags and paths to check before the work (``--mesh``)
    progress : ``progress(done, total)`` for the View's long CPU work
    suffixes : flag -> the suffixes its file may have (``-o`` .png and ``--stats`` .json are
        known)
    after : ``after(view, stats, outputs)`` runs before the View is released (e.g. a mesh
        export staged with ``outputs.path("--mesh")``)
    """

    # a picture file carries its keys unless --no-annotations (the declared default, said here
    # because tests turn the library's default off for their bare-render oracles)
    opts = {"annotations": True, **(options or {}),
            **given_options(args, view_class(kind).Options, kind)}
    cls = cluster_view(kind, opts)
    with warnings.catch_warnings():  # the real parse below warns once
        warnings.simplefilter("ignore")
        try:   # syntax and ranges, before reading anything
            checked = cls.Options.parse(None, **opts)
        except InputError as err:
            raise flag_error(err, args) from None
    pick = getattr(args, "pick", None)
    if pick is not None and not (pick[0] < checked.size[0] and pick[1] < checked.size[1]):
        w, h = checked.size
        raise InputError(f"--pick: pixel {pick[0]:g},{pick[1]:g} is outside the {w}x{h} "
                         "picture")
    picked = ""
    save_camera = getattr(args, "save_camera", None)
    progressive = bool(opts.get("progressive"))
    named = {"-o": args.output, "--stats": getattr(args, "stats", None),
             "--save-camera": save_camera,
             "--progressive": coarse_path(args.output) if progressive else None,
             **(outputs or {})}
    allowed = {"-o": (".png",), "--stats": (".json",), "--save-camera": (".json",),
               "--progressive": (".png",), **(suffixes or {})}
    t_start = time.perf_counter()
    coarse_line, timing = "", dict[str, Any]()
    camera_file = getattr(args, "camera", None)
    inputs = [*inputs, *(opts.get("wells") or ()), *([opts["mask"]] if isinstance(
        opts.get("mask"), str) else []), *([opts["drape"]] if isinstance(opts.get("drape"), str)
                                           else [])]
    with Outputs(named, [*case_files(*inputs), *([camera_file] if camera_file else [])],
                 allowed) as out:
        planned = before_loading(kind, args, checked, inputs)  # the memory plan, before reading
        model = planned.read(load)
        if isinstance(model, tuple):  # (model, options found in the file, e.g. a deck's wells)
            model, more = model
            opts.update(more)
        opts.update(planned.options)
        out.protect(model_inputs(model))  # INCLUDEs, INIT, UNRST: known once read
        # every option is checked against the model, then the GL context is made
        with cls(model, progress=progress, **opts) as view:
            cam = view.camera()  # framed on the model (or the saved one of --camera)
            if progressive:
                coarse_line, timing = _progressive_preview(
                    view, cam, out, named["--progressive"], t_start, png_bytes)
            img, stats = view.draw(cam, frames=args.frames)
            stats.update(planned.stats())
            if getattr(view.options, "summary", None):   # the curves under the picture
                from geoshade.render.animate import view_strip, with_strip  # matplotlib

                img = with_strip(img, view_strip(view), view.options.step)
                stats["summary"] = {"vectors": list(view.options.summary),
                                    "strip_height": int(img.shape[0] - view.size[1])}
            if progressive:
                stats["progressive"] = {"full_s": round(time.perf_counter() - t_start, 3),
                                        **timing}
            if save_camera:
                w, h = view.size
                out.put("--save-camera", cam.with_aspect(w / h).saved().to_json().encode())
            if pick is not None:
                hit = view.pick(*pick)
                stats["pick"] = None if hit is None else hit.as_dict()
                picked = f"pick {pick[0]:g},{pick[1]:g}: " + (hit.text() if hit is not None
                                                              else "nothing there")
            if after is not None:
                after(view, stats, out)
            summary = view.summary(stats)
        out.put("-o", png_bytes(img))
        out.put("--stats", json_bytes(stats))
        out.commit()
    if coarse_line:
        print(coarse_line)
    print(f"{args.output}: {summary}"
          + (f" (full picture after {stats['progressive']['full_s']:.1f} s)"
             if progressive else ""))
    if picked:
        print(picked)
    return 0


__all__ = ["add_animation_args", "add_output_args", "add_render_args", "add_skip_missing_arg",
           "check_outputs", "cluster_view", "coarse_path", "model_inputs", "pixel_arg",
           "run_render", "skip_missing_hint"]
