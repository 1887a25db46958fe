"""Colour palettes: the paper's array ``A`` of 256 RGBA colours, indexed by the colour index map."""

from __future__ import annotations

import importlib.util

import numpy as np

from geoshade.errors import InputError

#: entries of every palette (one per 1-byte colour index)
PALETTE_SIZE = 256
#: a few names listed in error messages
SUGGESTED = ("viridis", "magma", "inferno", "plasma", "cividis", "gray", "bone", "copper", "turbo")


def palette(name: str = "viridis", n: int = 256) -> np.ndarray:
    """A 256-entry RGBA palette from a matplotlib colour map.

    Parameters
    ----------
    name : str
        Any name in ``matplotlib.colormaps`` (``"viridis"``, ``"gray"``, ``"magma_r"``, ...).
    n : int
        Number of distinct colours, 1..256: the map is sampled at ``n`` levels spread evenly over
        the 256 entries (``n < 256`` gives bands).

    Returns
    -------
    (256, 4) uint8
        RGBA, entry 0 for the low end of the colour range, 255 for the high end.

    Raises
    ------
    InputError
        Unknown name (the message lists a few valid ones) or ``n`` outside 1..256.

    Examples
    --------
    >>> p = palette("gray")
    >>> p.shape, p.dtype.name, p[0].tolist(), p[255].tolist()
    ((256, 4), 'uint8', [0, 0, 0, 255], [255, 255, 255, 255])
    >>> len(np.unique(palette("viridis", n=4), axis=0))
    4
    """
    cmap = colormap(name)
    if not isinstance(n, int | np.integer) or not 1 <= int(n) <= PALETTE_SIZE:
        raise InputError(f"palette: n must be an integer in 1..{PALETTE_SIZE}, got {n!r}")
    n = int(n)
    levels = cmap(np.linspace(0.0, 1.0, n), bytes=True)
    band = np.arange(PALETTE_SIZE) * n // PALETTE_SIZE
    return np.ascontiguousarray(levels[band], dtype=np.uint8)


def colormap(name: str):
    """The matplotlib colour map ``name``: one of matplotlib's, or colorcet's (``fire``,
    ``cet_fire``, ``rainbow4`` ...; the ``colors`` extra), ``NAME_r`` reversed.

    >>> colormap("viridis").name
    'viridis'
    """
    import matplotlib  # imported here: `import geoshade.styles` stays light

    if isinstance(name, str) and name in matplotlib.colormaps:
        return matplotlib.colormaps[name]
    base = name[:-2] if isinstance(name, str) and name.endswith("_r") else name

    have_cc = importlib.util.find_spec("colorcet") is not None
    if have_cc and isinstance(name, str):
        importlib.import_module("colorcet")  # registers the cet_* colour maps with matplotlib
        for cand in (name, f"cet_{name}", f"cet_{base}_r" if base != name else None):
            if cand and cand in matplotlib.colormaps:
                return matplotlib.colormaps[cand]
    hint = "" if have_cc else " (colorcet's maps need pip install 'geoshade[colors]')"
    raise InputError(
        f"colormap: unknown colour map {name!r}; expected a matplotlib colour map name such as "
        f"{', '.join(SUGGESTED)}{hint}")


def random_palette(seed: int = 0) -> np.ndarray:
    """256 distinct opaque colours in random order (for tests that decode indices from pixels).

    The colours are the 8 × 8 × 4 grid of red, green and blue levels, shuffled by ``seed``: any
    two differ by at least 36 in some channel.

    Examples
    --------
    >>> p = random_palette(1)
    >>> p.shape, len(np.unique(p, axis=0)), bool((p[:, 3] == 255).all())
    ((256, 4), 256, True)
    """
    r, g, b = np.meshgrid(
        np.linspace(0, 255, 8), np.linspace(0, 255, 8), np.linspace(0, 255, 4), indexing="ij"
    )
    rgb = np.stack([r.ravel(), g.ravel(), b.ravel()], axis=1).round().astype(np.uint8)
    rgb = rgb[np.random.default_rng(seed).permutation(PALETTE_SIZE)]
    alpha = np.full((PALETTE_SIZE, 1), 255, np.uint8)
    return np.ascontiguousarray(np.concatenate([rgb, alpha], axis=1))
