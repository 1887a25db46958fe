"""Large corner-point cases for ``geoshade bench grid --full``, written independently of geoshade.

:func:`write_case` streams an ECLIPSE case (``CASE.EGRID``, ``CASE.INIT``, ``CASE.UNRST``) of any
size, layer slab by layer slab, straight into the files: the ECLIPSE unformatted layout (a
24-byte record header between Fortran markers, data in blocks of 1000 values between markers,
big-endian) is written here with numpy, not with geoshade's or resfo's writers, so that the
benchmark reads files that geoshade did not make (a test checks them against resfo on a small
case).  Memory stays at a few slabs of ``nx·ny`` values whatever the grid's size.

The case: vertical pillars on a 50 m × 50 m grid, layers 2–6 m thick dipping and undulating, two
faults along pillar lines (``i = nx // 3`` with a throw growing along j, ``j = 2 ny // 3``),
5 % inactive cells in smooth blobs, PORO/PERMX (INIT) and SWAT at ``steps`` report steps (UNRST,
active cells only, as simulators write them).

:func:`write_grdecl_case` writes the same grid as GRDECL text (also streamed).

Run ``python benchmarks/grid_cases.py OUTDIR NX NY NZ [--steps N] [--grdecl]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

BLOCK = {"INTE": 1000, "REAL": 1000, "LOGI": 1000, "DOUB": 1000, "CHAR": 105, "MESS": 1}
DTYPE = {"INTE": ">i4", "REAL": ">f4", "LOGI": ">i4", "DOUB": ">f8", "CHAR": "S8", "MESS": "S1"}
INACTIVE = 0.05


class Record:
    """One record streamed into an open file: header now, then :meth:`write` in any pieces."""

    def __init__(self, fh, keyword: str, count: int, type_: str):
        self.fh, self.count, self.type = fh, int(count), type_
        self.block, self.dtype = BLOCK[type_], np.dtype(DTYPE[type_])
        head = np.zeros(1, [("m0", ">i4"), ("kw", "S8"), ("n", ">i4"), ("t", "S4"),
                            ("m1", ">i4")])
        head[0] = (16, keyword.ljust(8).encode(), self.count, type_.encode(), 16)
        fh.write(head.tobytes())
        self.done, self.pending = 0, np.zeros(0, self.dtype)

    def write(self, values) -> None:
        v = np.asarray(values).astype(self.dtype, copy=False).ravel(order="F")
        if self.pending.size:
            v = np.concatenate([self.pending, v])
        nfull = v.size // self.block
        if nfull:
            blocks = v[: nfull * self.block].reshape(nfull, self.block)
            nb = self.block * self.dtype.itemsize
            out = np.empty(nfull, [("m0", ">i4"), ("d", self.dtype, (self.block,)),
                                   ("m1", ">i4")])
            out["m0"], out["d"], out["m1"] = nb, blocks, nb
            self.fh.write(out.tobytes())
        self.pending = v[nfull * self.block:].copy()
        self.done += v.size - self.pending.size

    def close(self) -> None:
        v = self.pending
        if v.size:
            nb = np.array([v.size * self.dtype.itemsize], ">i4").tobytes()
            self.fh.write(nb + v.astype(self.dtype).tobytes() + nb)
            self.done += v.size
        if self.done != self.count:
            raise RuntimeError(f"record wrote {self.done} of {self.count} values")


def record(fh, keyword: str, values, type_: str) -> None:
    r = Record(fh, keyword, np.asarray(values).size, type_)
    r.write(values)
    r.close()


# --- the case ----------------------------------------------------------------------------------
class Case:
    """The geometry and properties of the generated case, one layer at a time."""

    def __init__(self, nx: int, ny: int, nz: int, steps: int = 2):
        self.nx, self.ny, self.nz, self.steps = nx, ny, nz, steps
        self.d = 50.0
        self.px = np.arange(nx + 1)[:, None] * self.d
        self.py = np.arange(ny + 1)[None, :] * self.d
        lx, ly = nx * self.d, ny * self.d
        rng = np.random.default_rng(7)
        self.h = rng.uniform(2.0, 6.0, nz)
        self.top = (2000.0 + 0.02 * self.px + 0.01 * self.py
                    + 15.0 * np.sin(2 * np.pi * self.px / lx * 1.3)
                    * np.cos(2 * np.pi * self.py / ly * 0.9))
        self.lat = 1.0 + 0.3 * np.sin(2 * np.pi * (self.px / lx + 0.3 * self.py / ly))
        self.fa, self.fb = max(nx // 3, 1), max(2 * ny // 3, 1)
        self.layer_poro = rng.uniform(0.08, 0.3, nz)
        ia, jb = np.arange(nx), np.arange(ny)
        self.throw = {}
        for a in (0, 1):
            for b in (0, 1):
                t = np.where(ia[:, None] >= self.fa, 8.0 + 14.0 * ((jb + b) / ny)[None, :], 0.0)
                t = t + np.where(jb[None, :] >= self.fb, -(5.0 + 6.0 * ((ia + a) / nx))[:, None],
                                 0.0)
                self.throw[a, b] = t
        self.cu = (np.arange(nx) + 0.5)[:, None] / nx
        self.cv = (np.arange(ny) + 0.5)[None, :] / ny
        # the blob level leaving INACTIVE of the cells out, from a 64³ sample of the same field
        s = (np.arange(64) + 0.5) / 64
        sample = self._blob(s[:, None, None], s[None, :, None], s[None, None, :])
        self.level = float(np.quantile(sample, 1.0 - INACTIVE))

    @property
    def ncells(self) -> int:
        return self.nx * self.ny * self.nz

    def coord(self) -> np.ndarray:
        """(ny+1, nx+1, 6) float32 vertical pillars from 1900 m to 3000 m."""
        c = np.empty((self.ny + 1, self.nx + 1, 6), np.float32)
        c[..., 0] = c[..., 3] = self.px.T
        c[..., 1] = c[..., 4] = self.py.T
        c[..., 2], c[..., 5] = 1900.0, 3000.0
        return c

    def horizon(self, k: int) -> np.ndarray:
        """(nx+1, ny+1) depth of horizon k (top of layer k; k = nz: the base)."""
        return self.top + self.lat * float(np.sum(self.h[:k]))

    def zcorn_layer(self, k: int) -> np.ndarray:
        """(2nx, 2ny, 2) float32 ZCORN of layer k (F order inside)."""
        nx, ny = self.nx, self.ny
        out = np.empty((2 * nx, 2 * ny, 2), np.float32, order="F")
        for c in (0, 1):
            hz = self.horizon(k + c)
            for a in (0, 1):
                for b in (0, 1):
                    out[a::2, b::2, c] = np.round(hz[a:a + nx, b:b + ny] + self.throw[a, b], 3)
        return out

    def blob(self, k: int) -> np.ndarray:
        return self._blob(self.cu, self.cv, (k + 0.5) / self.nz)

    @staticmethod
    def _blob(u, v, w):
        return (np.cos(2 * np.pi * 1.7 * u + 0.3) * np.cos(2 * np.pi * 2.3 * v + 1.1)
                * np.cos(2 * np.pi * 1.1 * w + 0.7)
                + 0.5 * np.cos(2 * np.pi * 3.1 * u + 2.0) * np.cos(2 * np.pi * 0.7 * v)
                * np.cos(2 * np.pi * 2.9 * w + 0.2))

    def actnum_layer(self, k: int) -> np.ndarray:
        # threshold chosen so that about INACTIVE of the cells are inactive (blobs)
        return (self.blob(k) < self.level).astype(np.int32)

    def poro_layer(self, k: int) -> np.ndarray:
        p = self.layer_poro[k] + 0.05 * np.sin(7 * self.cu + 3 * self.cv + k)
        return np.round(np.clip(p, 0.01, 0.38), 4).astype(np.float32)

    def permx_layer(self, k: int) -> np.ndarray:
        return np.round(10.0 ** (-1.0 + 13.0 * self.poro_layer(k).astype(np.float64)),
                        3).astype(np.float32)

    def swat_layer(self, k: int, t: int) -> np.ndarray:
        r = np.sqrt(self.cu ** 2 + self.cv ** 2)
        front = 1.2 * (t + 1) / max(self.steps, 1) * (0.8 + 0.4 * self.poro_layer(k) / 0.3)
        return (0.2 + 0.3 * (1.0 - np.tanh((r - front) / 0.05))).astype(np.float32)


def _intehead(case: Case, nactive: int, date=(1, 1, 2000)) -> np.ndarray:
    h = np.zeros(411, np.int32)
    h[2] = 1  # METRIC
    h[8], h[9], h[10], h[11] = case.nx, case.ny, case.nz, nactive
    h[14] = 1  # oil-water-gas phases (any)
    h[64], h[65], h[66] = date
    h[94] = 100  # ECLIPSE 100
    return h


def write_case(folder, nx: int, ny: int, nz: int, steps: int = 2, name: str = "BIG",
               progress=None) -> dict[str, Path]:
    """Stream ``name.EGRID``, ``name.INIT`` and ``name.UNRST`` into ``folder``; their paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    case = Case(nx, ny, nz, steps)
    n = case.ncells
    paths = {s: folder / f"{name}.{s}" for s in ("EGRID", "INIT", "UNRST")}
    say = progress or (lambda msg: None)
    nact = 0
    with open(paths["EGRID"], "wb") as fh:
        fileh = np.zeros(100, np.int32)
        fileh[0], fileh[1], fileh[6] = 3, 2007, 1
        record(fh, "FILEHEAD", fileh, "INTE")
        record(fh, "MAPUNITS", np.array([b"METRES  "]), "CHAR")
        record(fh, "GRIDUNIT", np.array([b"METRES  ", b"        "]), "CHAR")
        gh = np.zeros(100, np.int32)
        gh[0], gh[1], gh[2], gh[3], gh[24] = 1, nx, ny, nz, 1  # [24]: NUMRES
        record(fh, "GRIDHEAD", gh, "INTE")
        record(fh, "COORD", case.coord().ravel(), "REAL")  # file order: 6 a pillar, i fastest
        z = Record(fh, "ZCORN", 8 * n, "REAL")
        for k in range(nz):
            zl = case.zcorn_layer(k)
            z.write(zl[:, :, 0])
            z.write(zl[:, :, 1])
            if k % 10 == 0:
                say(f"EGRID ZCORN layer {k}/{nz}")
        z.close()
        a = Record(fh, "ACTNUM", n, "INTE")
        for k in range(nz):
            al = case.actnum_layer(k)
            nact += int(al.sum())
            a.write(al)
        a.close()
        record(fh, "ENDGRID", np.zeros(0, np.int32), "INTE")
    with open(paths["INIT"], "wb") as fh:
        record(fh, "INTEHEAD", _intehead(case, nact), "INTE")
        record(fh, "LOGIHEAD", np.zeros(121, np.int32), "LOGI")
        record(fh, "DOUBHEAD", np.zeros(229, np.float64), "DOUB")
        for kw, fn in (("PORO", case.poro_layer), ("PERMX", case.permx_layer)):
            r = Record(fh, kw, nact, "REAL")
            for k in range(nz):
                act = case.actnum_layer(k).astype(bool)
                r.write(fn(k).ravel(order="F")[act.ravel(order="F")])
            r.close()
            say(f"INIT {kw}")
    with open(paths["UNRST"], "wb") as fh:
        for t in range(steps):
            record(fh, "SEQNUM", np.array([t], np.int32), "INTE")
            record(fh, "INTEHEAD", _intehead(case, nact, (1, 1 + t % 12, 2000 + t // 12)),
                   "INTE")
            record(fh, "LOGIHEAD", np.zeros(121, np.int32), "LOGI")
            record(fh, "DOUBHEAD", np.zeros(229, np.float64), "DOUB")
            record(fh, "STARTSOL", np.zeros(0, np.int32), "MESS")
            r = Record(fh, "SWAT", nact, "REAL")
            for k in range(nz):
                act = case.actnum_layer(k).astype(bool)
                r.write(case.swat_layer(k, t).ravel(order="F")[act.ravel(order="F")])
            r.close()
            record(fh, "ENDSOL", np.zeros(0, np.int32), "MESS")
            say(f"UNRST step {t}")
    return paths


def fixed_text(arr, decimals: int) -> bytes:
    """Values as fixed-point text, 8 a line (vectorised: no per-value Python formatting).

    >>> fixed_text(np.array([1.5, -2.25, 10.0]), 2)
    b'  1.50  -2.25  10.00\\n'
    """
    v = np.round(np.asarray(arr, np.float64).ravel(order="F") * 10.0 ** decimals).astype(np.int64)
    neg, a = v < 0, np.abs(v)
    ndig = max(len(str(int(a.max(initial=0)))), decimals + 1)
    width = ndig + 1 + (decimals > 0) + 1  # sign, digits, point, separator
    out = np.full((v.size, width), ord(" "), np.uint8)
    pos = width - 2
    for d in range(ndig):  # digits, not values
        if decimals and d == decimals:
            out[:, pos] = ord(".")
            pos -= 1
        digit = (a // 10 ** d) % 10
        show = (a >= 10 ** d) | (d <= decimals)
        out[:, pos] = np.where(show, ord("0") + digit, ord(" "))
        pos -= 1
    lead = np.argmax(out[:, :-1] != ord(" "), axis=1)
    out[np.flatnonzero(neg), lead[neg] - 1] = ord("-")
    out[:, -1] = ord(" ")
    out[7::8, -1] = ord("\n")
    if v.size % 8:
        out[-1, -1] = ord("\n")
    return out.tobytes()


def write_grdecl_case(path, nx: int, ny: int, nz: int, progress=None) -> Path:
    """The same grid as one GRDECL text file (SPECGRID, COORD, ZCORN, ACTNUM, PORO, PERMX)."""
    path = Path(path)
    case = Case(nx, ny, nz, 0)
    say = progress or (lambda msg: None)

    def values(fh, arr, decimals):
        fh.write(fixed_text(arr, decimals))

    with open(path, "wb") as fh:
        fh.write(f"SPECGRID\n{nx} {ny} {nz} 1 F /\n\nCOORD\n".encode())
        values(fh, case.coord().ravel(), 3)  # file order: 6 numbers a pillar, i fastest
        fh.write(b"/\n\nZCORN\n")
        for k in range(nz):
            zl = case.zcorn_layer(k)
            values(fh, zl[:, :, 0], 3)
            values(fh, zl[:, :, 1], 3)
            if k % 10 == 0:
                say(f"GRDECL ZCORN layer {k}/{nz}")
        fh.write(b"/\n\nACTNUM\n")
        for k in range(nz):
            values(fh, case.actnum_layer(k), 0)
        for kw, fn, dec in (("PORO", case.poro_layer, 4), ("PERMX", case.permx_layer, 3)):
            fh.write(f"/\n\n{kw}\n".encode())
            for k in range(nz):
                values(fh, fn(k), dec)
        fh.write(b"/\n")
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("dims", nargs=3, type=int)
    ap.add_argument("--steps", type=int, default=2)
    ap.add_argument("--grdecl", action="store_true", help="also write BIG.GRDECL")
    a = ap.parse_args(argv)

    def say(msg):
        print(msg, file=sys.stderr, flush=True)

    paths = write_case(a.folder, *a.dims, steps=a.steps, progress=say)
    if a.grdecl:
        paths["GRDECL"] = write_grdecl_case(Path(a.folder) / "BIG.GRDECL", *a.dims,
                                            progress=say)
    for p in paths.values():
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
