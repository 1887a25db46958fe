"""One-shot rendering of the digital-core part."""

from __future__ import annotations

import numpy as np

from geoshade.core.view import CoreView
from geoshade.models.volume import VoxelVolume
from geoshade.progress import Progress


def render(volume: VoxelVolume, camera=None, *, frames: int = 5, count: bool = True, ctx=None,
           progress: Progress | None = None, distributed: bool = False,
           **options) -> tuple[np.ndarray, dict]:
    """Render the voxels of ``box`` whose values lie in ``select``.

    Parameters
    ----------
    volume : VoxelVolume
    camera : Camera, CameraSpec or view name, optional
        Default: the options' camera framed on the box.
    frames : int
        Frames drawn for timing; ``frame_ms`` is the median after the first.
    count : bool
        Count the voxels drawn on the GPU (``voxels_drawn``).
    distributed : bool
        Draw on the ``scheduler`` cluster (an address, ``local:N`` or a Client): the View's
        cluster backend (:class:`~geoshade.core.distributed.ClusterBricks`), the same
        picture; its stats
        carry ``distributed`` (bytes moved, slowest worker, compositing time, bricks per
        worker).
    **options
        :class:`~geoshade.core.options.CoreOptions`: ``select=(lo, hi)`` or ``"auto"`` (the
        values up to Otsu's threshold; the old name ``range`` still works),
        ``box=[x0, y0, z0, nx, ny, nz]``, ``roi`` (``"cylinder"`` fitted to the sample,
        ``"cylinder:CX,CY,R"``) or ``mask`` (a volume, array or file; nonzero = inside): voxels
        outside are not drawn, ``method``
        (``auto raycast trefoil gs cubes``), ``colormap``/``color_range``/``color``, ``cull``,
        ``trefoil_mode``, ``bricks``, ``scheduler``, ``size``, ``view``/``azimuth``/
        ``elevation``/``zoom``/``ortho``, ``transparent`` ...

    Returns
    -------
    image : (h, w, 4) uint8
    stats : dict
        ``width height method frame_ms gpu_bytes voxels_selected voxels_drawn triangles box
        select`` (the range used), ``select_auto`` (Otsu's threshold, with ``"auto"``), ``roi``
        and more.

    Examples
    --------
    >>> import geoshade
    >>> vol = geoshade.synthetic_core(16)
    >>> img, st = geoshade.core.render(vol, select=(0, 15000), size="64x48", frames=1)
    >>> img.shape, st["method"], st["voxels_selected"] > 0
    ((48, 64, 4), 'raycast', True)
    """
    if distributed:
        options["distributed"] = True
    with CoreView(volume, ctx=ctx, progress=progress, **options) as view:
        return view.draw(camera, frames=frames, count=count)


__all__ = ["render"]
