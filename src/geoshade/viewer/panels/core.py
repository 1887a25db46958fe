"""Core panel: range sliders over the histogram, box offset and size, method, porosity plot."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QLineF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter
from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QLabel,
    QLineEdit,
    QPushButton,
    QSlider,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from geoshade.errors import GeoshadeError
from geoshade.viewer.panels import Panel
from geoshade.viewer.panels.colors import ColorControls
from geoshade.viewer.qt import single_shot

#: slider positions over the value range of float (or very wide integer) data
SLIDER_STEPS = 1000
#: ms a range or box edit waits for the next before the maps are rebuilt
DEBOUNCE_MS = 150


#: the occlusion choices of the panel and the option value of each
OCCLUSION = {"auto": None, "on": True, "off": False}

class HistogramWidget(QWidget):
    """Log-count bars of the volume's histogram with the selected range shaded."""

    def __init__(self, hist, parent=None):
        super().__init__(parent)
        self.hist = hist
        self.lo, self.hi = hist.vmin, hist.vmax
        self.otsu: float | None = None
        self.multi: list[float] = []
        self.setMinimumHeight(70)

    def set_range(self, lo: float, hi: float) -> None:
        self.lo, self.hi = lo, hi
        self.update()

    def set_thresholds(self, otsu: float | None, multi=()) -> None:
        """Marker lines: Otsu's threshold (red) and the multi-Otsu thresholds (grey)."""
        self.otsu, self.multi = otsu, list(multi)
        self.update()

    def _x(self, v: float) -> float:
        e = self.hist.edges
        return (v - e[0]) / max(e[-1] - e[0], 1e-300) * self.width()

    def paintEvent(self, event):  # noqa: N802
        p = QPainter(self)
        w, h = self.width(), self.height()
        p.fillRect(0, 0, w, h, QColor(250, 250, 250))
        x0, x1 = self._x(self.lo), self._x(self.hi)
        p.fillRect(QRectF(x0, 0, max(x1 - x0, 1.0), h), QColor(255, 220, 120))
        c = np.log1p(self.hist.counts.astype(float))
        top = c.max() if c.size and c.max() > 0 else 1.0
        bw = w / max(len(c), 1)
        p.setPen(Qt.PenStyle.NoPen)
        p.setBrush(QColor(60, 90, 160))
        for k in np.flatnonzero(c):  # one rectangle per non-empty bin (<= BINS), not per voxel
            bh = c[k] / top * (h - 4)
            p.drawRect(QRectF(k * bw, h - bh, max(bw, 1.0), bh))
        for v, colour in [(m, QColor(120, 120, 120)) for m in self.multi] + (
                [] if self.otsu is None else [(self.otsu, QColor(210, 40, 40))]):
            p.setPen(colour)
            x = self._x(v)
            p.drawLine(QLineF(x, 0.0, x, float(h)))
        p.end()


