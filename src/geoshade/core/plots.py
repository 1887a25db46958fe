"""Porosity plot as a PNG, drawn with matplotlib's Agg canvas (no pyplot, no GUI backend).

Using ``matplotlib.figure.Figure`` with ``FigureCanvasAgg`` directly never switches the global
backend, so interactive users (Jupyter, IPython with a GUI backend) are not affected.
"""

from __future__ import annotations

import io
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from geoshade.errors import InputError
from geoshade.io.output import atomic_write_bytes

_UNIT_LABEL = {"um": "µm", "micron": "µm", "micrometer": "µm"}


def axis_label(result) -> tuple[str, np.ndarray]:
    """The profile axis' label and the slice positions it runs over: world units where the
    spacing is known (``z (µm)``; ``z (spacing units)`` without a unit), else voxel indices.

    >>> import numpy as np
    >>> from geoshade.compute.voxels.porosity import porosity
    >>> from geoshade.models import VoxelVolume
    >>> r = porosity(VoxelVolume(np.zeros((2, 1, 1), np.uint8), (5, 5, 5), unit="um"), 0, 0)
    >>> axis_label(r)
    ('z (µm)', array([2.5, 7.5]))
    """
    unit = getattr(result, "unit", "") or ""
    spacing = getattr(result, "spacing", None)
    if spacing is None or not hasattr(result, "coordinates"):
        return f"{result.axis} (voxels)", np.asarray(result.positions, np.float64)
    name = _UNIT_LABEL.get(unit, unit) if unit else "spacing units"
    return f"{result.axis} ({name})", result.coordinates()


def porosity_plot(result, path, title: str | None = None, dpi: int = 100) -> Path:
    """Draw the porosity profile and the total porosity into a PNG file (written atomically).

    Parameters
    ----------
    result : geoshade.compute.voxels.porosity.PorosityResult
        What :func:`geoshade.compute.voxels.porosity.porosity` returned.
    path : str or Path
        The PNG to write; its folder must exist.
    title : str, optional
        Figure title (default: the range and the box).
    dpi : int
        Resolution (the figure is 6.4 × 4 inches).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import numpy as np
    >>> from geoshade.compute.voxels.porosity import porosity
    >>> r = porosity(np.random.default_rng(0).integers(0, 2, (20, 8, 8), np.uint8), 0, 0)
    >>> p = porosity_plot(r, pathlib.Path(tempfile.mkdtemp()) / "poro.png")
    >>> p.read_bytes()[:4] == b"\\x89PNG"
    True
    """
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{path}: folder {parent} does not exist")
    profile = np.asarray(result.profile, dtype=np.float64)
    x_label, coords = axis_label(result)
    what = getattr(result, "quantity", "porosity")

    fig = Figure(figsize=(6.4, 4.0), dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(coords, profile, color="tab:blue", lw=1.5, label=f"{what} per {result.axis} slice")
    ax.axhline(
        result.porosity,
        color="tab:red",
        ls="--",
        lw=1.2,
        label=f"total {what} {result.porosity:.4f}",
    )
    ax.set_xlabel(x_label)
    ax.set_ylabel(f"{what} (fraction)")
    top = float(max(np.nanmax(profile, initial=0.0), result.porosity))
    ax.set_ylim(0.0, max(0.05, min(1.0, top * 1.15)))
    if len(coords) > 1:
        ax.set_xlim(float(np.min(coords)), float(np.max(coords)))
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    if title is None:
        lo, hi = getattr(result, "range", (None, None))
        box = getattr(result, "box", None)
        title = f"{what}, values [{lo:g}, {hi:g}]" if lo is not None else what
        if box:
            title += f", box {box[3]}×{box[4]}×{box[5]} at ({box[0]}, {box[1]}, {box[2]})"
    notes = list(result.notes()) if hasattr(result, "notes") else []
    if notes:  # what decides the number: the selection's side, the sample, the air warning
        title = "\n".join([title, *(textwrap.fill(n, 90) for n in notes)])
    ax.set_title(title, fontsize="medium" if not notes else "small")
    fig.tight_layout()

    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return atomic_write_bytes(path, buf.getvalue())
