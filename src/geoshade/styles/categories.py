"""Categorical properties: integer codes (facies, regions, zones, SATNUM, FIPNUM ...) drawn with
one qualitative colour per code and a legend with one entry per code, instead of a colour bar.

A property is categorical when the colour style says so (``categorical=True``), never when it
says ``False``, and by default (``None``) when its name is a known region/facies keyword
(:data:`CATEGORICAL_KEYWORDS`) holding whole numbers, or when its array holds integers with at
most :data:`MAX_CODES` distinct values.

The picture's colours and the legend's come from one palette: :func:`categorical_palette` puts
each code's colour at exactly the palette entry the code's value maps to over ``lo..hi`` (the
same ``rint((v - lo) / (hi - lo) * N)`` the colour index maps use), so a cell of code ``c`` is
drawn in the legend's colour of ``c``.

>>> import numpy as np
>>> is_categorical("FIPNUM", np.array([1.0, 2.0])), is_categorical("PORO", np.array([0.1, 0.2]))
(True, False)
>>> pal = categorical_palette([1, 2, 5])
>>> pal.lo, pal.hi, [pal.rgba_of(c)[:3] == tuple(pal.colors[n][:3]) for n, c in
...                   enumerate(pal.codes)]
(1.0, 5.0, [True, True, True])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geoshade.styles.options import ColorStyle

#: keywords of region, facies and zone codes (and ``*NUM`` region arrays): categorical by name
CATEGORICAL_KEYWORDS = frozenset({
    "FACIES", "FACIESCODE", "REGION", "REGIONS", "ZONE", "ZONES", "SATNUM", "FIPNUM", "PVTNUM",
    "EQLNUM", "LITHO", "LITHOLOGY", "IMBNUM", "ROCKNUM", "MULTNUM", "FLUXNUM", "OPERNUM",
    "ENDNUM", "MISCNUM", "KRNUM", "WH2NUM", "SATNUMS", "LITHOCLASS", "STRAT", "UNIT", "UNITS",
    "SEGMENT", "SEGMENTS", "FAULTBLOCK", "FAULTBLOCKS",
})
#: integer arrays with at most this many distinct values are categorical when not told
MAX_CODES = 64
#: a legend lists at most this many codes, then says how many more there are
MAX_ENTRIES = 24
#: a legend entry's longest text; a longer one ends in "…" (never cut silently)
ENTRY_CHARS = 40


def is_categorical(name: str | None, values=None, categorical: bool | None = None,
                   codes=None) -> bool:
    """Whether property ``name`` with ``values`` is drawn as categories.

    Parameters
    ----------
    name : str or None
        The property (keyword or expression); an expression is never categorical by name.
    values : array-like, optional
        Its values (any shape); only their dtype and whether they are whole numbers are used.
    categorical : bool or None
        The colour style's choice: True or False decides; None decides from name and values.
    codes : array-like, optional
        The distinct finite values, where known (saves a pass over ``values``).

    Returns
    -------
    bool

    Examples
    --------
    >>> import numpy as np
    >>> is_categorical("SATNUM", np.array([1.0, 2.0, 3.0]))
    True
    >>> is_categorical("ZONE", np.array([0.5, 1.5]))   # not whole numbers
    False
    >>> is_categorical("X", np.arange(10, dtype=np.int32)), is_categorical("X", np.arange(9.0))
    (True, False)
    >>> is_categorical("PORO", np.arange(3), categorical=True)
    True
    """
    if categorical is not None:
        return bool(categorical)
    if values is None and codes is None:
        return False
    n = str(name or "").strip().upper()
    u = np.asarray(codes if codes is not None else distinct_codes(values), np.float64)
    whole = bool(u.size) and bool(np.all(u == np.round(u)))
    if not whole or u.size == 0:
        return False
    if by_name(n):
        return True
    # (the dtype of a dask array without reading it)
    dtype = u.dtype if values is None else (values.dtype if hasattr(values, "dtype")
                                            else np.asarray(values).dtype)
    return bool(np.issubdtype(dtype, np.integer) and u.size <= MAX_CODES)


def by_name(name: str | None) -> bool:
    """A region/facies/zone keyword (:data:`CATEGORICAL_KEYWORDS`, or a ``*NUM`` keyword).

    >>> by_name("fipnum"), by_name("EQLNUM"), by_name("PORO"), by_name("log10(PERMX)")
    (True, True, False, False)
    """
    n = str(name or "").strip().upper()
    return n in CATEGORICAL_KEYWORDS or (n.endswith("NUM") and n.isidentifier())


def distinct_codes(values, active=None) -> np.ndarray:
    """The distinct finite values of ``values`` (where ``active``), sorted, as float64."""
    v = np.asarray(values)
    if active is not None:
        v = v[np.asarray(active, bool)]
    v = np.asarray(v, np.float64).ravel()
    return np.unique(v[np.isfinite(v)])


def qualitative_colors(n: int) -> np.ndarray:
    """``(n, 4)`` uint8 distinct colours for ``n`` categories: matplotlib's ``tab10`` up to 10,
    ``tab20`` up to 20, then ``tab20`` + ``tab20b`` + ``tab20c`` (60), then evenly spread hues
    at three lightness levels.

    >>> qualitative_colors(3)[:, :3].tolist()
    [[31, 119, 180], [255, 127, 14], [44, 160, 44]]
    >>> len(np.unique(qualitative_colors(60), axis=0))
    60
    """
    import matplotlib

    n = int(n)
    if n <= 0:
        return np.zeros((0, 4), np.uint8)
    if n <= 10:
        base = matplotlib.colormaps["tab10"].colors
    elif n <= 20:
        base = matplotlib.colormaps["tab20"].colors
    else:
        base = [*matplotlib.colormaps["tab20"].colors, *matplotlib.colormaps["tab20b"].colors,
                *matplotlib.colormaps["tab20c"].colors]
    rgb = np.asarray(base, np.float64)[:, :3]
    if n > len(rgb):
        from matplotlib.colors import hsv_to_rgb

        extra = n - len(rgb)
        k = np.arange(extra)
        hsv = np.stack([(k * 0.618033988749895) % 1.0, 0.55 + 0.35 * (k % 2),
                        0.95 - 0.25 * (k % 3) / 2], axis=1)
        rgb = np.concatenate([rgb, hsv_to_rgb(hsv)])
    out = np.empty((n, 4), np.uint8)
    out[:, :3] = np.clip(np.rint(rgb[:n] * 255), 0, 255)
    out[:, 3] = 255
    return out


@dataclass(frozen=True)
class CategoricalPalette:
    """One qualitative colour per code, laid out in a 256-entry palette over ``lo..hi``.

    codes:   (n,) float64 sorted distinct codes
    colors:  (n, 4) uint8 the colour of each code
    lo, hi:  the value range the colour index maps use (the smallest and largest code)
    palette: (256, 4) uint8; entry ``index[n]`` is ``colors[n]``; with ``gaps`` entry 255 is
             the no-value colour and codes map to 0..254
    index:   (n,) int the palette entry of each code
    gaps:    cells without a value exist (entry 255 reserved)
    """

    codes: np.ndarray
    colors: np.ndarray
    lo: float
    hi: float
    palette: np.ndarray
    index: np.ndarray
    gaps: bool = False

    def rgba_of(self, code) -> tuple[int, ...]:
        """The RGBA the picture draws ``code`` in (its palette entry)."""
        n = int(np.searchsorted(self.codes, float(code)))
        return tuple(int(x) for x in self.palette[self.index[n]])

    @property
    def shared(self) -> int:
        """How many codes share a palette entry with another code (too many or too unevenly
        spread codes for 255 entries); 0 when every code has its own colour."""
        _, counts = np.unique(self.index, return_counts=True)
        return int(counts[counts > 1].sum())


def code_index(values, lo: float, hi: float, gaps: bool = False) -> np.ndarray:
    """Palette entries of ``values`` over ``lo..hi``: ``rint((v - lo) / (hi - lo) * N)``
    clipped to 0..N, N = 254 with ``gaps`` (entry 255 = no value) else 255 -- the formula of
    the parts' colour index maps.

    >>> code_index(np.array([1.0, 2.0, 3.0]), 1.0, 3.0).tolist()
    [0, 128, 255]
    """
    top = 254.0 if gaps else 255.0
    v = np.asarray(values, np.float64)
    span = float(hi) - float(lo)
    t = (v - float(lo)) / span if span > 0 else np.zeros_like(v)
    return np.clip(np.rint(np.nan_to_num(t, nan=0.0) * top), 0, top).astype(np.int64)


def categorical_palette(codes, gaps: bool = False, nan_rgba=None,
                        colors=None) -> CategoricalPalette:
    """The palette that draws each of ``codes`` in its own qualitative colour.

    Every palette entry takes the colour of the code whose entry is nearest, so the entry a
    code's value maps to holds exactly that code's colour.

    Parameters
    ----------
    codes : array-like
        The distinct codes (any order; duplicates and non-finite values are dropped).
    gaps : bool
        Reserve entry 255 for values without a colour (``nan_rgba``, RGBA 0..1).
    colors : (n, 4) uint8, optional
        The codes' colours (sorted code order); default :func:`qualitative_colors`.

    Returns
    -------
    CategoricalPalette

    Examples
    --------
    >>> p = categorical_palette([3, 1, 2], gaps=True, nan_rgba=(0.5, 0.5, 0.5, 1))
    >>> p.index.tolist(), p.palette[255].tolist(), p.shared
    ([0, 127, 254], [128, 128, 128, 255], 0)
    """
    c = np.asarray(codes, np.float64).ravel()
    c = np.unique(c[np.isfinite(c)])
    if c.size == 0:
        c = np.zeros(1)
    cols = qualitative_colors(c.size) if colors is None else np.asarray(colors, np.uint8)
    lo, hi = float(c[0]), float(c[-1])
    idx = code_index(c, lo, hi, gaps)
    top = 255 if gaps else 256
    entries = np.arange(top)
    # each entry takes the colour of the code with the nearest entry (ties: the lower code)
    pos = np.clip(np.searchsorted(idx, entries), 0, c.size - 1)
    below = np.clip(pos - 1, 0, c.size - 1)
    nearest = np.where(np.abs(idx[below] - entries) <= np.abs(idx[pos] - entries), below, pos)
    exact = np.searchsorted(idx, entries)
    hit = (exact < c.size) & (idx[np.clip(exact, 0, c.size - 1)] == entries)
    nearest = np.where(hit, np.clip(exact, 0, c.size - 1), nearest)
    pal = np.zeros((256, 4), np.uint8)
    pal[:top] = cols[nearest]
    if gaps:
        nan = (0.6, 0.6, 0.6, 1.0) if nan_rgba is None else nan_rgba
        pal[255] = np.clip(np.rint(np.asarray(nan, float) * 255), 0, 255).astype(np.uint8)
    # codes sharing an entry: the entry shows the first, and so does the legend (rgba_of)
    return CategoricalPalette(c, cols, lo, hi, pal, idx, gaps)


#: codes that mean "no value" in a file format (``meta["format"]``): ROFF's undefined discrete
UNDEFINED_CODES = {"ROFF": (-999.0,)}


def undefined_codes(meta: dict | None) -> tuple[float, ...]:
    """The codes meaning "no value" in the format a model was read from (a grid store's
    ``source_format``: the file it was ingested from).

    >>> undefined_codes({"format": "ROFF"}), undefined_codes({"format": "EGRID"})
    ((-999.0,), ())
    >>> undefined_codes({"format": "grid-store", "source_format": "ROFF"})
    (-999.0,)
    """
    m = meta or {}
    return UNDEFINED_CODES.get(str(m.get("source_format") or m.get("format", "")).upper(), ())


@dataclass(frozen=True)
class CodeStyle:
    """The colour style of codes where some codes mean "no value" (ROFF's -999): those become
    NaN (the no-value colour, palette entry 255) in the colour index map; every other code maps
    linearly over its range (the :class:`ColorStyle` interface the parts' colour index maps
    use: ``transform``, ``transformed_range``, ``nan_index``, ``log``).

    >>> s = CodeStyle((-999.0,))
    >>> s.transform(np.array([1, -999, 3])).tolist()
    [1.0, nan, 3.0]
    """

    undefined: tuple = ()
    log: bool = False

    def transform(self, values) -> np.ndarray:
        v = np.asarray(values, np.float64)
        if self.undefined:
            v = np.where(np.isin(v, self.undefined), np.nan, v)
        return v

    @staticmethod
    def transformed_range(lo: float, hi: float) -> tuple[float, float]:
        return float(lo), float(hi)

    @staticmethod
    def nan_index(t, lo: float, hi: float) -> np.ndarray:
        """0..254 by value, 255 where there is none (:meth:`ColorStyle.nan_index`)."""

        return ColorStyle.nan_index(t, lo, hi)


def code_text(code: float, names: dict | None = None) -> str:
    """A legend entry's text: ``3 sand`` where the file names the code, else ``3``.

    >>> code_text(2.0, {2: "shale"}), code_text(7.0), code_text(-999.0, {})
    ('2 shale', '7', '-999')
    """
    c = int(code) if float(code).is_integer() else code
    name = (names or {}).get(c) if names else None
    if name is None and names:
        name = names.get(str(c))
    return f"{c} {name}" if name not in (None, "") and str(name) != str(c) else str(c)


def entry_text(text: str, limit: int = ENTRY_CHARS) -> str:
    """A legend entry's text within ``limit`` characters, ending in "…" where it was cut.

    >>> entry_text("3 " + "fluvial channel sandstone, cross-bedded"), entry_text("2 shale")
    ('3 fluvial channel sandstone, cross-bedd…', '2 shale')
    """
    text = str(text)
    return text if len(text) <= limit else text[:limit - 1].rstrip() + "…"


def legend_entries(pal: CategoricalPalette, names: dict | None = None,
                   max_entries: int = MAX_ENTRIES) -> tuple[tuple[str, tuple], ...]:
    """``(text, rgba)`` legend entries of a categorical palette: one per code (the picture's
    colour of each code, its text cut with "…" past :data:`ENTRY_CHARS`), at most
    ``max_entries``; past that the last entry says how many more codes there are (with no
    swatch colour: alpha 0).

    >>> p = categorical_palette(range(30))
    >>> e = legend_entries(p)
    >>> len(e), e[-1][0], e[0][1] == p.rgba_of(0)
    (24, '+7 more', True)
    """
    n = pal.codes.size
    shown = n if n <= max_entries else max(1, max_entries - 1)
    out = [(entry_text(code_text(c, names)), pal.rgba_of(c)) for c in pal.codes[:shown]]
    if shown < n:
        out.append((f"+{n - shown} more", (0, 0, 0, 0)))
    return tuple(out)


__all__ = ["CATEGORICAL_KEYWORDS", "ENTRY_CHARS", "MAX_CODES", "MAX_ENTRIES", "UNDEFINED_CODES",
           "CategoricalPalette", "CodeStyle", "by_name", "categorical_palette", "code_index",
           "code_text", "distinct_codes", "entry_text", "is_categorical", "legend_entries",
           "qualitative_colors", "undefined_codes"]