class CorePanel(Panel):
    """Selection over the histogram, box, method and porosity of a
    :class:`~geoshade.core.CoreView` (histogram and colour range from :mod:`geoshade.core`)."""

    def __init__(self, view, host, parent=None):
        super().__init__(view, host, parent)
        hist, vol = view.histogram(), view.volume
        self.hist = hist
        self.integer = vol.dtype.kind in "ui"
        lo0, hi0 = view.settings()["select"]
        # the sliders run over the data's values and the range it opened with
        self.dmin, self.dmax = min(hist.vmin, lo0), max(hist.vmax, hi0)
        span = self.dmax - self.dmin
        self.direct = self.integer and span <= 100_000  # slider positions are the values
        lay = QVBoxLayout(self)

        rng = QGroupBox("Selection (absorption values)")
        rl = QGridLayout(rng)
        self.histogram = HistogramWidget(hist)
        rl.addWidget(self.histogram, 0, 0, 1, 3)
        self.lo_slider, self.hi_slider = QSlider(Qt.Orientation.Horizontal), \
            QSlider(Qt.Orientation.Horizontal)
        self.lo_spin, self.hi_spin = QDoubleSpinBox(), QDoubleSpinBox()
        for row, (name, sl, sp) in enumerate((("low", self.lo_slider, self.lo_spin),
                                              ("high", self.hi_slider, self.hi_spin)), start=1):
            sl.setRange(0, int(span) if self.direct else SLIDER_STEPS)
            sp.setDecimals(0 if self.integer else 4)
            lo_lim, hi_lim = vol.value_limits() if self.integer else (-1e300, 1e300)
            sp.setRange(lo_lim, hi_lim)
            sp.setKeyboardTracking(False)
            rl.addWidget(QLabel(name), row, 0)
            rl.addWidget(sl, row, 1)
            rl.addWidget(sp, row, 2)
            sl.valueChanged.connect(self._slider_moved)
            sp.valueChanged.connect(self._spin_changed)
        self.limits = QLabel(f"data {hist.vmin:g} … {hist.vmax:g}")
        rl.addWidget(self.limits, 3, 0, 1, 2)
        self.otsu_button = QPushButton("Otsu")
        self.otsu_button.setToolTip("select the pore space: the values up to Otsu's threshold "
                                    "of the box's voxels inside the ROI (red line; grey: "
                                    "multi-Otsu)")
        self.otsu_button.clicked.connect(self._select_otsu)
        rl.addWidget(self.otsu_button, 3, 2)
        lay.addWidget(rng)

        box = QGroupBox("Box (voxels)")
        bl = QGridLayout(box)
        self.offset = [QSpinBox() for _ in range(3)]
        self.extent = [QSpinBox() for _ in range(3)]
        for col, ax in enumerate("xyz", start=1):
            bl.addWidget(QLabel(ax), 0, col)
        bl.addWidget(QLabel("offset"), 1, 0)
        bl.addWidget(QLabel("size"), 2, 0)
        for k, n in enumerate(vol.shape_xyz):
            self.offset[k].setRange(0, n - 1)
            self.extent[k].setRange(1, n)
            for sb in (self.offset[k], self.extent[k]):
                sb.setKeyboardTracking(False)
                sb.valueChanged.connect(self._box_changed)
            bl.addWidget(self.offset[k], 1, k + 1)
            bl.addWidget(self.extent[k], 2, k + 1)
        self.roi = QLineEdit()
        self.roi.setPlaceholderText("cylinder, or cylinder:CX,CY,R")
        self.roi.setToolTip("region of interest: only voxels inside are drawn and counted "
                            "('cylinder' fits it to the sample scanned in air; empty: none)")
        self.roi.editingFinished.connect(self._roi_edited)
        bl.addWidget(QLabel("ROI"), 3, 0)
        bl.addWidget(self.roi, 3, 1, 1, 3)
        lay.addWidget(box)

        form = QFormLayout()
        self.method = QComboBox()
        self.method.addItems(list(type(view.options).choices("method")))
        self.method.setToolTip("auto: the fastest for this renderer; trefoil: the paper's "
                               "method; gs, cubes: baselines; raycast: exact voxel ray caster")
        self.method.currentTextChanged.connect(self._method_changed)
        form.addRow("method", self.method)
        self.occlusion = QComboBox()
        self.occlusion.addItems(list(OCCLUSION))
        self.occlusion.setToolTip("ambient occlusion and depth cue: creases and far surfaces "
                                  "darken (auto: on for one solid colour)")
        self.occlusion.currentTextChanged.connect(
            lambda t: self._syncing or self.host.apply(occlusion=OCCLUSION[t]))
        form.addRow("occlusion", self.occlusion)
        lay.addLayout(form)

        self.colors = ColorControls(self, log=False)
        lay.addWidget(self.colors)

        self.figure, self.canvas = _porosity_canvas()
        lay.addWidget(self.canvas, 1)
        self.timer = single_shot(self, DEBOUNCE_MS, self._commit)
        self.sync()

    # --- value <-> slider -------------------------------------------------------------------------
    def _to_pos(self, v: float) -> int:
        if self.direct:
            return round(v - self.dmin)
        return round((v - self.dmin) / max(self.dmax - self.dmin, 1e-300) * SLIDER_STEPS)

    def _to_value(self, pos: int) -> float:
        if self.direct:
            return float(self.dmin + pos)
        v = self.dmin + pos / SLIDER_STEPS * (self.dmax - self.dmin)
        return float(round(v)) if self.integer else float(v)

    # --- from the part to the controls -----------------------------------------------------------
    def sync(self) -> None:
        s = self.view.settings()
        self._syncing = True
        try:
            lo, hi = s["select"]
            self.lo_spin.setValue(lo)
            self.hi_spin.setValue(hi)
            self.lo_slider.setValue(self._to_pos(lo))
            self.hi_slider.setValue(self._to_pos(hi))
            self.histogram.set_range(lo, hi)
            self._show_thresholds()
            box = [*s["box"].offset, *s["box"].size]
            for k in range(3):
                self.offset[k].setValue(box[k])
                self.extent[k].setValue(box[3 + k])
            self.method.setCurrentText(s["method"])
            roi = self.view.options.roi
            self.roi.setText("" if roi is None else roi.text())
            occ = self.view.options.occlusion
            self.occlusion.setCurrentText("auto" if occ is None else "on" if occ else "off")
        finally:
            self._syncing = False
        self._plot()

    def _thresholds(self):
        """The view's suggested thresholds, or None (scikit-image missing, one value only)."""

        try:
            return self.view.thresholds()
        except GeoshadeError as exc:
            self.otsu_button.setEnabled(False)
            self.otsu_button.setToolTip(str(exc))
            return None

    def _show_thresholds(self) -> None:
        t = self._thresholds()
        if t is None:
            self.histogram.set_thresholds(None)
            return
        self.otsu_button.setEnabled(True)
        self.otsu_button.setText(f"Otsu ≤ {t.otsu:g}")
        self.histogram.set_thresholds(t.otsu, t.multiotsu)

    def _select_otsu(self) -> None:
        t = self._thresholds()
        if t is None:
            return
        lo, hi = t.pore_select()
        self.lo_spin.setValue(lo)   # through _spin_changed: sliders, shading, debounced commit
        self.hi_spin.setValue(hi)

    # --- from the controls to the part -----------------------------------------------------------
    def _slider_moved(self, _pos) -> None:
        if self._syncing:
            return
        self._syncing = True
        try:
            self.lo_spin.setValue(self._to_value(self.lo_slider.value()))
            self.hi_spin.setValue(self._to_value(self.hi_slider.value()))
        finally:
            self._syncing = False
        self._range_edited()

    def _spin_changed(self, _v) -> None:
        if self._syncing:
            return
        self._syncing = True
        try:
            self.lo_slider.setValue(self._to_pos(self.lo_spin.value()))
            self.hi_slider.setValue(self._to_pos(self.hi_spin.value()))
        finally:
            self._syncing = False
        self._range_edited()

    def _range_edited(self) -> None:
        self.histogram.set_range(self.lo_spin.value(), self.hi_spin.value())
        self.timer.start()

    def _box_changed(self, _v) -> None:
        if self._syncing:
            return
        n = self.view.volume.shape_xyz
        self._syncing = True
        try:
            for k in range(3):
                self.extent[k].setMaximum(n[k] - self.offset[k].value())
        finally:
            self._syncing = False
        self.timer.start()

    def _commit(self) -> None:
        lo, hi = self.lo_spin.value(), self.hi_spin.value()
        if lo > hi:
            self.host.show_error(f"select: low {lo:g} is above high {hi:g}")
            return
        box = [sb.value() for sb in self.offset] + [sb.value() for sb in self.extent]
        cur = self.view.settings()
        change = {}
        if (lo, hi) != tuple(cur["select"]):
            # automatic colours follow the selection: the View's default, as in core render
            change["select"] = (lo, hi)
        if box != [*cur["box"].offset, *cur["box"].size]:
            change["box"] = box
        if change:
            self.host.apply(reframe="box" in change, **change)

    def drawn(self, stats: dict) -> None:
        self.colors.sync(stats)

    def _roi_edited(self) -> None:
        if self._syncing:
            return
        text = self.roi.text().strip()
        roi = self.view.options.roi
        if text == ("" if roi is None else roi.text()):
            return
        self.host.apply(roi=text or None)

    def _method_changed(self, name: str) -> None:
        if not self._syncing:
            self.host.apply(method=name)

    def pending(self) -> bool:
        return self.timer.isActive()

    def stop(self) -> None:
        self.timer.stop()

    def applied(self) -> None:
        self.sync()

    # --- porosity plot ---------------------------------------------------------------------------
    def _plot(self) -> None:
        res = self.view.porosity
        fig = self.figure
        fig.clear()
        ax = fig.add_subplot(1, 1, 1)
        if res is not None:
            x = res.coordinates() if hasattr(res, "coordinates") else res.positions
            from geoshade.core.plots import axis_label

            label, x = axis_label(res)
            ax.plot(np.asarray(res.profile), x, color="tab:blue", lw=1.2)
            ax.axvline(res.porosity, color="tab:red", ls="--", lw=1,
                       label=f"total {res.porosity:.4f}")
            ax.set_ylabel(label)
            ax.set_xlabel(getattr(res, "quantity", "porosity"))
            ax.set_xlim(0, max(0.05, min(1.0, float(np.nanmax(res.profile, initial=0)) * 1.15)))
            ax.legend(loc="best", fontsize="x-small")
        ax.tick_params(labelsize=7)
        fig.tight_layout()
        self.canvas.draw_idle()


def _porosity_canvas():
    from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3.2, 2.6), dpi=90)
    canvas = FigureCanvasQTAgg(fig)
    canvas.setMinimumHeight(180)
    return fig, canvas
