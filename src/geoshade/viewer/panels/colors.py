"""The colour controls every panel of a continuous colouring shows: colour map (reversed), colour
range (automatic or fixed) and a linear/log/automatic scale; changes go to ``host.apply``."""

from __future__ import annotations

from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
)

from geoshade.styles.options import ColorStyle

#: colour maps offered first (any matplotlib name can be typed)
COLORMAPS = ("viridis", "magma", "inferno", "plasma", "cividis", "turbo", "gray", "bone",
             "coolwarm", "RdYlBu", "Spectral", "terrain", "ocean", "copper")
SCALES = tuple(ColorStyle.SCALES)  # the options' colour scales


class ColorControls(QGroupBox):
    """Colour map, range and scale of a View's ``color`` option.

    ``host.apply(colormap=..., reverse=..., color_range=..., log=...)`` is called on a change;
    :meth:`sync` reads the View's current colouring (its stats when drawn).
    """

    def __init__(self, panel, title: str = "Colours", auto_range=None, log: bool = True):
        super().__init__(title)
        self.panel = panel
        #: the range "automatic" stands for (None: the View's own default)
        self.auto_range = auto_range
        self.is_auto = True
        self.has_log = bool(log)
        self._syncing = False
        form = QFormLayout(self)
        self.cmap = QComboBox()
        self.cmap.setEditable(True)
        self.cmap.addItems(list(COLORMAPS))
        self.reverse = QCheckBox("reversed")
        row = QHBoxLayout()
        row.addWidget(self.cmap, 1)
        row.addWidget(self.reverse)
        form.addRow("colour map", row)
        self.auto = QCheckBox("automatic")
        self.lo, self.hi = QDoubleSpinBox(), QDoubleSpinBox()
        for sb in (self.lo, self.hi):
            sb.setDecimals(6)
            sb.setRange(-1e300, 1e300)
            sb.setKeyboardTracking(False)
        row2 = QHBoxLayout()
        row2.addWidget(self.auto)
        row2.addWidget(self.lo)
        row2.addWidget(self.hi)
        form.addRow("range", row2)
        self.scale = QComboBox()
        self.scale.addItems(list(SCALES))
        self.scale.setToolTip("auto: log for permeability-like properties spanning more than "
                              "three decades")
        if log:
            form.addRow("scale", self.scale)
        else:
            self.scale.hide()
        self.cmap.currentTextChanged.connect(self._changed)
        self.reverse.toggled.connect(self._changed)
        self.auto.toggled.connect(self._changed)
        self.lo.valueChanged.connect(self._changed)
        self.hi.valueChanged.connect(self._changed)
        self.scale.currentTextChanged.connect(self._changed)
        self.sync()

    def sync(self, stats: dict | None = None) -> None:
        c = self.panel.view.options.color
        self._syncing = True
        try:
            self.cmap.setCurrentText(c.colormap)
            self.reverse.setChecked(c.reverse)
            if self.auto_range is None:
                self.is_auto = c.range is None
            self.auto.setChecked(self.is_auto)
            shown = (stats or {}).get("color_range") or c.range
            if shown:
                self.lo.setValue(float(shown[0]))
                self.hi.setValue(float(shown[1]))
            self.lo.setEnabled(not self.is_auto)
            self.hi.setEnabled(not self.is_auto)
            self.scale.setCurrentText({v: k for k, v in ColorStyle.SCALES.items()}[c.log])
        finally:
            self._syncing = False

    def _changed(self, *_) -> None:
        if self._syncing:
            return
        self.is_auto = self.auto.isChecked()
        self.lo.setEnabled(not self.is_auto)
        self.hi.setEnabled(not self.is_auto)
        crange = (self.auto_range() if self.auto_range is not None else None) if self.is_auto \
            else (self.lo.value(), self.hi.value())
        if crange is not None and crange[0] > crange[1]:
            self.panel.host.show_error(f"color range: low {crange[0]:g} is above high "
                                       f"{crange[1]:g}")
            return
        changes = {"colormap": self.cmap.currentText(), "reverse": self.reverse.isChecked(),
                   "color_range": crange}
        if self.has_log:
            scale = self.scale.currentText()
            changes["log"] = ColorStyle.SCALES[scale]
        self.panel.host.apply(**changes)
