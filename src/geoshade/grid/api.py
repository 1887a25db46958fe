"""One-shot functions of the reservoir-grid part: ``render``, ``animate`` (every report step
into a video, the summary curves under the frames) and the demo's wells."""

from __future__ import annotations

import numpy as np

from geoshade.errors import InputError
from geoshade.grid.cells import property_values, uses_step
from geoshade.grid.geometry import demo_wells
from geoshade.grid.options import GridOptions
from geoshade.grid.view import GridView
from geoshade.models.grid import CornerPointGrid
from geoshade.models.steps import resolve_step
from geoshade.render.view import Progress


def render(grid: CornerPointGrid, camera=None, *, frames: int = 5, count: bool = True, ctx=None,
           progress: Progress | None = None, **options) -> tuple[np.ndarray, dict]:
    """Render a corner-point grid coloured by a cell property.

    Parameters
    ----------
    grid : CornerPointGrid
    camera : Camera, CameraSpec or view name, optional
        Default: the options' camera framed on the whole grid.
    frames : int
        Frames drawn for timing; ``frame_ms`` is the median after the first.
    count : bool
        Count the faces the GPU builds (``faces_drawn``).
    **options
        :class:`~geoshade.grid.options.GridOptions`: ``property``, ``step`` (index, -1,
        ``"R36"`` or a date; default the last), ``filter``, ``slice``, ``plane``, ``faults``,
        ``exaggeration``, ``edges``, ``approach``, ``wells``, ``colormap``/``color_range``/
        ``log``, ``size``, the camera (``view azimuth elevation zoom ortho``) ...

    Returns
    -------
    image : (h, w, 4) uint8
    stats : dict
        ``width height method frame_ms gpu_bytes cells active_cells shown_cells faces_drawn
        approach zcorn_bits zcorn_max_error property step`` and more.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> from geoshade.grid import render
    >>> img, stats = render(synthetic_grid(8, 6, 4), property="PORO", edges=True,
    ...                     size=(64, 48), frames=1)
    >>> img.shape, stats["faces_drawn"] == stats["faces"], stats["approach"]
    ((48, 64, 4), True, 3)
    """
    with GridView(grid, ctx=ctx, progress=progress, **options) as view:
        return view.draw(camera, frames=frames, count=count)


def animate(grid: CornerPointGrid, output, fps: float = 4.0, steps=None, summary=None,
            progress: Progress | None = None, ctx=None, **options) -> dict:
    """Render a report-step property at every step (or ``steps``) into an ``.mp4`` or
    ``.gif``, with one fixed camera and one colour scale over the steps drawn; ``summary``:
    summary vectors of the case (``["FOPR", "WBHP:*"]``) drawn as a strip under each frame,
    its cursor at the frame's date. Every option is checked before the file is opened.

    Returns
    -------
    dict
        ``output frames width height fps frame_ms steps titles color_range strip_height
        seconds``.

    Examples
    --------
    >>> import os, tempfile
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> out = os.path.join(tempfile.mkdtemp(), "swat.gif")
    >>> res = animate(synthetic_grid(8, 6, 3), out, property="SWAT", size=(64, 48))
    >>> res["frames"], os.path.getsize(out) > 0
    (4, True)
    """
    if not grid.steps:
        raise InputError(f"{grid.name or 'grid'}: no report steps to animate (no UNRST)")
    opts = GridOptions.parse(grid, **options).resolve(grid)
    if opts.property is None or not uses_step(grid, opts.property):
        raise InputError(f"animate: {opts.property or 'no property'} does not change with the "
                         "report step; give a report-step property (--property SWAT)")
    n = len(grid.steps)
    order = list(range(n)) if steps is None else [
        resolve_step(s, n, dates=grid.step_dates, reports=grid.meta.get("unrst_seqnum") or (),
                     where=grid.name) for s in steps]
    if opts.color.range is None and not opts.color.categorical:   # one scale for every frame
        lo, hi = _range_over(grid, opts, order)
        if lo is not None:
            opts = opts.replace(grid, color_range=(lo, hi))
    # the animation loop and the summary strip: resfo and matplotlib, loaded when used
    from geoshade.render.animate import animate_steps, summary_strip

    strip = None
    if summary:
        source = grid.meta.get("source") or grid.name
        strip = summary_strip(source, list(summary), opts.size[0], list(grid.step_dates),
                              list(grid.meta.get("unrst_seqnum") or ()))
    with GridView(grid, ctx=ctx, progress=progress, options=opts) as view:
        res = animate_steps(view, output, order, fps=fps, progress=progress, strip=strip)
    res["color_range"] = list(opts.color.range) if opts.color.range is not None else None
    return res


def _range_over(grid, opts, order) -> tuple[float | None, float | None]:
    """The finite range of the property (or difference) over the active cells of ``order``."""
    active = np.asarray(grid.active, bool)
    lo, hi = np.inf, -np.inf
    for k in order:
        v = np.asarray(property_values(grid, opts.property, k, opts.diff), np.float64)[active]
        v = v[np.isfinite(v) & ((v > 0) if opts.color.log else True)]
        if v.size:
            lo, hi = min(lo, float(v.min())), max(hi, float(v.max()))
    if opts.diff is not None and np.isfinite(lo):
        m = max(abs(lo), abs(hi))
        lo, hi = -m, m
    return (lo, hi) if np.isfinite(lo) else (None, None)


__all__ = ["animate", "demo_wells", "render"]
