"""One-shot functions of the reservoir-grid part: ``render`` and the demo's wells."""

from __future__ import annotations

import numpy as np

from geoshade.grid.geometry import demo_wells
from geoshade.grid.view import GridView
from geoshade.models.grid import CornerPointGrid
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
    >>> from geoshade.compute.synthetic_grid import synthetic_grid
    >>> from geoshade.grid import render
    >>> img, stats = render(synthetic_grid(8, 6, 4), property="PORO", edges=True,
    ...                     size=(64, 48), frames=1)
    >>> img.shape, stats["faces_drawn"] == stats["faces"], stats["approach"]
    ((48, 64, 4), True, 3)
    """
    with GridView(grid, ctx=ctx, progress=progress, **options) as view:
        return view.draw(camera, frames=frames, count=count)


__all__ = ["demo_wells", "render"]
