"""What every ``render`` subcommand shares: the output and camera flags, the colour flags, and
one generic run over the part's View.

Every render subcommand takes ``-o OUT.png``, ``--size WxH``, the camera (``--view --azimuth
--elevation --zoom --ortho``, or ``--camera FILE.json`` saved by ``--save-camera FILE.json``),
``--transparent``, ``--stats FILE.json`` and ``--frames N``;
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
from geoshade.cli.main import finite_float, positive_int
from geoshade.errors import GeoshadeDeprecationWarning, InputError
from geoshade.styles.options import CameraSpec, ViewOptions

#: the named views (the options' vocabulary)
RENDER_VIEWS = ViewOptions.choices("view")


def add_camera_args(p: argparse.ArgumentParser, view_default: str | None = "iso") -> None:
    p.add_argument("--view", default=view_default, choices=RENDER_VIEWS, help="named view (iso)")
    p.add_argument("--azimuth", type=finite_float, default=None,
                   help="degrees, overrides the view")
    p.add_argument("--elevation", type=finite_float, default=None,
                   help="degrees, overrides the view")
    p.add_argument("--zoom", type=finite_float, default=CameraSpec().zoom,
                   help="zoom factor (1 = whole model)")
    p.add_argument("--ortho", action="store_true", help="orthographic projection")


def add_render_args(p: argparse.ArgumentParser, size: str = "1024x768",
                    output: str = "OUT.png") -> None:
    """The options every render subcommand takes (DESIGN.md, public surface)."""
    p.add_argument("-o", "--output", required=True, metavar=output, help="file to write")
    p.add_argument("--size", default=size, metavar="WxH", help=f"image size ({size})")
    add_camera_args(p, view_default=None)
    p.add_argument("--camera", metavar="FILE.json",
                   help="the camera saved by --save-camera (or the viewer's Save camera): the "
                        "same view again, pixel for pixel at the same --size; instead of "
                        "--view/--azimuth/--elevation/--zoom/--ortho")
    p.add_argument("--save-camera", metavar="FILE.json",
                   help="write the camera of this picture (after framing) as JSON, for "
                        "--camera and the viewer's Load camera")
    p.add_argument("--transparent", action="store_true", help="background alpha 0")
    p.add_argument("--no-annotations", action="store_true",
                   help="the bare render: no title, colour bar or legend, axes or scale bar")
    p.add_argument("--stats", metavar="FILE.json", help="write render statistics as JSON")
    p.add_argument("--frames", type=positive_int, default=5,
                   help="frames timed for frame_ms (5)")
    p.add_argument("--pick", type=pixel_arg, metavar="X,Y",
                   help="print what pixel X,Y (from the top left) shows: cell/voxel, value, "
                        "depth; also under 'pick' in the stats JSON")


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


def add_color_args(p: argparse.ArgumentParser, what: str = "the property",
                   deprecated_range: bool = False, log: bool = True) -> None:
    """``--colormap``, ``--color-range``, ``--log`` (and the old ``--range`` of the grid)."""
    p.add_argument("--colormap", default=None, metavar="NAME",
                   help="colour map: matplotlib's names (viridis, the default; NAME_r "
                        "reversed) and, with the colors extra, colorcet's (fire, rainbow4...)")
    p.add_argument("--reverse", action="store_true", help="reverse the colour map")
    p.add_argument("--solid-color", metavar="COLOR",
                   help="one colour for everything shown (a name, #rrggbb or R,G,B 0..1)")
    p.add_argument("--color-range", type=finite_float, nargs=2, metavar=("LO", "HI"),
                   help=f"values of {what} spread over the colour map (default: its range)")
    if deprecated_range:
        p.add_argument("--range", dest="old_color_range", type=finite_float, nargs=2,
                       metavar=("LO", "HI"), help="deprecated: the old name of --color-range")
    if log:
        p.add_argument("--log", dest="log", action="store_const", const=True, default=None,
                       help="logarithmic colour scale (default: automatic for permeability-like "
                            "properties spanning more than three decades)")
        p.add_argument("--linear", dest="log", action="store_const", const=False,
                       help="linear colour scale (no automatic log)")
        p.add_argument("--nan-color", metavar="COLOR",
                       help="colour of cells without a value (light grey)")
        p.add_argument("--categorical", dest="categorical", action="store_const", const=True,
                       default=None,
                       help="draw the values as categories: one colour and one legend entry per "
                            "code (default: automatic for integer codes and region/facies "
                            "keywords such as FACIES, ZONE, SATNUM, FIPNUM)")
        p.add_argument("--continuous", dest="categorical", action="store_const", const=False,
                       help="draw integer codes with a colour map and a colour bar")


def add_skip_missing_arg(p: argparse.ArgumentParser) -> None:
    """``--skip-missing``: read a deck or GRDECL file whose INCLUDEs are partly missing."""
    p.add_argument("--skip-missing", action="store_true",
                   help="decks and GRDECL files: read what is there when INCLUDE files are "
                        "missing (one warning names them); a grid whose geometry is missing is "
                        "shown in IJK index space (unit cells)")


def skip_missing_hint(args) -> dict:
    """``{"skip_missing": True}`` when ``--skip-missing`` was given (a load hint), else {}."""
    return {"skip_missing": True} if getattr(args, "skip_missing", False) else {}


def deprecated_flag(new, old, old_flag: str, new_flag: str, what: str = ""):
    """The value of ``new_flag``, or of its old name ``old_flag`` with one warning line."""
    if old is None:
        return new
    if new is not None:
        raise InputError(f"{old_flag}: give either {old_flag} (deprecated) or {new_flag}")
    warnings.warn(f"{old_flag} is deprecated{what}: use {new_flag}", GeoshadeDeprecationWarning,
                  stacklevel=3)
    return old


def camera_options(args) -> dict:
    """The camera flags as options: ``camera=FILE.json`` for ``--camera`` (refused together
    with the flags it replaces), else the named view and its changes."""
    path = getattr(args, "camera", None)
    if path:
        given = [f for f, on in (("--view", args.view is not None),
                                 ("--azimuth", args.azimuth is not None),
                                 ("--elevation", args.elevation is not None),
                                 ("--zoom", args.zoom != 1.0), ("--ortho", args.ortho)) if on]
        if given:
            raise InputError(f"--camera: {path} fixes the view; give either it or "
                             f"{', '.join(given)}, not both")
        return {"camera": path}
    return {"view": args.view or "iso", "azimuth": args.azimuth, "elevation": args.elevation,
            "zoom": args.zoom, "ortho": args.ortho}


def color_options(args) -> dict:
    out: dict[str, Any] = {}
    if getattr(args, "colormap", None):
        out["colormap"] = args.colormap
    crange = deprecated_flag(getattr(args, "color_range", None),
                             getattr(args, "old_color_range", None), "--range", "--color-range",
                             " here (it is the colour range)")
    if crange is not None:
        out["color_range"] = tuple(crange)
    if getattr(args, "log", None) is not None:
        out["log"] = args.log
    if getattr(args, "reverse", False):
        out["reverse"] = True
    if getattr(args, "categorical", None) is not None:
        out["categorical"] = args.categorical
    for flag in ("solid_color", "nan_color"):
        if getattr(args, flag, None):
            out[flag] = _color_arg(getattr(args, flag))
    return out


def _color_arg(text: str):
    """``R,G,B`` (0..1) as numbers; any other text (a name, ``#rrggbb``) as it is."""
    parts = text.split(",")
    if len(parts) in (3, 4):
        try:
            return tuple(float(p) for p in parts)
        except ValueError:
            pass
    return text


def output_options(args) -> dict:
    return {"size": args.size, "transparent": args.transparent,
            "annotations": not getattr(args, "no_annotations", False), **camera_options(args)}


#: suffixes of the files of an ECLIPSE/OPM case (a case's outputs must not name any of them)
CASE_SUFFIXES = (".egrid", ".init", ".unrst", ".smspec", ".unsmry", ".data", ".grid", ".grdecl",
                 ".fegrid", ".finit", ".funrst", ".rsspec", ".prt")


def case_inputs(*paths) -> list[Path]:
    """The files a command reads before it reads them: ``paths`` and, for an ECLIPSE/OPM case,
    every file of the same case name beside it (INIT, UNRST, X0001, ...)."""
    out: list[Path] = []
    for p in paths:
        if p is None:
            continue
        p = Path(p)
        out.append(p)
        if p.suffix.lower() in CASE_SUFFIXES and p.parent.is_dir():
            stem = p.name[: -len(p.suffix)]
            out += [q for q in p.parent.glob(f"{stem}.*") if q != p]
    return out


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
    from geoshade.io.output import Outputs

    Outputs(outputs, inputs)


def add_distributed_args(p: argparse.ArgumentParser, parts: str) -> None:
    """``--distributed`` and ``--worker-timeout`` (with the parser's ``--scheduler``)."""
    p.add_argument("--distributed", action="store_true",
                   help=f"draw on the --scheduler cluster: {parts} stay on the workers' GPUs, "
                        "each worker returns colour and depth of its part of the picture, "
                        "composited by depth (the same picture as one process)")
    p.add_argument("--worker-timeout", type=finite_float, default=None, metavar="S",
                   help="--distributed: seconds a worker may take for one call before it is "
                        "taken as lost and its parts are redone elsewhere (300)")


def add_progressive_arg(p: argparse.ArgumentParser, preview: str) -> None:
    """``--progressive``: also draw the coarse preview first (``OUT.coarse.png``)."""
    p.add_argument("--progressive", action="store_true",
                   help=f"a picture at once: draw {preview} first, written as OUT.coarse.png "
                        "(its time printed), then the full picture (-o)")


def coarse_path(output) -> str:
    """Where ``--progressive`` writes the preview: ``OUT.coarse.png`` beside ``OUT.png``.

    >>> coarse_path("shots/a.png")
    'shots/a.coarse.png'
    """
    p = Path(output)
    return str(p.with_name(p.stem + ".coarse" + (p.suffix or ".png")))


def distributed_view(args, kind: str, options: dict):
    """The distributed View of part ``kind`` for ``--distributed`` (its options added), else
    None; one line when the flags do not go together."""
    if not getattr(args, "distributed", False):
        if getattr(args, "worker_timeout", None) is not None:
            raise InputError("--worker-timeout: applies to --distributed rendering")
        return None
    if not options.get("scheduler"):
        raise InputError("--distributed: give the cluster with --scheduler ADDRESS "
                         "(tcp://HOST:8786) or --scheduler local:N")

    if args.worker_timeout is not None:
        options["worker_timeout"] = args.worker_timeout
    options["distributed"] = True
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


def run_render(args, kind: str, load: Callable[[], Any], options: dict,
               inputs=(), after: Callable | None = None, outputs: dict | None = None,
               progress=None, suffixes: dict | None = None, view_cls=None) -> int:
    """Check, read, render, write: the one body of every ``render`` subcommand.

    Parameters
    ----------
    kind : the part (``core grid iso stacks``)
    load : reads the model (called after the cheap checks); may return ``(model, options)``
    options : the part's options from the flags (output and camera flags are added here)
    inputs : paths the outputs must not name
    outputs : other output flags and paths to check before the work (``--mesh``)
    progress : ``progress(done, total)`` for the View's long CPU work
    suffixes : flag -> the suffixes its file may have (``-o`` .png and ``--stats`` .json are
        known)
    after : ``after(view, stats, outputs)`` runs before the View is released (e.g. a mesh
        export staged with ``outputs.path("--mesh")``)
    view_cls : the View class when it is not the part's usual one (``--distributed``)
    """
    from geoshade.io.output import Outputs, json_bytes, png_bytes

    cls = view_cls or view_class(kind)
    opts = {**output_options(args), **options}
    with warnings.catch_warnings():  # the real parse below warns once
        warnings.simplefilter("ignore")
        checked = cls.Options.parse(None, **opts)  # syntax and ranges, before reading anything
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
    with Outputs(named, [*case_inputs(*inputs), *([camera_file] if camera_file else [])],
                 allowed) as out:
        model = load()
        if isinstance(model, tuple):  # (model, options found in the file, e.g. a deck's wells)
            model, more = model
            opts.update(more)
        out.protect(model_inputs(model))  # INCLUDEs, INIT, UNRST: known once read
        # every option is checked against the model, then the GL context is made
        with cls(model, progress=progress, **opts) as view:
            cam = view.camera()  # framed on the model (or the saved one of --camera)
            if progressive:
                coarse_line, timing = _progressive_preview(
                    view, cam, out, named["--progressive"], t_start, png_bytes)
            img, stats = view.draw(cam, frames=args.frames)
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


__all__ = ["RENDER_VIEWS", "add_camera_args", "add_color_args", "add_progressive_arg",
           "add_render_args", "add_skip_missing_arg", "camera_options", "case_inputs",
           "check_outputs", "coarse_path", "color_options", "deprecated_flag", "model_inputs",
           "output_options", "pixel_arg", "run_render", "skip_missing_hint"]
