"""One-shot rendering of the stacks part, and the section planes of a viewer."""

from __future__ import annotations

import numpy as np

from geoshade.models.stacks import StackModel
from geoshade.stacks.convert import convert, memory_stats
from geoshade.stacks.options import section_box
from geoshade.stacks.view import StacksView, demo_drape
from geoshade.styles.options import Plane


# ==============================================================================================
# rendering
# ==============================================================================================
def render(model, camera=None, *, frames: int = 5, count: bool = True, ctx=None,
           progress=None, **options) -> tuple[np.ndarray, dict]:
    """Ray-cast a stack model with the geologist's tools of Section 4.3.

    Parameters
    ----------
    model : StackModel, or anything :func:`convert` takes
    camera : Camera, CameraSpec or view name, optional
        Default: the options' camera framed on the model's box.
    frames : int
        Frames timed; ``frame_ms`` is the median after the first.
    **options
        :class:`~geoshade.stacks.options.StacksOptions`: ``layout`` (``textures
        r-supertexels l-supertexels texture3d ssbo dense``), ``hide``, ``opacity``, ``plane``
        (the old ``section`` still works), ``boreholes``, ``drape`` (a georeferenced GeoTIFF
        lands where it says), ``exaggeration``, ``legend``, ``walk``, ``walk_from``,
        ``kernel``, ``smooth``, ``lighting``, ``top`` (``auto smooth flat``: terrain tops
        interpolated between column centres), ``top_normals``, ``size``, the camera ...

    Returns
    -------
    image : (h, w, 4) uint8
    stats : dict
        ``width height method frame_ms gpu_bytes columns intervals max_intervals mrays_per_s``
        and more (``drape``: the picture shows the drape, ``drape_pixels``, ``top``).

    Examples
    --------
    >>> import geoshade.stacks as st
    >>> from geoshade.compute.stacks import synthetic_layers
    >>> img, stats = st.render(synthetic_layers(16, 12, 20), size=(64, 48), frames=1)
    >>> stats["method"], img.shape
    ('ssbo', (48, 64, 4))
    """
    with StacksView(model, ctx=ctx, progress=progress, **options) as view:
        return view.draw(camera, frames=frames, count=count)


def section_plane(model: StackModel, axis: str, fraction: float, flip: bool = False) -> Plane:
    """The plane across ``axis`` at ``fraction`` of the occupied box that keeps the near side
    (coordinates below the plane; the far side with ``flip``).

    >>> from geoshade.compute.stacks import synthetic_layers
    >>> section_plane(synthetic_layers(10, 8, 12), "x", 0.5)
    Plane(normal=(-1.0, 0.0, 0.0), offset=-5.0)
    """
    return Plane.across(section_box(model), axis, fraction, flip)


__all__ = ["convert", "demo_drape", "memory_stats", "render", "section_plane"]
