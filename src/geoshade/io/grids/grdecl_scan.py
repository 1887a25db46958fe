"""The numba kernels of the GRDECL reader (:mod:`geoshade.io.grids.grdecl`): a decimal number parser
and the scanner of long numeric records, compiled on first use (:func:`kernels`) and cached on
disk.  Plain Python functions until then (the tests call them directly, too).

Numbers: ``[+-]digits[.digits][(E|e|D|d)[+-]digits]`` and, as Python's ``float`` reads them (so
the numpy path of small records and this scanner agree), ``nan``, ``inf`` and ``infinity`` in
any case with an optional sign.  Whether such a value may stand where it is (a depth may not) is
checked by the model (:meth:`geoshade.models.CornerPointGrid.check_geometry`).
"""

from __future__ import annotations

import numpy as np

NEED, FULL, SLASH, BAD, OVERRUN, EOF = range(6)
_POW10 = np.array([float(10**i) for i in range(23)])
_JITTED: dict = {}


def kernels() -> dict:
    """``{"scan": jitted _scan}``; numba is imported only here."""
    if not _JITTED:
        from numba import njit

        g = globals()
        g["_word"] = njit(cache=True, nogil=True)(_word)
        g["_to_float"] = njit(cache=True, nogil=True)(_to_float)
        _JITTED["scan"] = njit(cache=True, nogil=True)(_scan)
    return _JITTED


def _word(buf, i, b, word):
    """``buf[i:b]`` equals the lower-case ASCII ``word`` in any case."""
    if b - i != len(word):
        return False
    for q in range(len(word)):
        if buf[i + q] | 32 != word[q]:
            return False
    return True


_NAN = np.array([110, 97, 110], np.uint8)
_INF = np.array([105, 110, 102], np.uint8)
_INFINITY = np.array([105, 110, 102, 105, 110, 105, 116, 121], np.uint8)


def _to_float(buf, a, b):
    """Parse ``buf[a:b]`` as a decimal number: (ok, value); correctly rounded for ≤ 15 digits."""
    i = a
    neg = False
    c = buf[i]
    if c == 45 or c == 43:
        neg = c == 45
        i += 1
    if i < b and (buf[i] | 32 == 110 or buf[i] | 32 == 105):  # nan, inf, infinity
        if _word(buf, i, b, _NAN):
            return True, np.nan
        if _word(buf, i, b, _INF) or _word(buf, i, b, _INFINITY):
            return True, -np.inf if neg else np.inf
        return False, 0.0
    mant = 0
    nd = 0
    e10 = 0
    digits = 0
    frac = False
    while i < b:
        c = buf[i]
        if c == 46 and not frac:
            frac = True
            i += 1
            continue
        if c < 48 or c > 57:
            break
        digits += 1
        if nd < 18:
            if mant > 0 or c != 48:
                mant = mant * 10 + (c - 48)
                nd += 1
            if frac:
                e10 -= 1
        elif not frac:
            e10 += 1
        i += 1
    if digits == 0:
        return False, 0.0
    if i < b:
        c = buf[i]
        if c != 69 and c != 101 and c != 68 and c != 100:
            return False, 0.0
        i += 1
        eneg = False
        if i < b and (buf[i] == 45 or buf[i] == 43):
            eneg = buf[i] == 45
            i += 1
        if i >= b:
            return False, 0.0
        ex = 0
        while i < b:
            c = buf[i]
            if c < 48 or c > 57:
                return False, 0.0
            if ex < 100000:
                ex = ex * 10 + (c - 48)
            i += 1
        e10 += -ex if eneg else ex
    if mant < 9007199254740992 and -22 <= e10 <= 22:  # exact power: correctly rounded
        v = float(mant) * _POW10[e10] if e10 >= 0 else float(mant) / _POW10[-e10]
    else:
        v = float(mant) * 10.0 ** e10 if e10 >= 0 else float(mant) / 10.0 ** (-e10)
    return True, -v if neg else v




def _scan(buf, pos, end, final, out, base, limit, st, stv, whole):
    """Parse numbers from ``buf[pos:end]`` into ``out[base:]`` until ``/``, a full ``out`` or
    the end of the bytes.

    Returns (status, pos, n): ``n`` values written; ``pos`` where to go on (for BAD/OVERRUN
    the start of the offending token, for NEED the start of an unfinished token).  ``st[0]``
    holds repeats still to write (value ``stv[0]``), ``st[1]`` = inside a comment.  ``limit`` is
    how many values may still come: a repeat beyond it gives OVERRUN.  ``whole`` (1 for an
    integer ``out``): NaN, infinities and values beyond int32 give BAD (a cast would be
    undefined).
    """
    n = 0
    cap = out.shape[0] - base
    while True:
        rep = st[0]
        if rep > 0:
            m = min(rep, cap - n)
            v = stv[0]
            for q in range(base + n, base + n + m):
                out[q] = v
            n += m
            st[0] = rep - m
            if st[0] > 0:
                return FULL, pos, n
        if st[1] == 1:
            while pos < end and buf[pos] != 10:
                pos += 1
            if pos >= end:
                return (EOF if final else NEED), pos, n
            st[1] = 0
        while pos < end and buf[pos] <= 32:
            pos += 1
        if pos >= end:
            return (EOF if final else NEED), pos, n
        c = buf[pos]
        if c == 47:
            return SLASH, pos + 1, n
        if c == 45:
            if pos + 1 < end:
                if buf[pos + 1] == 45:
                    st[1] = 1
                    pos += 2
                    continue
            elif not final:
                return NEED, pos, n
        if n >= cap:
            return FULL, pos, n
        t0 = pos
        star = -1
        while pos < end:
            c = buf[pos]
            if c <= 32 or c == 47 or c == 39:
                break
            if c == 42 and star < 0:
                star = pos
            pos += 1
        if pos >= end and not final:
            return NEED, t0, n
        if pos == t0:
            return BAD, t0, n
        if star < 0:
            ok, v = _to_float(buf, t0, pos)
            if not ok or (whole and not abs(v) < 2147483648.0):
                return BAD, t0, n
            out[base + n] = v
            n += 1
        else:
            cnt = 0
            for q in range(t0, star):
                c = buf[q]
                if c < 48 or c > 57 or cnt > 100000000000000:
                    return BAD, t0, n
                cnt = cnt * 10 + (c - 48)
            if cnt <= 0 or star + 1 >= pos:
                return BAD, t0, n
            ok, v = _to_float(buf, star + 1, pos)
            if not ok or (whole and not abs(v) < 2147483648.0):
                return BAD, t0, n
            if cnt > limit - n:
                return OVERRUN, t0, n
            st[0] = cnt
            stv[0] = v
