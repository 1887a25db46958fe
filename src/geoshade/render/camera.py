"""Orbit camera with perspective and orthographic projection, framed from bounds only.

World axes: x east, y north, z up. Named views look at the box centre from a direction:
``top`` (from +z, screen-up = +y), ``bottom`` (from -z), ``front`` (from -y), ``back`` (+y),
``left`` (-x), ``right`` (+x), ``iso`` (azimuth 45°, elevation 35.26°).

>>> import numpy as np
>>> cam = Camera.framed(np.array([[0, 0, 0], [10, 10, 10.]]), view="top", ortho=True)
>>> cam.eye.round(3).tolist()[:2]
[5.0, 5.0]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from geoshade.io.output import write_text
from geoshade.styles.options import VIEWS, CameraSpec, SavedCamera

__all__ = ["VIEWS", "Camera", "CameraSpec", "SavedCamera", "look_at", "orthographic",
           "perspective"]


def _corners(bounds) -> np.ndarray:
    """(8, 4) homogeneous corners of a (2, 3) box."""
    b = np.asarray(bounds, float)
    return np.array([[b[i, 0], b[j, 1], b[k, 2], 1.0] for i in (0, 1) for j in (0, 1)
                     for k in (0, 1)])


def _normalize(v):
    n = np.linalg.norm(v)
    return v / n if n > 0 else v


def look_at(eye, target, up) -> np.ndarray:
    """4×4 view matrix (row-major numpy; transpose for GL)."""
    f = _normalize(np.asarray(target, float) - eye)
    s = _normalize(np.cross(f, up))
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def perspective(fovy_deg, aspect, near, far) -> np.ndarray:
    f = 1.0 / math.tan(math.radians(fovy_deg) / 2)
    m = np.zeros((4, 4))
    m[0, 0], m[1, 1] = f / aspect, f
    m[2, 2] = (far + near) / (near - far)
    m[2, 3] = 2 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


def orthographic(half_h, aspect, near, far) -> np.ndarray:
    m = np.eye(4)
    m[0, 0] = 1.0 / (half_h * aspect)
    m[1, 1] = 1.0 / half_h
    m[2, 2] = -2.0 / (far - near)
    m[2, 3] = -(far + near) / (far - near)
    return m


@dataclass
class Camera:
    """An orbit camera.

    target: (3,) float  point the camera turns around (world units)
    distance: float     eye-to-target distance
    azimuth, elevation: degrees (see VIEWS)
    fovy: float         vertical field of view in degrees (perspective)
    ortho: bool         orthographic projection; ``half_height`` world units fill half the view
    aspect: float       width / height
    radius: float       radius of the framed bounds, for near/far planes
    box: ((3,), (3,))   the framed box, or None: near/far follow its corners (perspective)
    viewport: (x0, y0, x1, y1) or None   the part of the picture (normalised device
                        coordinates, -1..1) the view fills: annotations keep the rest
    """

    target: np.ndarray = field(default_factory=lambda: np.zeros(3))
    distance: float = 10.0
    azimuth: float = 45.0
    elevation: float = 35.26
    fovy: float = 30.0
    ortho: bool = False
    half_height: float = 1.0
    aspect: float = 1.0
    radius: float = 1.0
    box: tuple | None = None
    viewport: tuple | None = None

    @classmethod
    def framed(cls, bounds, view: str | CameraSpec = "iso", azimuth=None, elevation=None,
               zoom: float = 1.0, ortho: bool = False, aspect: float = 1.0, fovy: float = 30.0,
               points=None, fill: float = 0.96, viewport=None) -> Camera:
        """The camera that shows the whole of ``bounds`` ((2, 3) min/max corners) from ``view``.

        This is the one framing of every part. ``points`` ((n, 3), default the box's 8
        corners) are what must fit: a grid passes its corner pillars at its top and bottom
        depths, tighter than the box of a rotated grid. Under perspective the camera moves
        along its view direction until the points fill ``fill`` of the view (a flat reservoir
        is not left small inside its bounding sphere); an orthographic view gets the half
        height that fits them with 2 % margin. The near and far planes then follow the box's
        corners in every orbit, pan or zoom (a 24-bit depth buffer keeps thin cells apart).

        The framing depends only on the bounds, never on what is selected inside them, so two
        pictures of the same box are pixel-aligned.

        ``view`` may be a :class:`CameraSpec`; then ``azimuth``/``elevation``/``zoom``/
        ``ortho`` given here override it. ``viewport`` (NDC rectangle): fit into that part of
        the picture only.
        """
        full_aspect = aspect
        if viewport is not None:
            x0, y0, x1, y1 = (float(v) for v in viewport)
            aspect = aspect * (x1 - x0) / (y1 - y0)
        spec = CameraSpec.parse(view, azimuth=azimuth, elevation=elevation,
                                zoom=None if zoom == 1.0 else zoom, ortho=ortho or None)
        if spec.saved is not None:  # a camera saved after framing: used as it is
            return cls.from_saved(spec.saved)
        b = np.asarray(bounds, float)
        az, el = spec.angles()
        centre = b.mean(axis=0)
        radius = max(float(np.linalg.norm(b[1] - b[0])) / 2, 1e-9)
        cam = cls(target=centre, azimuth=az, elevation=el, fovy=fovy, ortho=spec.ortho,
                  aspect=aspect, radius=radius)
        corners = _corners(b)
        pts = corners if points is None else np.concatenate(
            [np.asarray(points, float).reshape(-1, 3), np.ones((len(points), 1))], axis=1)
        if spec.ortho:
            cam.distance = 2.0 * radius
            v = (pts @ cam.view_matrix().T)[:, :2]
            half = max(float(np.abs(v[:, 1]).max()), float(np.abs(v[:, 0]).max()) / aspect)
            cam.half_height = max(half, 1e-9) * 1.02
        else:
            half = math.radians(fovy) / 2
            half_x = math.atan(math.tan(half) * aspect)
            cam.distance = radius / math.sin(min(half, half_x))

            def extent(d):
                c = replace(cam, distance=d)
                p = pts @ (c.projection_matrix() @ c.view_matrix()).T
                if np.any(p[:, 3] <= 1e-9):
                    return np.inf
                return float(np.abs(p[:, :2] / p[:, 3:]).max())

            if extent(cam.distance) <= fill:
                lo, hi = cam.radius * 1e-3, cam.distance
                for _ in range(40):  # the extent shrinks as the camera moves away
                    mid = 0.5 * (lo + hi)
                    if extent(mid) <= fill:
                        hi = mid
                    else:
                        lo = mid
                cam.distance = hi
        cam.box = (tuple(float(v) for v in b[0]), tuple(float(v) for v in b[1]))
        if viewport is not None:
            cam.aspect, cam.viewport = full_aspect, tuple(float(v) for v in viewport)
        return cam.zoomed(spec.zoom) if spec.zoom != 1.0 else cam

    # --- saved cameras (JSON) ------------------------------------------------------------------
    def saved(self) -> SavedCamera:
        """This camera as a :class:`SavedCamera` (every value exact).

        >>> cam = Camera.framed(np.array([[0, 0, 0], [4, 3, 2.]]), azimuth=30, aspect=1.5)
        >>> back = Camera.from_saved(SavedCamera.from_json(cam.saved().to_json()))
        >>> bool(np.array_equal(back.view_matrix(), cam.view_matrix())
        ...      and np.array_equal(back.projection_matrix(), cam.projection_matrix()))
        True
        """
        box = None if self.box is None else (tuple(float(v) for v in self.box[0]),
                                             tuple(float(v) for v in self.box[1]))
        return SavedCamera(tuple(float(v) for v in self.target),  # type: ignore[arg-type]
                           float(self.distance), float(self.azimuth), float(self.elevation),
                           float(self.fovy), bool(self.ortho), float(self.half_height),
                           float(self.aspect), float(self.radius), box,
                           None if self.viewport is None else
                           tuple(float(v) for v in self.viewport))

    @classmethod
    def from_saved(cls, saved: SavedCamera) -> Camera:
        """The camera a :class:`SavedCamera` describes."""
        return cls(target=np.array(saved.target, dtype=float), distance=saved.distance,
                   azimuth=saved.azimuth, elevation=saved.elevation, fovy=saved.fovy,
                   ortho=saved.ortho, half_height=saved.half_height, aspect=saved.aspect,
                   radius=saved.radius, box=saved.box, viewport=saved.viewport)

    def save(self, path) -> None:
        """Write this camera as JSON (atomic); ``CameraSpec.parse(path)``, ``--camera PATH``
        and the viewer's "Load camera…" read it back."""

        write_text(path, self.saved().to_json())

    @classmethod
    def load(cls, path) -> Camera:
        """The camera of a JSON file written by :meth:`save` or ``--save-camera``."""
        return cls.from_saved(SavedCamera.read(path))

    # --- derived ----------------------------------------------------------------------------
    @property
    def direction(self) -> np.ndarray:
        """Unit vector from the target towards the eye."""
        az, el = math.radians(self.azimuth), math.radians(self.elevation)
        return np.array([math.sin(az) * math.cos(el), -math.cos(az) * math.cos(el), math.sin(el)])

    @property
    def eye(self) -> np.ndarray:
        return self.target + self.distance * self.direction

    @property
    def up(self) -> np.ndarray:
        if abs(self.elevation) > 89.999:
            az = math.radians(self.azimuth)
            # screen-up is the horizontal direction the camera would face: +y for az = 0
            return np.array([-math.sin(az), math.cos(az), 0.0])
        return np.array([0.0, 0.0, 1.0])

    def view_matrix(self) -> np.ndarray:
        return look_at(self.eye, self.target, self.up)

    def near_far(self) -> tuple[float, float]:
        far = self.distance + 2.0 * self.radius
        if self.ortho:
            return max(self.distance - 2.0 * self.radius, -far), far
        near = max(self.distance - 2.0 * self.radius, far * 1e-4, 1e-6)
        if self.box is not None:
            depth = -(_corners(self.box) @ self.view_matrix().T)[:, 2]
            lo, hi = float(depth.min()), float(depth.max())
            if lo > 0 and hi > lo:  # else the eye is inside the box's depth range: sphere rule
                return max(0.9 * lo, 1e-5 * hi), 1.1 * hi
        return near, far

    def projection_matrix(self) -> np.ndarray:
        near, far = self.near_far()
        if self.viewport is None:
            if self.ortho:
                return orthographic(self.half_height, self.aspect, near, far)
            return perspective(self.fovy, self.aspect, near, far)
        x0, y0, x1, y1 = self.viewport
        aspect = self.aspect * (x1 - x0) / (y1 - y0)
        base = (orthographic(self.half_height, aspect, near, far) if self.ortho
                else perspective(self.fovy, aspect, near, far))
        fit = np.eye(4)  # clip space: x' = sx x + tx w, y' = sy y + ty w
        fit[0, 0], fit[0, 3] = (x1 - x0) / 2, (x1 + x0) / 2
        fit[1, 1], fit[1, 3] = (y1 - y0) / 2, (y1 + y0) / 2
        return fit @ base

    def units_per_pixel(self, height: int) -> float:
        """World units per pixel of an orthographic picture ``height`` pixels high."""
        span = 2.0 if self.viewport is None else self.viewport[3] - self.viewport[1]
        return 2.0 * self.half_height / (span / 2.0 * height)

    # --- interaction -------------------------------------------------------------------------
    def orbit(self, d_azimuth: float, d_elevation: float) -> Camera:
        el = float(np.clip(self.elevation + d_elevation, -90.0, 90.0))
        return replace(self, azimuth=self.azimuth + d_azimuth, elevation=el)

    def zoomed(self, factor: float) -> Camera:
        if self.ortho:
            return replace(self, half_height=self.half_height / factor)
        return replace(self, distance=self.distance / factor)

    def panned(self, dx: float, dy: float) -> Camera:
        """Move the target by (dx, dy) in screen units of the view's half height."""
        v = self.view_matrix()
        scale = self.half_height if self.ortho else self.distance * math.tan(
            math.radians(self.fovy) / 2)
        shift = (v[0, :3] * dx + v[1, :3] * dy) * scale
        return replace(self, target=self.target + shift)

    def with_aspect(self, aspect: float) -> Camera:
        return replace(self, aspect=aspect)
