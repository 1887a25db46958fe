"""Overviews of a multiscale store: the finest pyramid level that fits, rendered whole."""

from __future__ import annotations

import math

from geoshade.compute.voxels.bricks import DEFAULT_TEX_LIMIT, estimate_bytes
from geoshade.core.api import render
from geoshade.io.stores.ingest import read_level, store_levels


def overview_level(path, method: str = "raycast", tex_limit: int = DEFAULT_TEX_LIMIT,
                   budget: float | None = None, max_voxels: float = 512**3) -> int:
    """The finest pyramid level of a store whose whole volume fits unbricked (texture limit and
    ``budget``) and has at most ``max_voxels`` voxels (the overview should come quickly).

    Examples
    --------
    >>> overview_level("no/such.zarr")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: no/such.zarr: no such file
    """

    n = store_levels(path)
    for k in range(n):
        vol = read_level(path, k)
        size = vol.shape_xyz
        fits = max(size) <= tex_limit and math.prod(size) <= max_voxels
        if budget is not None:
            fits = fits and estimate_bytes(size, method) <= budget
        if fits:
            return k
    return n - 1


def render_overview(path, select=None, level=None, **render_kw):
    """Render a whole ingested core from a coarse pyramid level.

    Parameters
    ----------
    path : str or Path
        A store written by :func:`geoshade.io.stores.ingest.ingest`.
    select : (lo, hi)
        Selection (the values are level 0's: ``nearest`` pyramids keep them); ``range`` is
        its deprecated name.
    level : int, optional
        Pyramid level; default :func:`overview_level`.
    **render_kw
        Passed to :func:`geoshade.core.render` (``size``, ``view``, ``method``, ``ctx`` ...).

    Returns
    -------
    image, stats
        ``stats["level"]`` is the level drawn; the world box is the whole core's, so a camera
        framed on it frames the level-0 core as well.
    """

    if select is None:
        select = render_kw.pop("range", None)
    if level is None:
        level = overview_level(path, method=render_kw.get("method", "raycast") or "raycast")
    vol = read_level(path, level)
    img, stats = render(vol, select=select, **render_kw)
    stats["level"] = int(level)
    stats["level_shape_xyz"] = list(vol.shape_xyz)
    return img, stats


__all__ = ["overview_level", "render_overview"]
