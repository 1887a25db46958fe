"""The Qt widgets of the grid's cutting and summary controls (types of
:data:`geoshade.viewer.controls.TYPES`, rendered once, as the browser renders them):

- ``ijk``: from and to of each of I, J and K (1-based and both shown, as ECLIPSE counts; sent
  as ``[[i0, i1], [j0, j1], [k0, k1]]``, 0-based and end exclusive);
- ``ranges``: the min and max of each property's values (a slider and a box for each end of the
  chosen property; every narrowed property is kept): sent as ``{NAME: [lo, hi]}`` (an end at
  the property's extreme is open: None), ``{}`` for none;
- ``vectors``: summary vectors typed as a comma-separated list with completion over the case's
  vectors (wildcards such as ``WOPR:*`` too): sent as a list, None for none.
"""

from __future__ import annotations

import math
from typing import Any

from PySide6.QtCore import QSignalBlocker, QStringListModel, Qt
from PySide6.QtWidgets import (
    QComboBox,
    QCompleter,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSlider,
    QSpinBox,
    QWidget,
)

from geoshade.viewer.panels.base import Control, NumberBox, Sink, fmt, number
from geoshade.viewer.values import slider_value

#: slider positions between a property's min and max
SLIDER_STEPS = 1000


class IjkControl(QWidget, Control):
    """From and to of each of I, J, K (see the module); each change is sent at once."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        self.dims = [int(n) for n in spec.get("dims") or (1, 1, 1)]
        grid = QGridLayout(self)
        grid.setContentsMargins(0, 0, 0, 0)
        self.lo: list[QSpinBox] = []
        self.hi: list[QSpinBox] = []
        for a, (axis, n) in enumerate(zip("IJK", self.dims, strict=True)):
            lo, hi = QSpinBox(), QSpinBox()
            for box, end in ((lo, "first"), (hi, "last")):
                box.setRange(1, max(n, 1))
                box.setKeyboardTracking(False)   # typed numbers are sent when complete
                box.setToolTip(f"the {end} {axis} shown (1 to {n}, both ends shown)")
            lo.setValue(1)
            hi.setValue(n)
            lo.valueChanged.connect(lambda _v, a=a: self._changed(a, "lo"))
            hi.valueChanged.connect(lambda _v, a=a: self._changed(a, "hi"))
            grid.addWidget(QLabel(axis), a, 0)
            grid.addWidget(lo, a, 1)
            grid.addWidget(QLabel("to"), a, 2)
            grid.addWidget(hi, a, 3)
            grid.addWidget(QLabel(f"of {n}"), a, 4)
            self.lo.append(lo)
            self.hi.append(hi)

    def _changed(self, axis: int, end: str) -> None:
        lo, hi = self.lo[axis], self.hi[axis]
        if lo.value() > hi.value():   # the other end follows: never an empty range
            other = hi if end == "lo" else lo
            with QSignalBlocker(other):
                other.setValue(lo.value() if end == "lo" else hi.value())
        self.send_value(self.value())

    def value(self) -> list[list[int]]:
        """``[[i0, i1], [j0, j1], [k0, k1]]``: 0-based, end exclusive."""
        return [[lo.value() - 1, hi.value()] for lo, hi in zip(self.lo, self.hi, strict=True)]

    def set_range(self, axis: str, first: int, last: int) -> None:
        """Show cells ``first`` to ``last`` (1-based, both shown) of ``axis`` (I, J or K) as a
        user would (for scripts and tests); sent once."""
        a = "IJK".index(axis.upper())
        with QSignalBlocker(self.lo[a]), QSignalBlocker(self.hi[a]):
            self.lo[a].setValue(int(first))
            self.hi[a].setValue(int(last))
        self._changed(a, "hi")

    def put(self, value: Any) -> None:
        pairs = value if isinstance(value, list | tuple) and len(value) == 3 else \
            [[0, n] for n in self.dims]
        for a, pair in enumerate(pairs):
            lo = 0 if pair[0] is None else int(pair[0])
            hi = self.dims[a] if pair[1] is None else int(pair[1])
            self.lo[a].setValue(min(max(lo + 1, 1), self.dims[a]))
            self.hi[a].setValue(min(max(hi, 1), self.dims[a]))


class RangesControl(QWidget, Control):
    """The value range of each property (see the module): choose a property, move its min and
    max sliders (sent when released) or type its ends; ``clear`` lets every cell through
    again."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        #: name -> (min, max) of its values (the spec's items)
        self.extent: dict[str, tuple[float, float]] = {
            str(n): (float(lo), float(hi)) for n, lo, hi in spec.get("items") or ()
            if lo is not None and hi is not None}
        #: the narrowed properties: name -> [lo, hi] (None: that end open)
        self.ranges: dict[str, list] = {}
        self.name = QComboBox()
        self.name.addItems(list(self.extent))
        self.name.setToolTip("the property whose range the sliders show")
        self.name.currentTextChanged.connect(self._show_chosen)
        self.clear = QPushButton("clear")
        self.clear.setToolTip("show the cells of every value again")
        self.clear.clicked.connect(self._clear)
        self.sliders, self.boxes = [], []
        grid = QGridLayout(self)
        grid.setContentsMargins(0, 0, 0, 0)
        top = QHBoxLayout()
        top.addWidget(self.name, 1)
        top.addWidget(self.clear)
        grid.addLayout(top, 0, 0, 1, 3)
        for row, end in enumerate(("min", "max"), start=1):
            sl = QSlider(Qt.Orientation.Horizontal)
            sl.setRange(0, SLIDER_STEPS)
            sl.setTracking(False)   # a drag is sent when released
            sl.setToolTip(f"the least value shown ({end} end)" if end == "min"
                          else "the greatest value shown (max end)")
            sl.valueChanged.connect(lambda p, e=row - 1: self._slid(e, p))
            sl.sliderMoved.connect(lambda p, e=row - 1: self._moving(e, p))
            box = NumberBox()
            box.setMinimumWidth(64)
            box.returnPressed.connect(lambda e=row - 1: self._typed(e))
            grid.addWidget(QLabel(end), row, 0)
            grid.addWidget(sl, row, 1)
            grid.addWidget(box, row, 2)
            self.sliders.append(sl)
            self.boxes.append(box)
        self.narrowed = QLabel("")
        self.narrowed.setWordWrap(True)
        grid.addWidget(self.narrowed, 3, 0, 1, 3)
        self._show_chosen(self.name.currentText())

    # --- positions and values -------------------------------------------------------------------
    def _value_at(self, name: str, pos: int) -> float:
        lo, hi = self.extent[name]
        return slider_value(lo, hi, pos, SLIDER_STEPS)

    def _pos_of(self, name: str, value: float) -> int:
        lo, hi = self.extent[name]
        if not hi > lo:
            return 0
        return min(max(round((value - lo) / (hi - lo) * SLIDER_STEPS), 0), SLIDER_STEPS)

    def _ends(self, name: str) -> tuple[float, float]:
        lo, hi = self.extent[name]
        got = self.ranges.get(name) or [None, None]
        return (lo if got[0] is None else float(got[0]), hi if got[1] is None else float(got[1]))

    # --- showing --------------------------------------------------------------------------------
    def _show_chosen(self, name: str) -> None:
        if name not in self.extent:
            return
        ends = self._ends(name)
        for sl, box, v in zip(self.sliders, self.boxes, ends, strict=True):
            with QSignalBlocker(sl):
                sl.setValue(self._pos_of(name, v))
            box.setText(fmt(v))
        lo, hi = self.extent[name]
        for box, v in zip(self.boxes, (lo, hi), strict=True):
            box.setPlaceholderText(fmt(v))
        self.narrowed.setText(self.summary())

    def summary(self) -> str:
        """``PORO 0.1 to 0.3 · PERMX from 100``: the narrowed properties, one line."""
        parts = []
        for n, (lo, hi) in self.ranges.items():
            parts.append(f"{n} from {fmt(lo)}" if hi is None else f"{n} up to {fmt(hi)}"
                         if lo is None else f"{n} {fmt(lo)} to {fmt(hi)}")
        return " · ".join(parts) if parts else "every value shown"

    # --- changing -------------------------------------------------------------------------------
    def _moving(self, end: int, pos: int) -> None:
        name = self.name.currentText()
        if name in self.extent:
            self.boxes[end].setText(fmt(self._value_at(name, pos)))

    def _slid(self, end: int, pos: int) -> None:
        name = self.name.currentText()
        if name not in self.extent:
            return
        if end == 0 and pos > self.sliders[1].value():   # the other end follows
            with QSignalBlocker(self.sliders[1]):
                self.sliders[1].setValue(pos)
        if end == 1 and pos < self.sliders[0].value():
            with QSignalBlocker(self.sliders[0]):
                self.sliders[0].setValue(pos)
        lo_p, hi_p = (sl.value() for sl in self.sliders)
        self._set(name, None if lo_p <= 0 else self._value_at(name, lo_p),
                  None if hi_p >= SLIDER_STEPS else self._value_at(name, hi_p))

    def _typed(self, _end: int = 0) -> None:
        name = self.name.currentText()
        if name not in self.extent:
            return
        texts = [b.text().strip() for b in self.boxes]
        try:
            lo, hi = (None if t == "" else number(t, f"{name} {('min', 'max')[k]}")
                      for k, t in enumerate(texts))
        except ValueError as err:
            self.sink.error(str(err))
            return
        mn, mx = self.extent[name]
        self._set(name, None if lo is None or lo <= mn else lo,
                  None if hi is None or hi >= mx else hi)

    def _set(self, name: str, lo: float | None, hi: float | None) -> None:
        if lo is None and hi is None:
            self.ranges.pop(name, None)
        else:
            self.ranges[name] = [lo, hi]
        self._show_chosen(name)
        self.send_value(self.value())

    def _clear(self) -> None:
        self.ranges = {}
        self._show_chosen(self.name.currentText())
        self.send_value({})

    def value(self) -> dict:
        return {n: list(r) for n, r in self.ranges.items()}

    def set_range(self, name: str, lo: float | None, hi: float | None) -> None:
        """Narrow property ``name`` to ``lo``..``hi`` as a user typing both ends (for scripts
        and tests); sent once."""
        self.name.setCurrentText(name)
        for box, v in zip(self.boxes, (lo, hi), strict=True):
            box.setText(fmt(v))
        self._typed(0)

    def put(self, value: Any) -> None:
        self.ranges = {}
        for n, pair in (value or {}).items():
            key = next((k for k in self.extent if k.upper() == str(n).upper()), None)
            if key is not None:
                lo, hi = (None if v is None or (isinstance(v, float) and not math.isfinite(v))
                          else float(v) for v in pair)
                self.ranges[key] = [lo, hi]
        self._show_chosen(self.name.currentText())


