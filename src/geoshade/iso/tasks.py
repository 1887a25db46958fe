"""One-shot functions of the iso part: ``render``, ``export_mesh``, ``animate``."""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

from geoshade.compute.mesh import marching_cubes as mc
from geoshade.errors import EmptySceneWarning, InputError
from geoshade.io.interop.mesh import write_mesh
from geoshade.iso.api import OutsideValuesWarning
from geoshade.iso.diff import assumed_level, difference_field
from geoshade.iso.options import IsoOptions, field_reports
from geoshade.iso.view import IsoView
from geoshade.models.field import TriangleMesh
from geoshade.models.steps import resolve_step
from geoshade.render.video import VideoWriter
from geoshade.styles.categories import by_name
from geoshade.styles.difference import symmetric_range


def render(field, level=None, camera=None, *, frames: int = 5, count: bool = True, mesh=None,
           ctx=None, progress=None, **options) -> tuple[np.ndarray, dict]:
    """Render the isosurface ``S = level`` of one step of ``field``.

    Parameters
    ----------
    field : FieldSeries or CornerPointGrid
    level : float, optional
        ``S*``; a level outside the step's values draws nothing and warns
        (:class:`~geoshade.errors.EmptySceneWarning`). Default: the middle of the values.
    camera : Camera, CameraSpec or view name, optional
        Default: the options' camera framed on the field's bounds.
    frames : int
        Frames drawn for timing; ``frame_ms`` is the median after the first.
    mesh : str or Path, optional
        Also write the drawn triangles (transform feedback) to this ``.ply/.obj/.stl``.
    **options
        :class:`~geoshade.iso.options.IsoOptions`: ``step`` (default the last), ``color_by``,
        ``colormap``/``color_range``, ``patch_level``/``skip_patches``/``slice_axis``
        (``64, False, "z"`` is the paper's method exactly), ``exaggeration``, ``mesh_cache``,
        ``caps`` (close the surface along inactive, NaN and infinite cells; default open),
        ``size``, the camera ...

    Returns
    -------
    image : (h, w, 4) uint8
    stats : dict
        ``width height method frame_ms gpu_bytes cells triangles`` and more (see
        :class:`IsoView`); ``mesh_vertices``/``mesh_faces`` when a mesh was written.

    Examples
    --------
    >>> import geoshade.iso
    >>> from geoshade.compute.mesh.displacement import displacement_field
    >>> f = displacement_field((24, 16, 16), steps=2)
    >>> img, st = geoshade.iso.render(f, 0.5, size="64x48", frames=1)
    >>> img.shape, st["method"], st["step"]
    ((48, 64, 4), 'tessellation', 1)
    """
    options.setdefault("prefetch", False)
    with IsoView(field, level, ctx=ctx, progress=progress, **options) as v:
        img, stats = v.draw(camera, frames=frames, count=count)
        if mesh is not None:
            m = v.mesh()

            write_mesh(mesh, m)
            stats["mesh"] = str(mesh)
            stats["mesh_vertices"], stats["mesh_faces"] = m.n_vertices, m.n_faces
        return img, stats


def export_mesh(field, level, path=None, step=None, color_by=None, color_range=None,
                ctx=None, **options) -> TriangleMesh:
    """The isosurface's triangles as the GPU emits them (transform feedback), optionally written.

    Parameters
    ----------
    path : str or Path, optional
        ``.ply``, ``.obj`` or ``.stl`` to write (atomically).

    Returns
    -------
    TriangleMesh
        World coordinates, welded vertices, normals towards lower values.

    Examples
    --------
    >>> from geoshade.compute.mesh.displacement import displacement_field
    >>> m = export_mesh(displacement_field((24, 16, 16), steps=2), 0.5)   # doctest: +SKIP
    >>> m.n_faces > 0                                                      # doctest: +SKIP
    True
    """
    v = IsoView(field, level, step=step, color_by=color_by, color_range=color_range,
                size=(1, 1), prefetch=False, ctx=ctx, **options)
    try:
        reason = v.empty_reason()
        if reason is not None:
            warnings.warn(f"{v.field.name or 'field'} at step {v.step}: {reason}; the mesh is "
                          "empty", EmptySceneWarning, stacklevel=2)
        m = v.mesh()
        if path is not None:
            write_mesh(path, m)
        return m
    finally:
        v.release()


