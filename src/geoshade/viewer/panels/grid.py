"""Grid panel: property and report step, cell filter, IJK slices, edges, faults, wells and
simulation wells."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QLabel,
    QLineEdit,
    QSlider,
    QSpinBox,
    QVBoxLayout,
)

from geoshade.models.steps import step_label
from geoshade.viewer.panels import Panel
from geoshade.viewer.panels.colors import ColorControls
from geoshade.viewer.qt import single_shot

NO_PROPERTY = "(none)"


class GridPanel(Panel):
    """Property, report step, filter, IJK slice, edges, faults, wells and simulation wells of a
    :class:`~geoshade.grid.GridView`."""

    def __init__(self, view, host, parent=None):
        super().__init__(view, host, parent)
        grid = view.grid
        self.deck_wells = list(grid.meta.get("wells") or [])
        lay = QVBoxLayout(self)
        form = QFormLayout()
        self.property = QComboBox()
        self.property.addItems([NO_PROPERTY, *view.property_names()])
        self.property.currentTextChanged.connect(self._property_changed)
        form.addRow("property", self.property)
        self.expression = QLineEdit()
        self.expression.setPlaceholderText("e.g. log10(PERMX) or PORO * NTG")
        self.expression.setToolTip("colour by an expression over the grid's properties (the "
                                   "filter's grammar); Enter applies it")
        self.expression.returnPressed.connect(self._expression_changed)
        form.addRow("expression", self.expression)
        self.step = QSlider(Qt.Orientation.Horizontal)
        self.step.setRange(0, max(0, view.nsteps - 1))
        self.step.setEnabled(view.nsteps > 0)
        self.step.valueChanged.connect(self._step_changed)
        self.step_label = QLabel("no report steps" if not view.nsteps else "")
        form.addRow("report step", self.step)
        form.addRow("", self.step_label)
        self.filter = QLineEdit()
        self.filter.setPlaceholderText("e.g. PORO > 0.2 and PERMX > 100")
        self.filter.setToolTip("cell filter over the grid's properties (any case); Enter "
                               "applies it")
        self.filter.returnPressed.connect(self._filter_changed)
        form.addRow("filter", self.filter)
        lay.addLayout(form)

        sl = QGroupBox("IJK slice (0-based, end exclusive)")
        gl = QGridLayout(sl)
        self.lo = [QSpinBox() for _ in range(3)]
        self.hi = [QSpinBox() for _ in range(3)]
        for k, (ax, n) in enumerate(zip("ijk", grid.dims, strict=True)):
            self.lo[k].setRange(0, n - 1)
            self.hi[k].setRange(1, n)
            gl.addWidget(QLabel(ax), k, 0)
            gl.addWidget(self.lo[k], k, 1)
            gl.addWidget(self.hi[k], k, 2)
            for sb in (self.lo[k], self.hi[k]):
                sb.setKeyboardTracking(False)
                sb.valueChanged.connect(self._slice_edited)
        lay.addWidget(sl)

        form2 = QFormLayout()
        self.edges = QComboBox()
        self.edges.addItems(list(type(view.options).choices("edges")))
        self.edges.currentTextChanged.connect(
            lambda t: self._syncing or self.host.apply(edges=t))
        form2.addRow("cell edges", self.edges)
        self.faults = QComboBox()
        self.faults.addItems(list(type(view.options).choices("faults")))
        self.faults.currentTextChanged.connect(
            lambda t: self._syncing or self.host.apply(faults=t))
        form2.addRow("faults", self.faults)
        wells = self.deck_wells
        self.wells = QCheckBox(f"{len(wells)} wells" if wells else "no wells")
        self.wells.setEnabled(bool(wells))
        self.wells.toggled.connect(
            lambda on: self._syncing or self.host.apply(wells=wells if on else False))
        form2.addRow("wells", self.wells)
        has_sim = view.has_sim_wells()
        self.sim_wells = QCheckBox("from the restart file" if has_sim else "none in the case")
        self.sim_wells.setToolTip("simulation wells (IWEL/ICON/ZWEL of the shown report step): "
                                  "producers green, water injectors blue, gas injectors red, "
                                  "shut wells and completions grey")
        self.sim_wells.setEnabled(has_sim)
        self.sim_wells.toggled.connect(
            lambda on: self._syncing or self.host.apply(sim_wells=on))
        form2.addRow("sim wells", self.sim_wells)
        lay.addLayout(form2)

        self.colors = ColorControls(self)
        lay.addWidget(self.colors)
        lay.addStretch(1)
        self.timer = single_shot(self, 150, self._commit_slice)
        self.sync()

    def sync(self) -> None:
        s = self.view.settings()
        self._syncing = True
        try:
            prop = s["property"] or NO_PROPERTY
            if self.property.findText(prop) < 0:   # an expression: listed once applied
                self.property.addItem(prop)
            self.property.setCurrentText(prop)
            if s["step"] is not None:
                self.step.setValue(s["step"])
            self._step_text(s["step"])
            self.filter.setText("" if s["filter"] is None else str(s["filter"]))
            for k, sl in enumerate(s["slice"]):
                self.lo[k].setValue(sl.start)
                self.hi[k].setValue(sl.stop)
            self.edges.setCurrentText(s["edges"])
            self.faults.setCurrentText(s["faults"])
            self.wells.setChecked(bool(s["wells"]))
            self.sim_wells.setChecked(bool(s["sim_wells"]))
        finally:
            self._syncing = False

    def _step_text(self, step) -> None:

        g = self.view.grid
        if step is not None and self.view.nsteps:
            self.step_label.setText(f"{step_label(step, g.step_dates)} of {self.view.nsteps}")

    def _property_changed(self, name: str) -> None:
        if not self._syncing:
            self.host.apply(property=None if name == NO_PROPERTY else name)

    def _expression_changed(self) -> None:
        text = self.expression.text().strip()
        if text:
            self.host.apply(property=text)
            self.sync()   # the property list shows the expression once it is applied

    def _step_changed(self, k: int) -> None:
        if not self._syncing:
            self._step_text(k)
            self.host.apply(step=k)

    def _filter_changed(self) -> None:
        self.host.apply(filter=self.filter.text().strip() or None)

    def _slice_edited(self, _v) -> None:
        if not self._syncing:
            self.timer.start()

    def _commit_slice(self) -> None:
        spec = {}
        for k, ax in enumerate("ijk"):
            a, b = self.lo[k].value(), self.hi[k].value()
            if a >= b:
                self.host.show_error(f"slice: {ax} from {a} to {b} is empty (end is exclusive)")
                return
            spec[ax] = (a, b)
        self.host.apply(slice=spec)

    def drawn(self, stats: dict) -> None:
        self.colors.sync(stats)

    def pending(self) -> bool:
        return self.timer.isActive()

    def stop(self) -> None:
        self.timer.stop()