class _ListCompleter(QCompleter):
    """Completes the last name of a comma-separated list."""

    def splitPath(self, path: str) -> list[str]:  # noqa: N802 (Qt's name)
        return [path.split(",")[-1].strip()]

    def pathFromIndex(self, index) -> str:  # noqa: N802 (Qt's name)
        done = self.widget().text().split(",")[:-1]
        return ", ".join([*(d.strip() for d in done if d.strip()), str(index.data())])


class VectorsControl(QLineEdit, Control):
    """Summary vectors (see the module): Enter or leaving the box sends what changed."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        self.choices = [str(c) for c in spec.get("choices") or ()]
        self.setPlaceholderText("FOPR, WBHP:*")
        completer = _ListCompleter(QStringListModel(self.choices), self)
        completer.setCaseSensitivity(Qt.CaseSensitivity.CaseInsensitive)
        completer.setFilterMode(Qt.MatchFlag.MatchContains)
        self.setCompleter(completer)
        self.shown = ""
        self.returnPressed.connect(self.commit)
        self.editingFinished.connect(self.commit)

    def names(self) -> list[str]:
        return [n.strip() for n in self.text().split(",") if n.strip()]

    def commit(self) -> None:
        text = ", ".join(self.names())
        if text == self.shown:
            return
        self.shown = text
        self.send_value(self.names() or None)

    def put(self, value: Any) -> None:
        names = [value] if isinstance(value, str) else list(value or ())
        self.shown = ", ".join(str(n) for n in names)
        self.setText(self.shown)


__all__ = ["IjkControl", "RangesControl", "VectorsControl"]
