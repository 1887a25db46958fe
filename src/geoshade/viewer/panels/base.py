"""What every control widget shares: the sink it sends to, its spec, how a value reads.

The widgets of each control type are in :mod:`geoshade.viewer.panels.widgets` (and
:mod:`geoshade.viewer.panels.cuts` for the cutting ones).
"""

from __future__ import annotations

from typing import Any, Protocol

from PySide6.QtWidgets import QLineEdit, QWidget


class Sink(Protocol):
    """What a control sends to: its panel."""

    def send(self, values: dict) -> None: ...

    def ready(self) -> bool: ...

    def error(self, text: str) -> None: ...


def label(value: Any) -> str:
    """A choice as the user reads it (as the browser's ``label``).

    >>> [label(v) for v in (None, True, False, "auto", 16)]
    ['(none)', 'yes', 'no', 'auto', '16']
    """
    return "(none)" if value is None else "yes" if value is True else "no" \
        if value is False else str(value)


def same(a: Any, b: Any) -> bool:
    """Equal as choices: True is not 1, None only None."""
    if a is None or b is None or isinstance(a, bool) or isinstance(b, bool):
        return a is b or (isinstance(a, bool) and isinstance(b, bool) and a == b)
    return a == b


def number(text: str, what: str, whole: bool = False) -> float | int:
    try:
        v = float(text)
    except ValueError:
        raise ValueError(f"{what}: expected a {'whole ' if whole else ''}number, "
                         f"got {text!r}") from None
    if whole:
        if not v.is_integer():
            raise ValueError(f"{what}: expected a whole number, got {text!r}")
        return int(v)
    return v


def fmt(v: Any) -> str:
    if isinstance(v, bool) or not isinstance(v, int | float):
        return "" if v is None else str(v)
    return str(v) if isinstance(v, int) else f"{v:.6g}"


class Control:
    """Mix-in of every control widget: its spec, the option it sets and the sink."""

    spec: dict
    sink: Sink

    def setup(self, spec: dict, sink: Sink) -> None:
        self.spec, self.sink = spec, sink
        sets = spec.get("sets", spec["name"])
        #: the option this control sets (a materials list sets two: it sends both)
        self.target = sets if isinstance(sets, str) else spec["name"]
        if spec.get("help") and isinstance(self, QWidget):
            self.setToolTip(spec["help"])

    def send_value(self, value: Any) -> None:
        self.sink.send({self.target: value})

    def put(self, value: Any) -> None:
        """Show ``value`` (signals blocked by the caller)."""


class NumberBox(QLineEdit):
    """A number's box: as narrow as a number needs (a row of six fits the side)."""

    def sizeHint(self):  # noqa: N802 (Qt's name)
        hint = super().sizeHint()
        hint.setWidth(min(hint.width(), 8 * self.fontMetrics().averageCharWidth() + 12))
        return hint


__all__ = ["Control", "NumberBox", "Sink", "fmt", "label", "number", "same"]
