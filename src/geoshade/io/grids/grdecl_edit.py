"""The edit keywords of GRDECL files and decks: ``EQUALS``, ``MULTIPLY``, ``ADD``, ``COPY``,
``MINVALUE``, ``MAXVALUE`` on cell properties, ACTNUM and the block-centred cell arrays (``DX DY
DZ TOPS``), each record with an optional ``I1 I2 J1 J2 K1 K2`` box that defaults to the current
BOX.  A mixin of :class:`geoshade.io.grids.grdecl.GridBuilder`.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.block_centred import CELL_KEYWORDS
from geoshade.io.grids.grid_checks import check_memory

#: the edit keywords
EDIT_KEYWORDS = ("EQUALS", "MULTIPLY", "ADD", "COPY", "MINVALUE", "MAXVALUE")
#: ECLIPSE defaults of properties that EQUALS may create for part of the grid (else NaN)
_DEFAULTS = {"NTG": 1.0, **{f"MULT{a}{s}": 1.0 for a in "XYZ" for s in ("", "-")},
             "MULTPV": 1.0}


class EditKeywords:
    """The handler of the edit keywords (:meth:`_edit`), for a grid builder."""

    root: Path
    dims: tuple[int, int, int] | None
    actnum: np.ndarray | None
    props: dict[str, np.ndarray]
    block: dict[str, np.ndarray]

    # provided by the grid builder
    def need_dims(self, kw, src) -> tuple[int, int, int]:  # pragma: no cover
        raise NotImplementedError

    def _box_from(self, rec, at, kw, src, use_current=True) -> tuple:  # pragma: no cover
        raise NotImplementedError

    def block_array(self, name: str) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def _shape(self) -> tuple[int, int, int]:
        if self.dims is None:  # pragma: no cover - need_dims() came first
            raise InputError(f"{self.root}: an edit keyword before SPECGRID/DIMENS")
        return self.dims

    def _get(self, name) -> np.ndarray | None:
        if name in CELL_KEYWORDS:  # block-centred geometry: DX DY DZ TOPS
            return self.block.get(name)
        return self.actnum if name == "ACTNUM" else self.props.get(name)

    def _target(self, name, is_int) -> np.ndarray:
        if name in CELL_KEYWORDS:
            return self.block_array(name)
        if name == "ACTNUM":
            if self.actnum is None:
                self.actnum = np.ones(self._shape(), np.uint8, order="F")
            return self.actnum
        arr = self.props.get(name)
        if arr is None:
            shape = self._shape()
            n = shape[0] * shape[1] * shape[2]
            check_memory(self.root, f"{name} ({n} values)", 4 * n)
            arr = np.zeros(shape, np.int32, order="F") if is_int else \
                np.full(shape, _DEFAULTS.get(name, np.nan), np.float32, order="F")
            self.props[name] = arr
        return arr

    def _edit_records(self, kw, src):
        """The records of edit keyword ``kw``, checked: ``(name, target, value, box)`` (COPY:
        ``target`` is the destination and ``value`` None; the others: ``target`` None)."""
        while True:
            rec = src.record(kw)
            if not rec:
                return
            self.need_dims(kw, src)
            name = str(rec[0]).strip().upper() if rec[0] else ""
            dst, value = None, None
            try:
                if kw == "COPY":
                    dst = str(rec[1]).strip().upper()
                else:
                    value = float(str(rec[1]).replace("D", "E").replace("d", "e"))
            except (TypeError, ValueError, IndexError):
                want = "SOURCE TARGET" if kw == "COPY" else "NAME VALUE"
                raise InputError(f"{src.path}: {kw}: expected {want} [I1 I2 J1 J2 K1 K2], got "
                                 f"{' '.join(map(str, rec))!r}") from None
            yield name, dst, value, self._box_from(rec, 2, kw, src)

    def _edit(self, kw, src):
        """EQUALS / MULTIPLY / ADD / MINVALUE / MAXVALUE / COPY records on cell properties."""
        for name, dst, value, box in self._edit_records(kw, src):
            if kw == "EQUALS":
                self._target(name, name.endswith("NUM"))[box] = value
                continue
            arr = self._get(name)
            if arr is None:
                warnings.warn(f"{src.path}: {kw} {name}: {name} is not defined before; "
                              "record skipped", stacklevel=2)
                continue
            if kw == "COPY":
                self._target(dst, arr.dtype.kind in "iu")[box] = arr[box]
                continue
            op = {"MULTIPLY": np.multiply, "ADD": np.add, "MINVALUE": np.maximum,
                  "MAXVALUE": np.minimum}[kw]
            arr[box] = op(arr[box], value).astype(arr.dtype)


__all__ = ["EDIT_KEYWORDS", "EditKeywords"]
