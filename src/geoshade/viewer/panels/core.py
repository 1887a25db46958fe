"""Core panel: the core's controls and two plots that are not controls: the histogram of the
volume with the selection and Otsu's thresholds drawn on it, and the porosity profile (the
browser shows the same two as SVG, :mod:`geoshade.web.plots`)."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QLineF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter
from PySide6.QtWidgets import QFormLayout, QWidget

from geoshade.errors import GeoshadeError
from geoshade.viewer.panels import Panel


class HistogramWidget(QWidget):
    """Log-count bars of the volume's histogram with the selected range shaded."""

    def __init__(self, hist, parent=None):
        super().__init__(parent)
        self.hist = hist
        self.lo, self.hi = hist.vmin, hist.vmax
        self.otsu: float | None = None
        self.multi: list[float] = []
        self.setMinimumHeight(70)
        self.setToolTip(f"histogram of the volume (log counts), data {hist.vmin:g} … "
                        f"{hist.vmax:g}; shaded: the selection; red: Otsu's threshold, grey: "
                        "multi-Otsu")

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
    """The controls of a :class:`~geoshade.core.CoreView`, its histogram above the selection
    and its porosity profile below (both from :mod:`geoshade.core`)."""

    def __init__(self, session, host, parent=None):
        super().__init__(session, host, parent)
        self.histogram = HistogramWidget(self.view.histogram())
        select = self.controls.get("select")
        form = select.parentWidget().layout() if select is not None else None
        if isinstance(form, QFormLayout):
            row, _role = form.getWidgetPosition(select)
            form.insertRow(row, self.histogram)
        else:
            self.layout_.insertWidget(0, self.histogram)
        self.figure, self.canvas = _porosity_canvas()
        self._plotted = None
        self.layout_.insertWidget(self.layout_.count() - 1, self.canvas, 1)

    def sync(self, settings: dict | None = None) -> None:
        super().sync(settings)
        lo, hi = self.view.settings()["select"]
        self.histogram.set_range(lo, hi)
        self._show_thresholds()
        self._plot()

    def _show_thresholds(self) -> None:
        """Otsu's thresholds on the histogram and on the Otsu button (disabled, with the
        reason, where there are none: scikit-image missing, one value only)."""
        button = self.controls.get("otsu")
        try:
            t = self.view.thresholds()
        except GeoshadeError as exc:
            self.histogram.set_thresholds(None)
            if button is not None:
                button.setEnabled(False)
                button.setToolTip(str(exc))
            return
        self.histogram.set_thresholds(t.otsu, t.multiotsu)
        if button is not None:
            button.setEnabled(True)
            button.setToolTip(f"{button.spec.get('help') or ''}\nOtsu's threshold {t.otsu:g} "
                              "(the red line on the histogram)".strip())

    def _plot(self) -> None:
        res = self.view.porosity
        if res is self._plotted and res is not None:   # a camera key or a colour: no new profile
            return
        self._plotted = res
        fig = self.figure
        fig.clear()
        ax = fig.add_subplot(1, 1, 1)
        if res is not None:
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
