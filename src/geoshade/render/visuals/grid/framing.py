"""Cameras framed on a reservoir's box: tight for flat boxes, with depth planes that hug it.

``Camera.framed`` fits the bounding sphere, which leaves a flat reservoir (kilometres wide,
a hundred metres thick) small in a perspective view. :func:`framed_camera` moves the camera
along its view direction until the box's 8 corners fill the view, and returns a
:class:`BoxCamera`, whose near and far planes follow the box's corners in every orbit, pan or
zoom (a 24-bit depth buffer then keeps the faces of thin cells apart). Framing still depends
only on the bounds.

>>> import numpy as np
>>> box = np.array([[0, 0, -100], [10000, 8000, 0.0]])
>>> from geoshade.render.camera import Camera
>>> cam = framed_camera(box, aspect=1.5)
>>> cam.distance < Camera.framed(box, aspect=1.5).distance
True
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from geoshade.render.camera import Camera


def _corners(bounds) -> np.ndarray:
    b = np.asarray(bounds, float)
    return np.array([[b[i, 0], b[j, 1], b[k, 2], 1.0] for i in (0, 1) for j in (0, 1)
                     for k in (0, 1)])


@dataclass
class BoxCamera(Camera):
    """A camera that knows the box it shows: near/far from the box's corners in view space."""

    box: tuple = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))

    def near_far(self) -> tuple[float, float]:
        near, far = super().near_far()
        if self.ortho:
            return near, far
        depth = -(_corners(self.box) @ self.view_matrix().T)[:, 2]
        lo, hi = float(depth.min()), float(depth.max())
        if lo <= 0 or hi <= lo:
            return near, far      # the eye is inside the box's depth range: sphere rule
        return max(0.9 * lo, 1e-5 * hi), 1.1 * hi


def framed_camera(bounds, view: str = "iso", azimuth=None, elevation=None, zoom: float = 1.0,
                  ortho: bool = False, aspect: float = 1.0, points=None,
                  fill: float = 0.96) -> BoxCamera:
    """A :class:`BoxCamera` showing ``bounds`` ((2, 3) world box) from ``view``.

    ``points`` ((n, 3), default the box's 8 corners) are what must fit: a grid passes its
    corner pillars at its top and bottom depths, tighter than the box of a rotated grid. Under
    perspective the camera moves along its view direction until the points fill ``fill`` of the
    view; an orthographic view gets the half height that fits them (with 2 % margin).
    """
    cam = Camera.framed(bounds, view=view, azimuth=azimuth, elevation=elevation, zoom=1.0,
                        ortho=ortho, aspect=aspect)
    pts = _corners(bounds) if points is None else np.concatenate(
        [np.asarray(points, float).reshape(-1, 3), np.ones((len(points), 1))], axis=1)

    def extent(d):
        c = replace(cam, distance=d)
        p = pts @ (c.projection_matrix() @ c.view_matrix()).T
        if np.any(p[:, 3] <= 1e-9):
            return np.inf
        return float(np.abs(p[:, :2] / p[:, 3:]).max())

    if ortho:
        v = (pts @ cam.view_matrix().T)[:, :2]
        half = max(float(np.abs(v[:, 1]).max()), float(np.abs(v[:, 0]).max()) / aspect)
        cam = replace(cam, half_height=max(half, 1e-9) * 1.02)
    elif extent(cam.distance) <= fill:
        lo, hi = cam.radius * 1e-3, cam.distance
        for _ in range(40):                  # the extent shrinks as the camera moves away
            mid = 0.5 * (lo + hi)
            if extent(mid) <= fill:
                hi = mid
            else:
                lo = mid
        cam = replace(cam, distance=hi)
    b = np.asarray(bounds, float)
    out = BoxCamera(**{f.name: getattr(cam, f.name) for f in fields(cam)},
                    box=(tuple(b[0]), tuple(b[1])))
    return out.zoomed(zoom) if zoom != 1.0 else out
