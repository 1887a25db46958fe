"""Picking: what the picture shows at a pixel — the cell, voxel, interval or surface point, its
value and depth (:meth:`geoshade.render.view.View.pick`).

A pick casts the pixel's ray on the CPU (:mod:`geoshade.compute.pick`) through what the View
shows now (the grid's slice, filter, plane and active cells, the core's selection and box, the
stacks' hidden materials and section, the isosurface of the shown step), so it is the same on
llvmpipe and on any GPU and needs no read-back. Each part registers its picker here
(:func:`register_picker`, from ``geoshade.<part>.pick``); the View base dispatches by its
``kind``, so ``render`` does not import the parts.

>>> p = Pick("grid", (2, 4, 1), (120.0, 45.0, -1012.5), 1012.5, 0.21, "PORO",
...          label="I=3 J=5 K=2", ijk_label="I=3 J=5 K=2", length_unit="m")
>>> p.text()
'I=3 J=5 K=2 · PORO 0.21 · depth 1012.5 m · x 120 y 45 z -1012.5'
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from geoshade.compute.pick import Ray, unproject
from geoshade.errors import InputError

#: kind -> ``picker(view, ray) -> Pick | None`` (the ray in the View's display world)
PICKERS: dict[str, Callable[[Any, Ray], Any]] = {}


def register_picker(kind: str):
    """Decorator: ``picker(view, ray)`` picks for the Views of ``kind``."""

    def deco(fn):
        PICKERS[kind] = fn
        return fn

    return deco


def _num(v) -> str:
    if v is None:
        return ""
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    f = float(v)
    if not math.isfinite(f):
        return "no value"
    return f"{f:.1f}" if abs(f) >= 1e5 else f"{f:.6g}"


@dataclass(frozen=True)
class Pick:
    """What one pixel shows.

    kind:   ``core grid iso stacks``
    index:  grid: (i, j, k) 0-based; core: voxel (x, y, z) in the volume; stacks: (column x,
            column y, interval number in the column from the bottom, 0-based); iso: the nearest
            grid point (x, y, z) of the field (on a corner-point grid: the cell i, j, k)
    world:  (x, y, z) hit point in model units, z up, exaggeration removed (a grid: map x, y)
    depth:  positive down: a grid's TVD, a core's distance below its top face; z otherwise
    value:  the shown property or field at the pick (None where nothing is coloured)
    name:   the shown property, field or variable; ``unit`` its unit where known
    label:  the index as a line (``I=3 J=5 K=2``, ``voxel x=4 y=5 z=6`` ...)
    ijk_label: 1-based ``I=3 J=5 K=2`` where the pick is a grid cell ("" otherwise)
    length_unit: of ``world`` and ``depth``
    vertical: what ``depth`` is called in the read-out: ``depth`` (positive down), or
            ``elevation`` where z is up (stack models and terrains)
    extra:  more (name, text) pairs for the read-out (material, step ...)
    pixel:  (x, y) picked; ``t``: position on the pixel's ray (0 near, 1 far)
    """

    kind: str
    index: tuple[int, ...]
    world: tuple[float, float, float]
    depth: float
    value: Any = None
    name: str = ""
    unit: str = ""
    label: str = ""
    ijk_label: str = ""
    length_unit: str = ""
    extra: tuple[tuple[str, str], ...] = ()
    pixel: tuple[float, float] | None = None
    t: float = 0.0
    vertical: str = "depth"

    def text(self) -> str:
        """One line: where, what, how deep, which point."""
        lu = f" {self.length_unit}" if self.length_unit else ""
        parts = [self.label or " ".join(map(str, self.index))]
        if self.value is not None or self.name:
            unit = f" {self.unit}" if self.unit and self.value is not None else ""
            parts.append(f"{self.name} {_num(self.value)}{unit}".strip())
        parts += [v if v.startswith(k) else f"{k} {v}" for k, v in self.extra]
        if self.name != self.vertical:   # a terrain's value is its elevation already
            parts.append(f"{self.vertical} {_num(self.depth)}{lu}")
        x, y, z = self.world
        parts.append(f"x {_num(x)} y {_num(y)} z {_num(z)}")
        return " · ".join(p for p in parts if p)

    def as_dict(self) -> dict:
        """Plain values (for JSON)."""
        value = self.value
        if isinstance(value, np.generic):
            value = value.item()
        if isinstance(value, float) and not math.isfinite(value):
            value = None
        return {"kind": self.kind, "index": [int(v) for v in self.index],
                "world": [float(v) for v in self.world], "depth": float(self.depth),
                "value": value, "name": self.name, "unit": self.unit, "label": self.label,
                "ijk_label": self.ijk_label, "length_unit": self.length_unit,
                "vertical": self.vertical, "extra": dict(self.extra),
                "pixel": None if self.pixel is None else [float(v) for v in self.pixel],
                "text": self.text()}


def pixel_ray(camera, size, x: float, y: float) -> Ray:
    """The ray of pixel ``(x, y)`` (origin top-left, as in the image array; the pixel's centre
    ``(x + 0.5, y + 0.5)`` is cast) of a ``size`` = (w, h) picture drawn with ``camera``, in
    world coordinates, from the near plane (t = 0) to the far plane (t = 1).

    >>> from geoshade.render.camera import Camera
    >>> cam = Camera.framed(np.array([[0, 0, 0], [10, 10, 10.]]), view="top", ortho=True)
    >>> r = pixel_ray(cam, (100, 100), 49.5, 49.5)
    >>> np.round(r.origin[:2], 6).tolist(), bool(r.direction[2] < 0)
    ([5.0, 5.0], True)
    """
    w, h = (int(v) for v in size)
    if not (0 <= x < w and 0 <= y < h):
        raise InputError(f"pick: pixel ({x:g}, {y:g}) is outside the {w}x{h} picture")
    cam = camera.with_aspect(w / h)
    vp = cam.projection_matrix() @ cam.view_matrix()
    ndc_x = (float(x) + 0.5) / w * 2.0 - 1.0
    ndc_y = 1.0 - (float(y) + 0.5) / h * 2.0
    return unproject(np.linalg.inv(vp), ndc_x, ndc_y, eye=None if cam.ortho else cam.eye)


def pick_view(view, x: float, y: float, camera=None):
    """:meth:`View.pick` (see there)."""
    if view.released:
        raise InputError(f"{view.kind} view: pick() after release()")
    picker = PICKERS.get(view.kind)
    if picker is None:
        raise InputError(f"pick: the {view.kind or 'view'} view cannot pick")
    last = getattr(view, "_last_frame", None)
    if camera is None and last is not None:
        cam, size = last[:2]
    else:
        size = tuple(last[1]) if last is not None else tuple(view.size)
        cam = view._camera_for(camera)
    ray = pixel_ray(cam, size, x, y)
    hit = picker(view, ray)
    if hit is None:
        return None

    return replace(hit, pixel=(float(x), float(y)))


def in_refinement(hit: Pick, refinement) -> Pick:
    """``hit`` (a pick of a local grid refinement's own View) named by the refinement, its
    local I, J, K and its host cell (:meth:`~geoshade.models.grid.Refinement.cell_label`)."""
    label = refinement.cell_label(*hit.index)
    return replace(hit, label=label, ijk_label=label,
                   extra=(("LGR", refinement.name), *hit.extra))


def nearest_with_refinements(view, ray, picker: Callable) -> Pick | None:
    """``picker(view, ray)``, or the nearer hit of a local grid refinement the View draws
    (``view.refined``, whose ``picks(ray, picker)`` names its hits): the grid part's cells and
    the iso part's surfaces alike."""
    hit = picker(view, ray)
    refined = getattr(view, "refined", None)
    if refined is None:
        return hit
    hits = [h for h in (hit, *refined.picks(ray, picker)) if h is not None]
    return min(hits, key=lambda h: h.t) if hits else None


__all__ = ["PICKERS", "Pick", "in_refinement", "nearest_with_refinements", "pick_view",
           "pixel_ray", "register_picker"]
