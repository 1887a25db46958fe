"""The Qt widget of each control type (:data:`geoshade.viewer.controls.TYPES`), made once.

A panel turns a View's control specs (:func:`geoshade.viewer.controls.controls`) into widgets
with :func:`make`, one group box per declared group (:func:`group_box`). A widget sends the
option values it stands for to ``sink.send({option: value})`` when the user changes it, and
shows a value with ``put(value)`` (:func:`geoshade.viewer.values.control_values`) with its
signals blocked, so showing never sends. The browser renders the same types in
``web/static/app.js`` (``makeControl``): every control exists in both.

Types: ``select`` (``editable`` for a colour map, ``auto`` for auto/yes/no), ``check``,
``number``, ``text`` (Enter or leaving the box applies it), ``pair`` and ``ints`` (number
boxes; all empty is None), ``step`` (a slider with the step's label and play/pause),
``button``, ``materials`` (visible and opacity per material), ``section`` (a cut across an
axis at a fraction, flipped or not; a grid's and a stack model's clip plane), ``ijk`` (from
and to of each of I, J, K), ``ranges`` (min and max of each property's values) and
``vectors`` (summary vectors typed with completion): the last three in
:mod:`geoshade.viewer.panels.cuts`.
"""

from __future__ import annotations

import math
from typing import Any

from PySide6.QtCore import QSignalBlocker, Qt, QTimer
from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QScrollArea,
    QSlider,
    QWidget,
)

from geoshade.viewer.panels.base import Control, NumberBox, Sink, fmt, label, number, same
from geoshade.viewer.panels.cuts import IjkControl, RangesControl, VectorsControl

#: ms between steps while playing (at most: a step waits until the last one is drawn)
PLAY_MS = 300
#: material rows shown before the list scrolls
MATERIAL_ROWS = 8


