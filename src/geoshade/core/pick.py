"""Picking in the digital-core view: the first selected voxel along a pixel's ray.

The ray (the vertical exaggeration undone) walks the voxels of the shown box in order
(:func:`geoshade.compute.pick.ray_cells`, at most ``nx + ny + nz`` voxels; only those are read,
from memory, a memmap or a dask array); the first whose value lies in the selection
(``lo <= v <= hi``, as the bit maps select) and, where the options have a cutting plane, whose
centre it keeps, is the pick. Its depth is the distance below the top face of the whole
volume (z up), as a core is logged from its top.
"""

from __future__ import annotations

import numpy as np

from geoshade.compute.pick import Ray, gather, ray_cells
from geoshade.core.view import model_matrix
from geoshade.render.pick import Pick, register_picker


@register_picker("core")
def pick_core(view, ray: Ray) -> Pick | None:
    """The voxel a CoreView shows along ``ray`` (display world), or None."""

    vol, o = view.volume, view.options
    box = o.box
    m = model_matrix(vol, box)  # true geometry: what the pick reports
    shown = model_matrix(vol, box, float(getattr(o, "exaggeration", 1.0)))  # what was drawn
    local = ray.transformed(np.linalg.inv(shown))  # box index space: voxel v covers [v, v + 1]
    cells, t_in, _ = ray_cells(local, box.size)
    if cells.size == 0:
        return None
    xyz = cells + np.asarray(box.offset, np.int64)
    values = gather(vol.data, xyz[:, 2], xyz[:, 1], xyz[:, 0])
    lo, hi = o.select
    with np.errstate(invalid="ignore"):
        sel = (values >= lo) & (values <= hi)
    roi = getattr(o, "roi", None)
    if roi is not None and sel.any():  # voxels outside the ROI are not drawn
        if hasattr(roi, "contains"):
            sel &= roi.contains(xyz[:, 0], xyz[:, 1], xyz[:, 2])
        else:
            sel &= gather(roi.data, xyz[:, 2], xyz[:, 1], xyz[:, 0]) != 0
    plane = getattr(o, "plane", None)
    if plane is not None and sel.any():
        if plane.offset is None:  # through the centre of what is shown
            plane = plane.resolve(vol.bounds(box).mean(axis=0))
        centres = (cells + 0.5) @ m[:3, :3].T + m[:3, 3]
        sel &= plane.keeps(centres)
    if not sel.any():
        return None
    q = int(np.argmax(sel))
    t = float(t_in[q])
    world = m[:3, :3] @ local.at(t) + m[:3, 3]
    v = values[q]
    value = v.item() if isinstance(v, np.generic) else v
    x, y, z = (int(c) for c in xyz[q])
    meta = vol.meta or {}
    top = float(vol.bounds()[1, 2])   # depth: how far below the volume's top face
    return Pick("core", (x, y, z), (float(world[0]), float(world[1]), float(world[2])),
                top - float(world[2]), value, str(meta.get("variable") or "value"),
                unit=str(meta.get("value_unit") or ""), label=f"voxel x={x} y={y} z={z}",
                length_unit=view._length_unit(), t=t)


__all__ = ["pick_core"]
