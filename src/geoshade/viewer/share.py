"""Views you can share: a View's state (its options and camera) as JSON text, and back.

:func:`view_text` is what the desktop viewer's *Copy view* puts on the clipboard and the
notebook widget's ``state()`` gives: the data set's file, the part, and :meth:`View.state
<geoshade.render.view.View.state>` (every option not at its default, the camera the picture is
drawn with). :func:`read_view` reads such a text back (or a bare state, as ``view.state()``
gives it) and says in one line what is wrong with one that is not; ``geoshade.view(model,
**shared.state)`` draws the same picture pixel for pixel at the same size, and *Open view*
opens it in the viewer.

>>> shared = read_view('{"geoshade_view": 1, "file": "/runs/CASE.EGRID", "part": "grid", '
...                    '"state": {"property": "SWAT", "step": 12}}')
>>> shared.file, shared.part, shared.state
('/runs/CASE.EGRID', 'grid', {'property': 'SWAT', 'step': 12})
>>> read_view('{"property": "PORO"}').state     # a bare state: the data set shown
{'property': 'PORO'}
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from geoshade.errors import InputError
from geoshade.render.state import left_out

#: the key (and version) that marks a shared view's JSON
MARK = "geoshade_view"
#: the parts a shared view may name
PARTS = ("core", "grid", "iso", "stacks")


@dataclass(frozen=True)
class SharedView:
    """A shared view: ``file`` (None: the data set shown), ``part`` (None: as the file is
    read) and ``state`` (options by the names ``geoshade.view`` takes, ``camera`` among
    them)."""

    file: str | None
    part: str | None
    state: dict

    def settings(self) -> dict:
        """The options a viewer opens the data with: the state but its picture size (the
        viewer's window or widget decides that)."""
        return {k: v for k, v in self.state.items() if k != "size"}


def view_document(view, camera=None, source: Any = None) -> dict:
    """The shared view of ``view`` drawn through ``camera``, as a dict (see :func:`view_text`)."""
    doc: dict[str, Any] = {MARK: 1}
    if isinstance(source, str | Path):
        doc["file"] = str(Path(source).expanduser().resolve())
    doc["part"] = view.kind
    doc["state"] = view.state(camera)
    missing = left_out(view)
    if missing:   # said in the text, so whoever opens it knows what it does not carry
        doc["left_out"] = missing
    return doc


def view_text(view, camera=None, source: Any = None) -> str:
    """JSON text of the view: ``{"geoshade_view": 1, "file": ..., "part": ..., "state":
    {...}}`` (``file`` where ``source`` is a path; ``left_out``: options set to values no
    JSON carries, such as wells read from files)."""
    return json.dumps(view_document(view, camera, source), indent=1)


def read_view(text: str) -> SharedView:
    """A shared view from its JSON text (:func:`view_text`, or a bare :meth:`View.state`).

    Raises
    ------
    InputError
        One line: the text is no JSON object, or a field has the wrong type.
    """
    text = (text or "").strip()
    if not text:
        raise InputError("view: nothing to open; copy a view first (Copy view, or "
                         "view.state() as JSON)")
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as err:
        raise InputError(f"view: not JSON ({err.msg} at line {err.lineno} column "
                         f"{err.colno}); expected the text Copy view gives") from None
    if not isinstance(doc, dict):
        raise InputError(f"view: expected a JSON object (Copy view's text), got "
                         f"{type(doc).__name__}")
    if MARK not in doc:   # a bare state
        return SharedView(None, None, doc)
    state = doc.get("state")
    if not isinstance(state, dict):
        raise InputError(f"view: \"state\" must be an object of options, got {state!r:.60}")
    file = doc.get("file")
    if file is not None and not isinstance(file, str):
        raise InputError(f"view: \"file\" must be a path, got {file!r:.60}")
    part = doc.get("part")
    if part is not None and part not in PARTS:
        raise InputError(f"view: \"part\" must be one of {', '.join(PARTS)}, got {part!r:.60}")
    return SharedView(file, part, state)


__all__ = ["MARK", "SharedView", "read_view", "view_document", "view_text"]
