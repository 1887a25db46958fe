"""Stacks panel: materials (visibility, opacity, legend swatch), section plane, borehole mode,
drape (a GeoTIFF placed by its georeference), smooth or flat top, legend on the picture."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFileDialog,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QPushButton,
    QScrollArea,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from geoshade.stacks import section_plane
from geoshade.viewer.panels import Panel
from geoshade.viewer.qt import single_shot


def swatch(rgba) -> QIcon:
    pm = QPixmap(14, 14)
    pm.fill(QColor(*rgba[:3]))
    return QIcon(pm)


class StacksPanel(Panel):
    """Materials (visible, opacity), a section plane across an axis, borehole mode, drape and
    legend of a :class:`~geoshade.stacks.StacksView`."""

    def __init__(self, view, host, parent=None):
        super().__init__(view, host, parent)
        #: the drape image the checkbox turns on (the one the view opened with, or picked)
        self.drape_image = view.options.drape
        #: (axis, fraction, flip) of the section controls, None: no section
        self.section_spec = None
        lay = QVBoxLayout(self)
        mats = QGroupBox("Materials (visible, opacity)")
        inner = QWidget()
        gl = QGridLayout(inner)
        self.visible: dict[int, QCheckBox] = {}
        self.opacity: dict[int, QSlider] = {}
        for row, (code, name, rgba) in enumerate(view.materials()):
            cb = QCheckBox(f"{code}  {name}")
            cb.setIcon(swatch(rgba))
            cb.setChecked(True)
            cb.toggled.connect(self._materials_edited)
            sl = QSlider(Qt.Orientation.Horizontal)
            sl.setRange(0, 100)
            sl.setValue(100)
            sl.setToolTip("opacity of a layer of the model's mean interval thickness")
            sl.valueChanged.connect(self._materials_edited)
            gl.addWidget(cb, row, 0)
            gl.addWidget(sl, row, 1)
            self.visible[code], self.opacity[code] = cb, sl
        scroll = QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(inner)
        scroll.setMinimumHeight(160)
        QVBoxLayout(mats).addWidget(scroll)
        lay.addWidget(mats, 1)

        form = QFormLayout()
        self.section_on = QCheckBox("cut")
        self.section_axis = QComboBox()
        self.section_axis.addItems(["x", "y", "z"])
        self.section_pos = QSlider(Qt.Orientation.Horizontal)
        self.section_pos.setRange(1, 99)
        self.section_pos.setValue(50)
        self.section_flip = QCheckBox("flip")
        row = QHBoxLayout()
        for w in (self.section_on, self.section_axis, self.section_pos, self.section_flip):
            row.addWidget(w)
        for sig in (self.section_on.toggled, self.section_axis.currentTextChanged,
                    self.section_pos.valueChanged, self.section_flip.toggled):
            sig.connect(self._section_edited)
        form.addRow("section", row)
        self.boreholes = QCheckBox(f"borehole columns only ({int(view.model.borehole.sum())})")
        self.boreholes.toggled.connect(lambda on: self._syncing or self.host.apply(boreholes=on))
        form.addRow("boreholes", self.boreholes)
        self.drape = QCheckBox("drape image")
        self.drape.setEnabled(self.drape_image is not None)
        self.drape.toggled.connect(
            lambda on: self._syncing or self.host.apply(drape=self.drape_image if on else None))
        pick = QPushButton("image…")
        pick.clicked.connect(self._pick_drape)
        row2 = QHBoxLayout()
        row2.addWidget(self.drape)
        row2.addWidget(pick)
        form.addRow("drape", row2)
        self.top = QComboBox()
        self.top.addItems(list(type(view.options).choices("top")))
        self.top.setToolTip("smooth: the top interpolated between column centres (terrain); "
                            "flat: each column's flat top; auto: smooth for models from DEMs")
        self.top.currentTextChanged.connect(
            lambda t: self._syncing or self.host.apply(top=t))
        form.addRow("top", self.top)
        self.legend = QCheckBox("legend on the picture")
        self.legend.toggled.connect(lambda on: self._syncing or self.host.apply(legend=on))
        form.addRow("legend", self.legend)
        lay.addLayout(form)
        self.timer = single_shot(self, 100, self._commit)
        self.sync()

    def sync(self) -> None:
        o = self.view.options
        self._syncing = True
        try:
            for code, cb in self.visible.items():
                cb.setChecked(code not in o.hide)
                self.opacity[code].setValue(round(100 * (o.opacity or {}).get(code, 1.0)))
            sec = self.section_spec if o.plane is not None else None
            self.section_on.setChecked(sec is not None)
            if sec is not None:
                self.section_axis.setCurrentText(sec[0])
                self.section_pos.setValue(round(100 * sec[1]))
                self.section_flip.setChecked(bool(sec[2]))
            self.boreholes.setChecked(o.boreholes)
            self.drape.setChecked(o.drape is not None)
            self.top.setCurrentText(o.top)
            self.legend.setChecked(o.legend)
        finally:
            self._syncing = False

    def _materials_edited(self, *_):
        if not self._syncing:
            self.timer.start()

    def _section_edited(self, *_):
        if not self._syncing:
            self.timer.start()

    def _commit(self) -> None:

        hidden = tuple(c for c, cb in self.visible.items() if not cb.isChecked())
        opacity = {c: sl.value() / 100 for c, sl in self.opacity.items() if sl.value() < 100}
        section = None
        if self.section_on.isChecked():
            section = (self.section_axis.currentText(), self.section_pos.value() / 100,
                       self.section_flip.isChecked())
        o = self.view.options
        change = {}
        if hidden != tuple(o.hide) or opacity != (o.opacity or {}):
            change.update(hide=hidden, opacity=opacity)
        if section != self.section_spec or (section is None) != (o.plane is None):
            self.section_spec = section
            change["plane"] = None if section is None else section_plane(self.view.model,
                                                                         *section)
        if change:
            self.host.apply(**change)

    def _pick_drape(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Drape image (a GeoTIFF lands where its "
                                              "georeference says)", "",
                                              "Images (*.png *.jpg *.jpeg *.tif *.tiff)")
        if path:
            self.drape_image = path
            self.drape.setEnabled(True)
            if self.drape.isChecked():
                self.host.apply(drape=path)
            else:
                self.drape.setChecked(True)

    def pending(self) -> bool:
        return self.timer.isActive()

    def stop(self) -> None:
        self.timer.stop()
