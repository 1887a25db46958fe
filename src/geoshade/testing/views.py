"""The View contract as checks a part's tests run (ours in tests/gl/test_views_common.py, and
those of a part written outside geoshade): what the shared View shape promises.

- :func:`check_framing_fixed` -- framing depends on the model only: changes of selection,
  filter, step or colour do not move the camera;
- :func:`check_stats_keys` -- the base stats keys and the part's own;
- :func:`check_empty_scene` -- an empty scene gives the one EmptySceneWarning, also in
  ``stats["warning"]``;
- :func:`check_release` with :class:`RecordingContext` -- ``release()`` frees every GPU object
  the View made through its context (``gpu_bytes`` 0), and is idempotent.

Each takes a View class (or ``geoshade.view``), a model and options; none imports moderngl.

>>> sorted(BASE_KEYS)[:3]
['first_frame_ms', 'frame_ms', 'gpu_bytes']
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable
from typing import Any, ClassVar

import numpy as np

from geoshade.errors import EmptySceneWarning, InputError

#: the stats every View's draw() gives
BASE_KEYS = frozenset({"width", "height", "method", "frame_ms", "first_frame_ms", "gpu_bytes",
                       "renderer", "kind"})


def camera_state(cam) -> tuple:
    """What a framed camera is, rounded (two equal states: the same framing)."""
    return (*np.round(cam.eye, 9), *np.round(cam.target, 9), round(cam.distance, 9),
            round(cam.half_height, 9), cam.box)


def check_framing_fixed(open_view: Callable[..., Any], changes: Iterable[dict]) -> None:
    """``open_view()`` gives a View; after each of ``changes`` (``update(**change)``) its
    framed camera and picture size are what they were."""
    with open_view() as v:
        before = camera_state(v.camera())
        _, st0 = v.draw(count=False)
        for change in changes:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", EmptySceneWarning)
                v.update(**change)
                _, st = v.draw(count=False)
            assert camera_state(v.camera()) == before, f"{change} moved the framing"
            assert (st["width"], st["height"]) == (st0["width"], st0["height"]), change


def check_stats_keys(open_view: Callable[..., Any], part_keys: Iterable[str]) -> dict:
    """The draw's stats have :data:`BASE_KEYS` and ``part_keys``, GPU bytes and no warning;
    the stats."""
    with open_view() as v:
        _, st = v.draw(frames=2)
    missing = (BASE_KEYS | set(part_keys)) - set(st)
    assert not missing, f"stats lack {sorted(missing)}"
    assert st["gpu_bytes"] > 0 and st["frame_ms"] >= 0
    assert "warning" not in st, st["warning"]
    return st


def check_empty_scene(open_view: Callable[..., Any], empty: dict) -> tuple[np.ndarray, dict]:
    """After ``update(**empty)`` a draw gives exactly one EmptySceneWarning, whose text is in
    ``stats["warning"]``; the picture and stats."""
    with open_view() as v:
        v.update(**empty)
        with warnings.catch_warnings(record=True) as rec:
            warnings.simplefilter("always")
            img, st = v.draw()
    ours = [w for w in rec if issubclass(w.category, EmptySceneWarning)]
    assert len(ours) == 1, f"{len(ours)} EmptySceneWarnings"
    assert st.get("warning") and str(ours[0].message) in st["warning"]
    return img, st


class RecordingContext:
    """A moderngl context that records every GPU object made through it (``created``)."""

    FACTORIES: ClassVar[set[str]] = {
        "buffer", "texture", "texture3d", "texture_array", "texture_cube", "depth_texture",
        "program", "vertex_array", "simple_vertex_array", "framebuffer", "renderbuffer",
        "depth_renderbuffer", "sampler", "compute_shader", "query", "scope"}

    def __init__(self, ctx):
        object.__setattr__(self, "_ctx", ctx)
        object.__setattr__(self, "created", [])

    def __getattr__(self, name):
        attr = getattr(self._ctx, name)
        if name not in self.FACTORIES:
            return attr

        def make(*a, **kw):
            obj = attr(*a, **kw)
            self.created.append((name, obj))
            return obj

        return make

    def __setattr__(self, name, value):
        setattr(self._ctx, name, value)

    def alive(self) -> list[str]:
        """The kinds of the recorded objects not released."""
        return [name for name, o in self.created if hasattr(o, "release")
                and type(getattr(o, "mglo", None)).__name__ != "InvalidObject"]


def check_release(open_view: Callable[..., Any], ctx, change: dict | None = None) -> None:
    """``open_view(ctx=RecordingContext(ctx))``, drawn, changed (``change``: new objects),
    drawn again, released: every object it made is released, ``gpu_bytes`` is 0, a second
    ``release()`` does nothing and a draw after it is one line."""
    rec = RecordingContext(ctx)
    v = open_view(ctx=rec)
    v.draw()
    if change:
        v.update(**change)
        v.draw()
    assert v.gpu_bytes > 0 and rec.created
    v.release()
    assert v.gpu_bytes == 0 and v.released
    assert rec.alive() == [], f"not released: {rec.alive()}"
    v.release()
    try:
        v.draw()
    except InputError as err:
        assert "after release" in str(err)
    else:
        raise AssertionError("draw() after release() drew")


__all__ = ["BASE_KEYS", "RecordingContext", "camera_state", "check_empty_scene",
           "check_framing_fixed", "check_release", "check_stats_keys"]
