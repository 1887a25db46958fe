"""The view a page's address carries, and what a tab opened with it does.

The page keeps its view in its address as one parameter, ``#view=`` followed by the base64url
text of ``{"file": NAME, "as": PART, "state": STATE}``: ``NAME`` the file as the catalogue names
it (never a path), ``STATE`` the View's own state (:meth:`geoshade.render.view.View.state` with
the camera of the picture: every option not at its default and the camera). The server sends the
state with every lossless frame; the page writes it into its address
(``history.replaceState``); a page opened with such an address sends it back with its ``open``.

A state from an address is input like any other, checked here before it changes anything
(:func:`restore`): it may change what the tab's panel changes (the option checks the value as any
change), turn the wells or the drape off or back on (never name a file), and give the camera;
anything else it names must be what this server opens the file with already. A state refused is
one line naming the field, and the file shows as it opens.

>>> decode(encode({"file": "case/A.EGRID", "state": {"step": 2}}))
{'file': 'case/A.EGRID', 'state': {'step': 2}}
"""

from __future__ import annotations

import base64
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from geoshade.errors import InputError
from geoshade.render.camera import Camera
from geoshade.render.state import NEVER
from geoshade.styles.options import CAMERA_OPTIONS, CameraSpec
from geoshade.styles.saved_camera import SavedCamera
from geoshade.viewer.controls import settable, to_options

#: the parameter of the address that holds the view
PARAMETER = "view"
#: options a state names by the check box that turns them on (their value names files)
SWITCHED = ("wells", "drape")
#: where the lines of a refused state start
WHERE = "the view in the address"


def encode(view: dict) -> str:
    """``view`` as the address carries it (base64url of its JSON, no padding)."""
    text = json.dumps(view, separators=(",", ":"), sort_keys=True)
    return base64.urlsafe_b64encode(text.encode()).decode().rstrip("=")


def decode(text: str) -> dict:
    """The view :func:`encode` wrote; InputError in one line for anything else."""
    try:
        raw = base64.urlsafe_b64decode(text + "=" * (-len(text) % 4))
        out = json.loads(raw.decode())
    except (ValueError, UnicodeDecodeError, RecursionError):
        raise InputError(f"{WHERE}: not readable (expected #{PARAMETER}= and base64url "
                         "JSON)") from None
    if not isinstance(out, dict):
        raise InputError(f"{WHERE}: expected a JSON object, got {type(out).__name__}")
    return out


@dataclass
class Restore:
    """What a state does to a tab's new View: ``changes`` for :meth:`View.jobs`, then the
    ``camera`` (or, without one, the named view and angles of ``spec``)."""

    changes: dict = field(default_factory=dict)
    camera: Camera | None = None
    spec: CameraSpec | None = None


def _same(a: Any, b: Any) -> bool:
    return json.dumps(a, sort_keys=True, default=str) == json.dumps(b, sort_keys=True,
                                                                     default=str)


def restore(state: dict, view, panel: list[dict], opened: dict | None = None,
            public: Callable[[Any], Any] = lambda v: v) -> Restore:
    """What ``state`` (from an address) changes on ``view``, a View just opened, whose panel
    is ``panel`` (``opened``: what its wells and drape check boxes turn on; ``public``: how the
    page sees a value, :meth:`~geoshade.web.catalog.Catalog.public`). InputError naming the
    field for a state this tab cannot take (see the module).

    Examples
    --------
    >>> from geoshade.viewer.views import open_view
    >>> from geoshade.viewer.controls import controls
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> v = open_view(synthetic_grid(4, 3, 2), size=(32, 24))
    >>> restore({"colormap": "magma", "size": [8, 8]}, v, controls(v)).changes
    {'colormap': 'magma'}
    >>> restore({"banana": 1}, v, controls(v))
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: the view in the address: 'banana' is no option of a grid view
    >>> restore({"medium": "fracture"}, v, controls(v))
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: the view in the address: medium is fixed by the server ...
    >>> v.release()
    """
    if not isinstance(state, dict):
        raise InputError(f"{WHERE}: expected {{option: value}}, got {type(state).__name__}")
    kind = view.kind
    names = set(view.Options.names())
    declared = view.Options.declarations()
    can = settable(panel)
    base = view.state()
    out = Restore()
    camera = {k: state[k] for k in CAMERA_OPTIONS if k in state}
    for name, value in state.items():
        if name == "size" or name in CAMERA_OPTIONS:
            continue   # the tab's own size; the camera's words below
        if name == "camera":
            out.camera = Camera.from_saved(SavedCamera.from_dict(value, where=f"{WHERE}: "
                                                                              "camera"))
            continue
        if name not in names:
            raise InputError(f"{WHERE}: {str(name)[:64]!r} is no option of a {kind} view")
        if name in NEVER:
            raise InputError(f"{WHERE}: {name} is not part of a view (it says where the work "
                             "runs, fixed by the server)")
        if _same(value, public(base.get(name))):
            continue   # as the file opens: nothing to change
        opt = declared.get(name, (None,))[0]
        if name not in can:
            raise InputError(f"{WHERE}: {name} is fixed by the server ({_show(value)} given, "
                             f"{_show(public(base.get(name)))} here)")
        if opt is not None and opt.control in SWITCHED:
            out.changes.update(to_options(name, bool(value), view, opened))
            continue
        out.changes[name] = tuple(value) if isinstance(value, list) else value
    if camera and out.camera is None:
        try:
            out.spec = CameraSpec.parse(None, **camera)
        except InputError as err:
            raise InputError(f"{WHERE}: {err}") from None
    return out


def _show(v: Any, limit: int = 40) -> str:
    text = json.dumps(v, default=str)
    return text if len(text) <= limit else text[:limit] + "…"


__all__ = ["PARAMETER", "SWITCHED", "Restore", "decode", "encode", "restore"]