def animate(field, level, output, size=(1920, 1080), fps: float = 4.0, steps=None,
            progress=None, ctx=None, summary=None, **options) -> dict:
    """Render every step (or ``steps``) into an ``.mp4`` or ``.gif``, with one fixed camera.

    The next step is prepared in a background thread while the current one is drawn; the file is
    written atomically. Steps where the level is outside the values are drawn empty and named in
    one warning at the end.

    Parameters
    ----------
    output : str or Path
        ``.mp4`` (H.264 through imageio-ffmpeg) or ``.gif`` (Pillow).
    progress : callable(done, total), optional
        Called after each frame (the CLI drives a tqdm bar with it).
    summary : list of str, optional
        Summary vectors of the case (``FOPR``, ``WOPR:*``) drawn as a strip under each frame,
        its cursor at the frame's date (:func:`geoshade.render.animate.summary_strip`).

    Returns
    -------
    dict
        ``output frames width height fps frame_ms`` (median draw), ``step_switch_ms`` (median),
        ``triangles`` (per step), ``empty_steps``, ``seconds``.
    """

    t_start = time.perf_counter()
    options.setdefault("mesh_cache", False)  # one frame per step: nothing to re-draw
    field = IsoView.coerce(field, options)
    # every option is checked before the output is opened
    opts = IsoOptions.parse(field, size=size, level=level, **options)
    order = list(range(field.nsteps)) if steps is None else [
        resolve_step(s, field.nsteps, dates=field.times, where=field.source) for s in steps]
    if not order:
        raise InputError("steps: no step to animate")
    shown = field if opts.diff is None else difference_field(field, opts.diff)
    if opts.diff is not None and opts.level is None:   # one level for every frame, said
        ends = [mc.prepare_values(shown.step(k), shown.active) for k in order]
        level = assumed_level(min((p.vmin for p in ends if p.vmin is not None), default=None),
                              max((p.vmax for p in ends if p.vmax is not None), default=None))
        warnings.warn(f"level {shown.name} = {level:g} assumed: half the largest change over "
                      "the steps animated; give --level (level=) to choose", UserWarning,
                      stacklevel=2)
        opts = IsoOptions.parse(field, opts, level=level)
    color_range = all_steps_range(shown, opts, order)
    if color_range is not None:   # one colour scale for the whole animation
        opts = IsoOptions.parse(field, opts, color=opts.color.with_(range=color_range))
    strip, with_strip, strip_height = None, None, 0
    if summary:   # the case's curves under the frames (resfo and matplotlib: loaded now)
        from geoshade.render import animate as anim

        with_strip, strip_height = anim.with_strip, anim.STRIP_HEIGHT
        summary_strip = anim.summary_strip

        strip = summary_strip(field.source or field.name, list(summary), opts.size[0],
                              list(field.times or ()), list(field_reports(field) or ()))
    writer = VideoWriter(output, fps=fps)
    v = None
    try:
        v = IsoView(field, ctx=ctx, options=opts, step=order[0])
        cam = v.camera()
        frame_ms, switch_ms, tris, empty, nonfinite, titles = [], [], [], [], 0, []
        for i, k in enumerate(order):
            if i:
                v.update(step=k)
                switch_ms.append(v.switch_ms)
            img, st = v.draw(cam, frames=1, count=True, warn=False)
            res_level = st["level"]
            writer.append(img if strip is None or with_strip is None
                          else with_strip(img, strip, k))
            frame_ms.append(st["frame_ms"])
            tris.append(st["triangles"])
            titles.append([t["text"] for t in st.get("annotations", {}).get("title", [])])
            if v.empty_reason() is not None:
                empty.append(k)
            nonfinite = max(nonfinite, st["nonfinite"])
            if progress is not None:
                progress(i + 1, len(order))
        writer.close()
    except BaseException:
        writer.abort()
        raise
    finally:
        if v is not None:
            v.release()
    name = shown.name or "field"
    if empty:
        warnings.warn(f"{name}: level {float(res_level):g} is outside the values at "
                      f"step(s) {empty}; those frames are empty", EmptySceneWarning,
                      stacklevel=2)
    if nonfinite:
        warnings.warn(f"{name}: up to {nonfinite:,} nodes per step are NaN or "
                      "infinite; they are treated as outside the surface", OutsideValuesWarning,
                      stacklevel=2)
    return {
        "output": str(Path(output)), "frames": len(order), "width": int(img.shape[1]),
        "height": int(img.shape[0]), "fps": float(fps),
        "frame_ms": float(np.median(frame_ms)),
        "step_switch_ms": float(np.median(switch_ms)) if switch_ms else 0.0,
        "triangles": tris, "empty_steps": empty, "steps": order, "titles": titles,
        "strip_height": strip_height,
        "color_range": list(color_range) if color_range is not None else
        (list(opts.color.range) if opts.color.range is not None else None),
        "seconds": round(time.perf_counter() - t_start, 3),
    }


def all_steps_range(field, opts: IsoOptions, steps) -> tuple[float, float] | None:
    """The colour range of ``opts.color_by`` over every step in ``steps`` (its finite values;
    positive ones where the scale is log; a change's symmetric about 0 over its active nodes,
    ``field`` being a :func:`~geoshade.iso.diff.difference_field`), so that every frame of an
    animation shares one colour scale; None when the surface is not coloured by a property,
    the range is given, or the property is drawn as categories.

    Examples
    --------
    >>> from geoshade.compute.mesh.displacement import displacement_field
    >>> f = displacement_field((12, 8, 8), steps=3)
    >>> o = IsoOptions.parse(f, level=0.5, color_by="PRESSURE")
    >>> lo, hi = all_steps_range(f, o, range(3))
    >>> bool(lo <= min(float(np.nanmin(f.property_step("PRESSURE", k))) for k in range(3)))
    True
    """
    c = opts.color
    if opts.color_by is None or c.range is not None or c.solid is not None or c.categorical:
        return None
    if opts.color_by in (field.meta or {}).get("differenced", ()):   # a change: centred on 0
        ends = [mc.prepare_values(field.property_step(opts.color_by, k), field.active)
                for k in steps]
        return symmetric_range(min((p.vmin for p in ends if p.vmin is not None), default=None),
                               max((p.vmax for p in ends if p.vmax is not None), default=None))
    ext, codes = [], False
    for k in steps:
        raw = np.asarray(field.property_step(opts.color_by, k))
        codes = codes or bool(np.issubdtype(raw.dtype, np.integer))
        v = raw.astype(np.float64)
        ok = v[np.isfinite(v)]
        if ok.size:
            pos = ok[ok > 0]
            ext += [ok.min(), ok.max()] + ([pos.min()] if pos.size else [])
    if not ext:
        return None

    ext_arr = np.asarray(ext)
    if c.categorical is None and (by_name(opts.color_by) or codes):
        return None   # region codes: the categories (one colour per code) decide
    style, _auto = c.resolved(opts.color_by, ext_arr)
    return style.default_range(ext_arr)
