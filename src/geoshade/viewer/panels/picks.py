"""The desktop viewer's picks (Qt), as ResInsight shows them: the picked cells in a list (a
left click on the grid adds one; remove, clear), the chosen cell's properties at the shown
report step in a table, and its history over the steps as a plot for a chosen report-step
property, the shown step marked. The data come from :class:`geoshade.viewer.picks.Picks`
(the notebook shows the same).
"""

from __future__ import annotations

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtGui import QPixmap
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QListWidget,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from geoshade.errors import GeoshadeError
from geoshade.viewer.picks import HISTORY_SIZE, Picks
from geoshade.viewer.qt import to_qimage

#: rows of the pick list shown before it scrolls
LIST_ROWS = 4


class PicksPanel(QWidget):
    """The picks of one grid View (see the module).

    ``host`` has ``show_error(text)``. :meth:`add` keeps a pick; :meth:`follow` shows the
    table and the plot again once the shown step (or property) changed.
    """

    def __init__(self, view, host, parent=None):
        super().__init__(parent)
        self.host = host
        self.picks = Picks(view)
        #: (cells, current, step, history property) the table and plot show
        self._shown: tuple | None = None
        self.list = QListWidget()
        self.list.setToolTip("the picked cells (a left click on the grid adds one)")
        self.list.setMaximumHeight(LIST_ROWS * self.list.fontMetrics().height() * 3 // 2 + 8)
        self.list.currentRowChanged.connect(self._chosen)
        self.remove = QPushButton("remove")
        self.remove.setToolTip("forget the chosen pick")
        self.remove.clicked.connect(self._remove)
        self.clear = QPushButton("clear")
        self.clear.setToolTip("forget every pick")
        self.clear.clicked.connect(self._clear)
        self.caption = QLabel("no cell picked: left-click the grid")
        self.caption.setWordWrap(True)
        self.table = QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels(["property", "value", "unit"])
        self.table.verticalHeader().hide()
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.horizontalHeader().setSectionResizeMode(
            QHeaderView.ResizeMode.ResizeToContents)
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.setMinimumHeight(8 * self.table.verticalHeader().defaultSectionSize())
        self.history = QComboBox()
        self.history.setToolTip("the report-step property whose history over the steps is "
                                "plotted")
        self.history.addItems(self.picks.history_names())
        self.history.currentTextChanged.connect(self._history_chosen)
        self.plot = QLabel()
        self.plot.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.plot.setMinimumSize(*HISTORY_SIZE)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        buttons = QHBoxLayout()
        buttons.addWidget(self.remove)
        buttons.addWidget(self.clear)
        buttons.addStretch(1)
        lay.addWidget(self.list)
        lay.addLayout(buttons)
        lay.addWidget(self.caption)
        lay.addWidget(self.table, 1)
        if self.picks.history_names():
            row = QHBoxLayout()
            row.addWidget(QLabel("history of"))
            row.addWidget(self.history, 1)
            lay.addLayout(row)
            lay.addWidget(self.plot)
        self._buttons()

    # --- the list -------------------------------------------------------------------------------
    def add(self, pick) -> bool:
        """Keep ``pick`` (a grid cell's); True when kept (then shown)."""
        try:
            kept = self.picks.add(pick)
        except GeoshadeError as err:
            self.host.show_error(str(err))
            return False
        if kept:
            self._list()
            self.follow()
        return kept

    def _list(self) -> None:
        with QSignalBlocker(self.list):
            self.list.clear()
            self.list.addItems(self.picks.labels())
            if self.picks.current is not None:
                self.list.setCurrentRow(self.picks.current)
        self._buttons()

    def _buttons(self) -> None:
        self.remove.setEnabled(self.picks.current is not None)
        self.clear.setEnabled(bool(self.picks.cells))

    def _chosen(self, row: int) -> None:
        if 0 <= row < len(self.picks.cells):
            self.picks.choose(row)
            self.follow()

    def _remove(self) -> None:
        self.picks.remove()
        self._list()
        self.follow()

    def _clear(self) -> None:
        self.picks.clear()
        self._list()
        self.follow()

    def _history_chosen(self, name: str) -> None:
        if not name:
            return
        try:
            self.picks.history_name = name
        except GeoshadeError as err:
            self.host.show_error(str(err))
            return
        self.follow()

    # --- what is shown --------------------------------------------------------------------------
    def follow(self) -> None:
        """Show the chosen cell at the shown step (the table and the plot's cursor), where
        anything they show changed since they were drawn."""
        p = self.picks
        shown = (tuple(p.cells), p.current, p.step(), p.history_name)
        if shown == self._shown:
            return
        self._shown = shown
        try:
            rows, image = p.rows(), p.history_image(HISTORY_SIZE)
        except GeoshadeError as err:
            self.host.show_error(str(err))
            return
        self.caption.setText(p.caption())
        self.table.setRowCount(len(rows))
        for r, texts in enumerate(rows):
            for c, text in enumerate(texts):
                item = QTableWidgetItem(text)
                if c == 1:
                    item.setTextAlignment(Qt.AlignmentFlag.AlignRight
                                          | Qt.AlignmentFlag.AlignVCenter)
                self.table.setItem(r, c, item)
        name = p.history_name
        if name is not None and self.history.currentText() != name:
            with QSignalBlocker(self.history):
                self.history.setCurrentText(name)
        if image is None:
            self.plot.clear()
        else:
            self.plot.setPixmap(QPixmap.fromImage(to_qimage(image)))


__all__ = ["PicksPanel"]