class SelectControl(QComboBox, Control):
    """One of the choices; an editable one (a colour map) also takes a typed name."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        self.choices = list(spec.get("choices") or [])
        for v in self.choices:
            self.addItem(label(v))
        if spec.get("editable"):
            self.setEditable(True)
            self.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
            self.lineEdit().returnPressed.connect(self._typed)
        self.currentIndexChanged.connect(self._chosen)

    def value(self) -> Any:
        if self.isEditable():
            return self.currentText().strip()
        i = self.currentIndex()
        return self.choices[i] if 0 <= i < len(self.choices) else None

    def _chosen(self, i: int) -> None:
        if 0 <= i < len(self.choices):
            self.send_value(self.choices[i])

    def _typed(self) -> None:
        text = self.currentText().strip()
        i = self.findText(text) if text else -1
        if text and i < 0:
            self.send_value(text)
        elif i >= 0 and i != self.currentIndex():   # a listed name: sent by _chosen
            self.setCurrentIndex(i)

    def choose(self, value: Any) -> None:
        """Choose ``value`` as a user would (for scripts and tests)."""
        self.setCurrentIndex(self._index(value))

    def _index(self, value: Any) -> int:
        for i, c in enumerate(self.choices):
            if same(c, value):
                return i
        self.choices.append(value)   # a value the list lacks (a typed expression)
        self.addItem(label(value))
        return len(self.choices) - 1

    def put(self, value: Any) -> None:
        self.setCurrentIndex(self._index(value))
        if self.isEditable():
            self.setEditText(label(value))


class CheckControl(QCheckBox, Control):
    def __init__(self, spec: dict, sink: Sink):
        super().__init__(spec["label"])
        self.setup(spec, sink)
        self.toggled.connect(self.send_value)

    def put(self, value: Any) -> None:
        self.setChecked(bool(value))


class TextControl(QLineEdit, Control):
    """Text or one number; Enter or leaving the box applies what changed (empty: None for
    text; a number box sends nothing when empty, as the browser's)."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        self.numeric = spec["type"] == "number"
        self.setPlaceholderText(str(spec.get("placeholder") or (
            "auto" if self.numeric and spec.get("default") in (None, "auto") else "")))
        self.shown = ""
        self.returnPressed.connect(self.commit)
        self.editingFinished.connect(self.commit)

    def commit(self) -> None:
        text = self.text().strip()
        if text == self.shown:
            return
        if self.numeric:
            if not text:
                return
            try:
                value: Any = number(text, self.spec["label"])
            except ValueError as err:
                self.sink.error(str(err))
                return
        else:
            value = text
        self.shown = text
        self.send_value(value)

    def put(self, value: Any) -> None:
        self.shown = fmt(value) if self.numeric else str(value or "")
        self.setText(self.shown)


class NumbersControl(QWidget, Control):
    """``pair`` (two numbers, e.g. a range) or ``ints`` (``n`` whole numbers, e.g. a box): all
    filled sends the list, all empty sends None, part filled waits."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        self.whole = spec["type"] == "ints"
        n = int(spec.get("n", 2)) if self.whole else 2
        grid = QGridLayout(self)
        grid.setContentsMargins(0, 0, 0, 0)
        per_row = 3 if n > 4 else n
        self.fields: list[NumberBox] = []
        names = list(spec.get("fields") or [])   # one name per number, where declared
        for k in range(n):
            f = NumberBox()
            f.setPlaceholderText(str(names[k] if k < len(names) else
                                     spec.get("placeholder") or ""))
            if k < len(names):
                f.setToolTip(str(names[k]))
            f.setMinimumWidth(48)
            f.returnPressed.connect(self.commit)
            f.editingFinished.connect(self.commit)
            grid.addWidget(f, k // per_row, k % per_row)
            self.fields.append(f)
        self.shown: list[str] = [""] * n

    def texts(self) -> list[str]:
        return [f.text().strip() for f in self.fields]

    def commit(self) -> None:
        texts = self.texts()
        if texts == self.shown:
            return
        if all(t == "" for t in texts):
            value = None
        elif any(t == "" for t in texts):
            return
        else:
            try:
                value = [number(t, self.spec["label"], self.whole) for t in texts]
            except ValueError as err:
                self.sink.error(str(err))
                return
        self.shown = texts
        self.send_value(value)

    def set_values(self, values) -> None:
        """Type ``values`` and apply them (for scripts and tests)."""
        for f, v in zip(self.fields, values, strict=True):
            f.setText(fmt(v))
        self.commit()

    def put(self, value: Any) -> None:
        vals = list(value) if isinstance(value, list | tuple) else [None] * len(self.fields)
        self.shown = [fmt(v) if isinstance(v, int | float) and math.isfinite(v) else ""
                      for v in vals]
        for f, t in zip(self.fields, self.shown, strict=False):
            f.setText(t)


class StepControl(QWidget, Control):
    """A slider over the steps (sent when released), the step's label and play/pause (the
    next step once the last is drawn, wrapping round)."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        self.labels = list(spec.get("labels") or [])
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(int(spec.get("min", 0)), int(spec.get("max", 0)))
        self.slider.setTracking(False)   # a drag sends its step when released
        self.play = QPushButton("▶ play")
        self.play.setCheckable(True)
        self.label = QLabel("")
        lay = QGridLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.slider, 0, 0)
        lay.addWidget(self.play, 0, 1)
        lay.addWidget(self.label, 1, 0, 1, 2)
        self.timer = QTimer(self)
        self.timer.setInterval(PLAY_MS)
        self.timer.timeout.connect(self._tick)
        self.slider.sliderMoved.connect(self._show)
        self.slider.valueChanged.connect(self._moved)
        self.play.toggled.connect(self._play)

    def _show(self, k: int) -> None:
        if 0 <= k < len(self.labels):
            self.label.setText(self.labels[k])

    def _moved(self, k: int) -> None:
        self._show(k)
        self.send_value(k)

    def _play(self, on: bool) -> None:
        self.play.setText("⏸ pause" if on else "▶ play")
        if on:
            self.timer.start()
        else:
            self.timer.stop()

    def _tick(self) -> None:
        if self.sink.ready():   # the last step is drawn: the next
            self.advance()

    def advance(self) -> None:
        """The next step (wraps round): what the play timer does."""
        lo, hi = self.slider.minimum(), self.slider.maximum()
        self.slider.setValue(lo + (self.slider.value() + 1 - lo) % (hi - lo + 1))

    def put(self, value: Any) -> None:
        if isinstance(value, int):
            self.slider.setValue(value)
            self._show(value)

    def stop(self) -> None:
        self.play.setChecked(False)


class ButtonControl(QPushButton, Control):
    """Sets its option to its ``value`` (Otsu: the core's selection ``auto``)."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__(spec["label"])
        self.setup(spec, sink)
        self.clicked.connect(lambda: self.send_value(spec.get("value")))


def swatch(colour: str) -> QIcon:
    pm = QPixmap(14, 14)
    pm.fill(QColor(colour))
    return QIcon(pm)


class MaterialsControl(QWidget, Control):
    """One row per material: visible (with its colour) and opacity (%, sent when released);
    sends ``hide`` and ``opacity`` together."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        inner = QWidget()
        grid = QGridLayout(inner)
        grid.setContentsMargins(2, 2, 2, 2)
        self.visible: dict[int, QCheckBox] = {}
        self.opacity: dict[int, QSlider] = {}
        for row, (code, name, colour) in enumerate(spec.get("items") or []):
            cb = QCheckBox(f"{code}  {name}")
            cb.setIcon(swatch(colour))
            cb.setChecked(True)
            cb.toggled.connect(self.commit)
            sl = QSlider(Qt.Orientation.Horizontal)
            sl.setRange(0, 100)
            sl.setValue(100)
            sl.setTracking(False)
            sl.setToolTip("opacity of a layer of the model's mean interval thickness (%)")
            sl.valueChanged.connect(self.commit)
            grid.addWidget(cb, row, 0)
            grid.addWidget(sl, row, 1)
            self.visible[int(code)], self.opacity[int(code)] = cb, sl
        scroll = QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(inner)
        scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        rows = min(len(self.visible), MATERIAL_ROWS)
        scroll.setMinimumHeight(rows * inner.sizeHint().height() // max(len(self.visible), 1)
                                + 6)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(scroll)

    def commit(self, *_) -> None:
        self.sink.send({
            "hide": [c for c, cb in self.visible.items() if not cb.isChecked()],
            "opacity": {c: sl.value() / 100 for c, sl in self.opacity.items()
                        if sl.value() < 100}})

    def put(self, value: Any) -> None:
        hidden = set((value or {}).get("hide") or ())
        op = (value or {}).get("opacity") or {}
        for code, cb in self.visible.items():
            cb.setChecked(code not in hidden)
            self.opacity[code].setValue(round(100 * op.get(code, 1.0)))


