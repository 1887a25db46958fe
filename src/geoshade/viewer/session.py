"""One interactive view of one part: camera interaction, named views, draw, read-out, screenshot.

Toolkit-free: the Qt window and the Jupyter widget turn their mouse, wheel and key events into
:meth:`Session.orbit` / :meth:`Session.pan` / :meth:`Session.zoom` / :meth:`Session.key`, then
call :meth:`Session.draw` and show the RGBA image.

>>> KEY_VIEWS["1"], KEY_VIEWS["t"]
('iso', 'top')
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.output import write_png
from geoshade.render.pick import Pick
from geoshade.render.view import View

#: degrees of azimuth / elevation per pixel of a left drag
DEGREES_PER_PIXEL = 0.4
#: zoom factor of one wheel notch (120 units) or one +/- key
ZOOM_STEP = 1.15
#: exaggeration factor of one [ or ] key
EXAGGERATION_STEP = 1.5
#: pixels a press may move and still be a click (a pick), not a drag
CLICK_SLOP = 3.0

#: keys of the named views: digits 1-7 and the initials (K for back)
KEY_VIEWS = {
    "1": "iso", "2": "top", "3": "bottom", "4": "front", "5": "back", "6": "left", "7": "right",
    "i": "iso", "t": "top", "b": "bottom", "f": "front", "k": "back", "l": "left", "r": "right",
}
#: other keys -> action
KEY_ACTIONS = {
    "0": "reset", "home": "reset", "o": "ortho", "+": "zoom_in", "=": "zoom_in",
    "-": "zoom_out", "s": "screenshot", "h": "help", "?": "help", "f1": "help",
    "]": "exaggerate", "[": "flatten",
}

HELP = """\
mouse     left click: pick (cell, value, depth) · left drag: orbit
          right or middle drag: pan · wheel: zoom
views     1 or I iso · 2 or T top · 3 or B bottom · 4 or F front · 5 or K back
          6 or L left · 7 or R right · 0 or Home: reset · O: orthographic on/off
keys      + / -: zoom · [ / ]: vertical exaggeration
          S or Ctrl+S: screenshot (PNG) · H or ?: this help"""


def screenshot_name(kind: str, folder=".") -> Path:
    """``geoshade-<kind>-<date>-<time>.png`` in ``folder``, not yet taken."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    p = Path(folder) / f"geoshade-{kind}-{stamp}.png"
    k = 1
    while p.exists():
        p = Path(folder) / f"geoshade-{kind}-{stamp}-{k}.png"
        k += 1
    return p


