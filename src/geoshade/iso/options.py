"""Options of the isosurface View (checked before any GL context exists)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from geoshade.compute import marching_cubes as mc
from geoshade.errors import InputError
from geoshade.models.field import FieldSeries
from geoshade.models.names import resolve_name
from geoshade.models.steps import resolve_step
from geoshade.styles.options import (
    ColorStyle,
    ViewOptions,
    check_choice,
    check_exaggeration,
    check_number,
    checks,
)

#: the one GPU method (the paper's tessellation marching cubes)
METHOD = "tessellation"
#: patch level L (patches of (L+1)² cells). The paper's 64 is the most a GPU allows; with patch
#: skipping on, smaller patches skip more cells that cannot hold the level. On llvmpipe, 256³
#: displacement fields at 3840×2160 drew fastest with 8 (4: more patches to process; 16: more
#: cells marched); see benchmarks/RESULTS.md, iso section, and docs/NOTES.md
DEFAULT_PATCH_LEVEL = 8
PAPER_PATCH_LEVEL = 64
#: the restart keyword a corner-point grid is shown by when none is given
DEFAULT_KEYWORD = "SWAT"


def check_level(level) -> float:
    """``level`` as a finite float, else one clear error.

    >>> check_level("0.5")
    0.5
    """
    try:
        s = float(level)
    except (TypeError, ValueError):
        raise InputError(f"level: expected a number, got {level!r}") from None
    if not np.isfinite(s):
        raise InputError(f"level: expected a finite number, got {level!r}")
    return s


def field_reports(field: FieldSeries) -> list:
    return list((field.meta or {}).get("reports") or ())


def with_color_by(field: FieldSeries, color_by) -> FieldSeries:
    """``field`` with the quantity ``color_by`` among its properties: read from the file the
    field came from (the same reader, steps and keyword) when the field was loaded without it,
    so ``geoshade.view(load(case, as_="field"), color_by="PRESSURE")`` and the viewer colour
    as ``iso render --color-by PRESSURE`` does. Names already present (any case), a field
    without a file, or no ``color_by``: the field as it is (the options then say what is
    missing).

    >>> import numpy as np, tempfile, os
    >>> from geoshade.io.fields import load_field
    >>> f = os.path.join(tempfile.mkdtemp(), "s.npz")
    >>> np.savez(f, SWAT=np.zeros((2, 3, 4, 5), np.float32), PRESSURE=np.ones((2, 3, 4, 5)))
    >>> sorted(with_color_by(load_field(f, keyword="SWAT"), "PRESSURE").properties)
    ['PRESSURE']
    """

    from geoshade.io.fields import load_field
    if not color_by or not field.source or str(color_by).upper() in {
            str(n).upper() for n in field.properties}:
        return field
    if not Path(str(field.source)).exists():
        return field
    meta = field.meta or {}
    try:
        more = load_field(field.source, keyword=meta.get("keyword") or field.name or None,
                          step=meta.get("step"), color_by=color_by)
    except InputError:
        return field  # not in the file: IsoOptions.check_color_by names what there is
    if more.nsteps != field.nsteps or tuple(more.shape) != tuple(field.shape):
        return field
    return dataclasses.replace(field, properties={**field.properties, **more.properties})


@dataclass(frozen=True)
class IsoOptions(ViewOptions):
    """Options of :class:`~geoshade.iso.IsoView`.

    level:    ``S*``; a node is below the level when ``S < S*`` (default: the middle of the
              initial step's finite values)
    step:     index, -1 (last, the default), ``"R36"`` or a date, as in every part
    keyword:  the quantity of a corner-point grid to show (default SWAT), when a grid is given
    color_by: a ``field.properties`` name (any case) to colour the surface by
    color:    :class:`ColorStyle`; ``range`` of ``color_by`` (default: its range at the initial
              step, then kept so colours compare across steps), ``solid`` the surface colour
              when not colouring (the old ``base_color``)
    patch_level, skip_patches, slice_axis: the patch-quads (``64, False, "z"`` is the paper)
    prefetch: prepare the next step in a background thread
    exaggeration: vertical exaggeration (the old name ``z_scale`` still works)
    mesh_cache: re-draw the triangles captured when the surface was last marched (default);
              False marches every frame (the paper)
    caps:     close the surface along inactive, NaN and infinite nodes (vertices halfway to
              them); default False: a cell with such a corner makes no triangles and the
              surface stays open there, as at the grid's outer boundary
    """

    level: Any = None  # a float once the View is set up
    step: Any = None
    keyword: str | None = None
    color_by: str | None = None
    color: ColorStyle = field(default_factory=ColorStyle)
    patch_level: int = DEFAULT_PATCH_LEVEL
    skip_patches: bool = True
    slice_axis: str = "auto"
    prefetch: bool = True
    exaggeration: float = 1.0
    mesh_cache: bool = True
    caps: bool = False

    PART: ClassVar[str] = "iso"
    CHOICES: ClassVar[dict[str, tuple]] = {**ViewOptions.CHOICES,
                                           "slice_axis": ("auto", *mc.SLICE_AXES)}
    FLAGS: ClassVar[tuple[str, ...]] = (*ViewOptions.FLAGS, "skip_patches", "prefetch",
                                        "mesh_cache", "caps")
    DEPRECATED: ClassVar[dict] = {"z_scale": ("exaggeration", None),
                                  "base_color": ("solid_color", None)}

    @staticmethod
    @checks("level")
    def check_level(value, model=None):
        return None if value is None else check_level(value)

    @staticmethod
    @checks("step")
    def check_step(value, model):
        if model is None:
            return value
        return resolve_step(value, model.nsteps, dates=model.times,
                            reports=field_reports(model), where=model.source or model.name)

    @staticmethod
    @checks("keyword")
    def check_keyword(value, model=None):
        return None if value is None else str(value)

    @staticmethod
    @checks("color_by")
    def check_color_by(value, model):
        if value is None or value == "":
            return None
        if model is None:
            return str(value)
        return resolve_name(value, model.properties, "color_by", model.source or model.name)

    @staticmethod
    @checks("patch_level")
    def check_patch_level(value, model=None):
        return check_number(value, "patch_level", 1, 64, integer=True)

    @staticmethod
    @checks("slice_axis")
    def check_slice_axis(value, model=None):
        return check_choice(value, IsoOptions.CHOICES["slice_axis"], "slice_axis")

    @staticmethod
    @checks("exaggeration")
    def check_exaggeration(value, model=None):
        return check_exaggeration(value)


__all__ = ["DEFAULT_KEYWORD", "DEFAULT_PATCH_LEVEL", "METHOD", "PAPER_PATCH_LEVEL", "IsoOptions",
           "check_level", "with_color_by"]
