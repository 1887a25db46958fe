"""Iso panel: level slider, time slider with play/pause, colour-by selector."""

from __future__ import annotations

from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QVBoxLayout,
)

from geoshade.viewer.panels import Panel
from geoshade.viewer.panels.colors import ColorControls

#: level slider positions between the step's smallest and largest value
LEVEL_STEPS = 1000
#: ms between steps while playing
PLAY_MS = 300
NO_COLOUR = "(plain)"


class IsoPanel(Panel):
    """Level, time step (play/pause) and colour-by of an :class:`~geoshade.iso.IsoView`."""

    def __init__(self, view, host, parent=None):
        super().__init__(view, host, parent)
        lay = QVBoxLayout(self)
        form = QFormLayout()
        self.lo, self.hi = view.level_range()
        self.level_slider = QSlider(Qt.Orientation.Horizontal)
        self.level_slider.setRange(0, LEVEL_STEPS)
        self.level = QDoubleSpinBox()
        self.level.setDecimals(4)
        span = self.hi - self.lo
        self.level.setRange(self.lo - span, self.hi + span)
        self.level.setSingleStep((self.hi - self.lo) / 100)
        self.level.setKeyboardTracking(False)
        self.level_slider.valueChanged.connect(self._slider_moved)
        self.level.valueChanged.connect(self._level_changed)
        row = QHBoxLayout()
        row.addWidget(self.level_slider, 1)
        row.addWidget(self.level)
        form.addRow("level", row)

        n = view.nsteps
        self.step = QSlider(Qt.Orientation.Horizontal)
        self.step.setRange(0, max(0, n - 1))
        self.step.setEnabled(n > 1)
        self.step.valueChanged.connect(self._step_changed)
        self.play = QPushButton("▶ play")
        self.play.setCheckable(True)
        self.play.setEnabled(n > 1)
        self.play.toggled.connect(self._play_toggled)
        row2 = QHBoxLayout()
        row2.addWidget(self.step, 1)
        row2.addWidget(self.play)
        form.addRow("time step", row2)
        self.time = QLabel("")
        form.addRow("", self.time)

        self.color_by = QComboBox()
        self.color_by.addItems([NO_COLOUR, *view.color_names()])
        self.color_by.setEnabled(bool(view.color_names()))
        self.color_by.currentTextChanged.connect(self._color_changed)
        form.addRow("colour by", self.color_by)
        self.caps = QCheckBox("closed at inactive cells")
        self.caps.setToolTip("close the surface along inactive cells (caps); by default it "
                             "stays open there, as at the grid's outer boundary")
        self.caps.toggled.connect(lambda on: self._syncing or self.host.apply(caps=on))
        form.addRow("surface", self.caps)
        lay.addLayout(form)

        self.colors = ColorControls(self)
        lay.addWidget(self.colors)
        lay.addStretch(1)
        self.timer = QTimer(self)
        self.timer.setInterval(PLAY_MS)
        self.timer.timeout.connect(self.advance)
        self.sync()

    def sync(self) -> None:
        s = self.view.settings()
        self._syncing = True
        try:
            self.level.setValue(s["level"])
            self.level_slider.setValue(self._to_pos(s["level"]))
            self.step.setValue(s["step"])
            f = self.view.field
            self.time.setText(f"step {s['step']} of {f.nsteps}: {f.times[s['step']]}")
            self.color_by.setCurrentText(s["color_by"] or NO_COLOUR)
            self.caps.setChecked(bool(self.view.options.caps))
        finally:
            self._syncing = False

    def _to_pos(self, v: float) -> int:
        return round((v - self.lo) / max(self.hi - self.lo, 1e-300) * LEVEL_STEPS)

    def _slider_moved(self, pos: int) -> None:
        if not self._syncing:
            self.level.setValue(self.lo + pos / LEVEL_STEPS * (self.hi - self.lo))

    def _level_changed(self, v: float) -> None:
        if self._syncing:
            return
        self._syncing = True
        try:
            self.level_slider.setValue(self._to_pos(v))
        finally:
            self._syncing = False
        self.host.apply(level=v)

    def _step_changed(self, k: int) -> None:
        if not self._syncing:
            self.host.apply(step=k)
            self.sync()

    def _color_changed(self, name: str) -> None:
        if not self._syncing:
            self.host.apply(color_by=None if name == NO_COLOUR else name)

    def _play_toggled(self, on: bool) -> None:
        self.play.setText("⏸ pause" if on else "▶ play")
        if on:
            self.timer.start()
        else:
            self.timer.stop()

    def advance(self) -> None:
        """Next step (wraps round); what the play timer calls."""
        n = self.view.nsteps
        self.step.setValue((self.step.value() + 1) % n)

    def drawn(self, stats: dict) -> None:
        self.colors.sync(stats)

    def stop(self) -> None:
        self.play.setChecked(False)