class SectionControl(QWidget, Control):
    """A cut across an axis at a fraction of the model (1..99 %), flipped or not; off: None."""

    def __init__(self, spec: dict, sink: Sink):
        super().__init__()
        self.setup(spec, sink)
        self.on = QCheckBox("cut")
        self.axis = QComboBox()
        self.axis.addItems([str(a) for a in spec.get("axes") or ("x", "y", "z")])
        self.position = QSlider(Qt.Orientation.Horizontal)
        self.position.setRange(1, 99)
        self.position.setValue(50)
        self.position.setTracking(False)
        self.flip = QCheckBox("flip")
        self.where = QLabel("50 %")
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        for w in (self.on, self.axis, self.position, self.where, self.flip):
            lay.addWidget(w)
        self.position.sliderMoved.connect(self._where)
        self.position.valueChanged.connect(self._where)
        for sig in (self.on.toggled, self.axis.currentIndexChanged,
                    self.position.valueChanged, self.flip.toggled):
            sig.connect(self.commit)

    def _where(self, pos: int) -> None:
        self.where.setText(f"{pos} %")

    def value(self) -> list | None:
        if not self.on.isChecked():
            return None
        return [self.axis.currentText(), self.position.value() / 100, self.flip.isChecked()]

    def commit(self, *_) -> None:
        self.send_value(self.value())

    def put(self, value: Any) -> None:
        self.on.setChecked(isinstance(value, list | tuple))
        if isinstance(value, list | tuple):
            self.axis.setCurrentText(str(value[0]))
            self.position.setValue(round(100 * float(value[1])))
            self._where(self.position.value())
            self.flip.setChecked(bool(value[2]))


#: control type -> its widget (number and text share the text box)
WIDGETS: dict[str, type] = {
    "select": SelectControl, "check": CheckControl, "number": TextControl,
    "text": TextControl, "pair": NumbersControl, "ints": NumbersControl,
    "step": StepControl, "button": ButtonControl, "materials": MaterialsControl,
    "section": SectionControl, "ijk": IjkControl, "ranges": RangesControl,
    "vectors": VectorsControl,
}


def make(spec: dict, sink: Sink) -> QWidget:
    """The widget of one control spec."""
    return WIDGETS[spec["type"]](spec, sink)


def group_box(group: dict, sink: Sink, made: dict[str, QWidget]) -> QGroupBox:
    """A titled box of one group's controls, each labelled (a check box and a button carry
    their label); the widgets are added to ``made`` by name."""
    box = QGroupBox(group["group"])
    form = QFormLayout(box)
    form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
    for spec in group["controls"]:
        w = make(spec, sink)
        made[spec["name"]] = w
        if spec["type"] in ("check", "button"):
            form.addRow(w)
        elif spec["type"] in ("materials", "ijk", "ranges"):   # a block of rows
            form.addRow(QLabel(spec["label"]))
            form.addRow(w)
        else:
            name = QLabel(spec["label"])
            name.setToolTip(spec.get("help") or "")
            form.addRow(name, w)
    return box


def align_labels(boxes) -> None:
    """One width for the labels of every group box: the fields line up down the panel."""
    labels = []
    for box in boxes:
        form = box.layout()
        for row in range(form.rowCount()):
            item = form.itemAt(row, QFormLayout.ItemRole.LabelRole)
            if item is not None and item.widget() is not None:
                labels.append(item.widget())
    width = max((w.sizeHint().width() for w in labels), default=0)
    for w in labels:
        w.setMinimumWidth(width)


def put_all(made: dict[str, QWidget], values: dict[str, Any]) -> None:
    """Show ``values`` in the controls, sending nothing."""
    for name, value in values.items():
        w = made.get(name)
        if w is None:
            continue
        blockers = [QSignalBlocker(x) for x in (w, *w.findChildren(QWidget))]
        try:
            w.put(value)
        finally:
            del blockers


__all__ = ["PLAY_MS", "WIDGETS", "Control", "Sink", "align_labels", "group_box", "label", "make",
           "put_all", "same"]