class Session:
    """Camera and frame state of one View.

    Parameters
    ----------
    view : geoshade.render.view.View
        The part's View (``CoreView``, ``GridView``, ``IsoView``, ``StacksView``).
    size : (w, h)
        Picture size in pixels.
    view : str
        Named view to start from (``iso top bottom front back left right``).
    ortho : bool
    azimuth, elevation, zoom
        As for ``Camera.framed``.

    A resize frames the model again for the new size while the camera is still the framed one
    (nothing clipped); once the user turned, panned, zoomed or loaded a camera, a resize keeps
    it. The desktop window, the notebook widget and the browser tab all resize through here.
    A View opened with a saved camera (``camera=`` a camera JSON, or a shared view's state:
    :meth:`View.state`) is looked through as it is, as ``render`` draws it, never framed again.

    Examples
    --------
    >>> from geoshade.viewer.views import open_view
    >>> from geoshade.compute.voxels.synthetic import synthetic_core
    >>> s = Session(open_view(synthetic_core(16)), size=(64, 48))
    >>> s.orbit(30, 0); img, stats = s.draw()
    >>> s.view.release()
    >>> img.shape
    (48, 64, 4)
    """

    def __init__(self, view: View, size=(800, 600), view_name: str = "iso", ortho: bool = False,
                 azimuth=None, elevation=None, zoom: float | None = None):
        self.view = view
        self.size = (max(1, int(size[0])), max(1, int(size[1])))
        view.resize(*self.size)
        # the View's own camera options (azimuth, elevation, zoom, ortho given as options) hold
        # where the arguments leave them open: the first frame is what `render` draws
        spec = view.options.camera
        self.view_name, self.ortho = view_name, bool(ortho or spec.ortho)
        #: the zoom the model was framed with (kept when it is framed again)
        self.framed_zoom = spec.zoom if zoom is None else float(zoom)
        self.camera = view.camera(
            view_name, azimuth=spec.azimuth if azimuth is None else azimuth,
            elevation=spec.elevation if elevation is None else elevation,
            zoom=self.framed_zoom, ortho=self.ortho)
        #: whether the camera is still the one the model was framed with (see the class)
        self.framed = True
        if spec.saved is not None:   # a saved camera (--camera, a shared view): looked through
            self.camera = view.camera().with_aspect(self.size[0] / self.size[1])
        self.image: np.ndarray | None = None
        self.stats: dict = {}
        self.frames = 0
        #: the last pick (None: nothing there, or none yet) and its read-out line
        self.picked: Pick | None = None
        self.pick_text = ""
        #: (x, y, camera, options) of the last pick: drawn again with other options through
        #: the same camera, the pick is made again (its line follows the property and step)
        self._picked_at: tuple | None = None
        self._press: tuple[float, float, str] | None = None
        self._pointer = (0.0, 0.0)
        self._dragging = False

    # --- camera ---------------------------------------------------------------------------------
    @property
    def camera(self):
        """The camera; setting one (a turn, a pan, a loaded camera) ends :attr:`framed`."""
        return self._camera

    @camera.setter
    def camera(self, camera) -> None:
        self._camera = camera
        self.framed = False

    def reset(self, view: str | None = None) -> None:
        """Frame the model from a named view (default: the current one)."""
        self.view_name = view or self.view_name
        self.camera = self.view.camera(self.view_name, ortho=self.ortho)
        self.framed = True

    def reframe(self) -> None:
        """Frame the (new) bounds again, keeping the direction of view."""
        c = self.camera
        self.camera = self.view.camera(self.view_name, azimuth=c.azimuth,
                                       elevation=c.elevation, zoom=self.framed_zoom,
                                       ortho=self.ortho)
        self.framed = True

    def orbit(self, dx: float, dy: float) -> None:
        """Turn by a mouse drag of ``(dx, dy)`` pixels (right: the model turns right)."""
        self.camera = self.camera.orbit(-dx * DEGREES_PER_PIXEL, dy * DEGREES_PER_PIXEL)

    def pan(self, dx: float, dy: float) -> None:
        """Move the model with a drag of ``(dx, dy)`` pixels."""
        h = self.size[1]
        self.camera = self.camera.panned(-2.0 * dx / h, 2.0 * dy / h)

    def zoom(self, steps: float) -> None:
        """Zoom in by ``steps`` wheel notches (negative: out)."""
        self.camera = self.camera.zoomed(ZOOM_STEP ** float(steps))

    # --- pointer: a press that moves is a drag (orbit, pan), one that does not is a click --------
    def press(self, x: float, y: float, button: str = "left") -> None:
        """A button went down at ``(x, y)`` (pointer pixels; ``button``: left, right, middle)."""
        self._press = (float(x), float(y), str(button))
        self._pointer = (float(x), float(y))
        self._dragging = False

    def move(self, x: float, y: float) -> bool:
        """The pointer moved with a button down: once it is more than :data:`CLICK_SLOP` pixels
        from the press, orbit (left button) or pan (others). True when the camera moved."""
        if self._press is None:
            return False
        x0, y0, button = self._press
        if not self._dragging:
            if max(abs(x - x0), abs(y - y0)) <= CLICK_SLOP:
                return False
            self._dragging = True
        dx, dy = x - self._pointer[0], y - self._pointer[1]
        self._pointer = (float(x), float(y))
        if button == "left":
            self.orbit(dx, dy)
        else:
            self.pan(dx, dy)
        return True

    def release(self, x: float, y: float, scale=(1.0, 1.0)) -> str:
        """The button went up: ``"drag"`` after a drag (draw the full frame again),
        ``"click"`` after a left click, which picks what the picture shows there (see
        :meth:`pick`; ``scale``: picture pixels per pointer pixel), else ``""``."""
        press, self._press = self._press, None
        if press is None:
            return ""
        if self._dragging or self.move(x, y):
            self._dragging = False
            return "drag"
        if press[2] != "left":
            return ""
        w, h = self.size
        px = min(max(press[0] * float(scale[0]), 0.0), w - 1.0)
        py = min(max(press[1] * float(scale[1]), 0.0), h - 1.0)
        self.pick(px, py)
        return "click"

    def pick(self, x: float, y: float) -> Pick | None:
        """What pixel ``(x, y)`` of the picture shows (:meth:`View.pick` through the camera of
        the picture on screen); kept in :attr:`picked` and, as one line, :attr:`pick_text`."""
        if self.image is None:
            self.draw()
        self.picked = self.view.pick(x, y)
        self.pick_text = (self.picked.text() if self.picked is not None
                          else f"nothing at pixel {x:.0f},{y:.0f}")
        self._picked_at = (x, y, self._camera, self.view.options)
        return self.picked

    def set_ortho(self, ortho: bool) -> None:
        self.ortho = bool(ortho)
        self.reframe()

    def resize(self, w: int, h: int) -> None:
        """A new picture size; the model framed again for it while :attr:`framed` (the same
        size changes nothing: a pick's line keeps following the options)."""
        size = (max(1, int(w)), max(1, int(h)))
        if size == self.size:
            return
        self.size = size
        self.view.resize(*self.size)
        if self.framed:
            self.reframe()

    # --- vertical exaggeration --------------------------------------------------------------------
    @property
    def exaggeration(self) -> float | None:
        """The View's vertical exaggeration, None where it does not apply."""
        return self.view.exaggeration

    def set_exaggeration(self, factor: float) -> None:
        self.view.set_exaggeration(factor)
        self.reframe()

    # --- keys -----------------------------------------------------------------------------------
    def key(self, key: str) -> str | None:
        """Apply a key (``"t"``, ``"1"``, ``"+"``, ``"home"`` …); returns the action, or None.

        ``screenshot`` and ``help`` are returned for the front end to carry out.
        """
        k = key.lower() if len(key) > 1 else key
        if k.lower() in KEY_VIEWS and len(k) == 1:
            self.reset(KEY_VIEWS[k.lower()])
            return "view"
        action = KEY_ACTIONS.get(k.lower() if k.isalpha() else k)
        if action == "reset":
            self.reset()
        elif action == "ortho":
            self.set_ortho(not self.ortho)
        elif action in ("zoom_in", "zoom_out"):
            self.zoom(1 if action == "zoom_in" else -1)
        elif action in ("exaggerate", "flatten"):
            if self.exaggeration is None:
                return None
            f = EXAGGERATION_STEP if action == "exaggerate" else 1 / EXAGGERATION_STEP
            self.set_exaggeration(self.exaggeration * f)
        return action

    # --- frames ---------------------------------------------------------------------------------
    def draw(self, interactive: bool = False) -> tuple[np.ndarray, dict]:
        """Draw one frame. ``interactive``: skip the GPU counting pass (while dragging)."""
        with warnings.catch_warnings():  # warnings are in stats["warning"] (the read-out)
            warnings.simplefilter("ignore", UserWarning)
            img, stats = self.view.draw(self.camera, count=not interactive)
        self.image, self.stats = img, stats
        self.frames += 1
        self._follow_pick()
        return img, stats

    def _follow_pick(self) -> None:
        """The last pick made again after an options change (same pixel, same camera): a
        status line belongs to the state it describes. A camera moved since: the pick stays
        (its pixel no longer shows that cell)."""
        if self._picked_at is None:
            return
        x, y, cam, opts = self._picked_at
        if cam is self._camera and opts is not self.view.options:
            self.pick(x, y)

    def readout(self) -> str:
        """``12.3 ms/frame · GPU 4.56 MiB · <the part's counts>`` (and a warning if any)."""
        s = self.stats
        if not s:
            return ""
        ex = self.exaggeration
        parts = [f"{s.get('frame_ms', 0):.1f} ms/frame",
                 f"GPU {s.get('gpu_bytes', 0) / 2**20:.2f} MiB", self.view.readout(s)]
        if ex is not None:
            parts.append(f"exaggeration ×{ex:g}")
        if s.get("warning"):
            parts.append(f"⚠ {s['warning']}")
        return " · ".join(p for p in parts if p)

    def screenshot(self, path=None) -> Path:
        """Write the current picture as PNG (atomically); draws one first if there is none."""

        if self.image is None:
            self.draw()
        path = Path(path) if path is not None else screenshot_name(self.view.kind)
        if path.suffix.lower() != ".png":
            raise InputError(f"{path}: screenshots are PNG files; give a name ending in .png")
        return write_png(path, self.image)
