"""Options of the isosurface View (checked before any GL context exists)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from geoshade.compute.mesh import marching_cubes as mc
from geoshade.errors import InputError
from geoshade.io.fields import load_field
from geoshade.iso.diff import check_diff_field
from geoshade.models.field import FieldSeries
from geoshade.models.names import resolve_name
from geoshade.models.steps import resolve_step
from geoshade.styles.declare import option
from geoshade.styles.options import check_number, checks
from geoshade.styles.shared_options import STEP, ColorOptions, ExaggerationOptions, SummaryOptions

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


def field_dates(field: FieldSeries) -> list[str]:
    """The steps' dates ("" where a step has only its ``"step k"`` label), so a date asked of
    a field without dates says so instead of listing labels as dates.

    >>> field_dates(FieldSeries(np.zeros((2, 2, 2, 2)))), field_dates(
    ...     FieldSeries(np.zeros((1, 2, 2, 2)), times=["2000-01-01"]))
    (['', ''], ['2000-01-01'])
    """
    return ["" if str(t).startswith("step ") else str(t) for t in field.times]


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
class IsoOptions(ExaggerationOptions, ColorOptions, SummaryOptions):
    """Options of :class:`~geoshade.iso.IsoView`.

    level:    ``S*``; a node is below the level when ``S < S*`` (default: the middle of the
              initial step's finite values)
    step:     index, -1 (last, the default), ``"R36"`` or a date, as in every part
    diff:     a step (as ``step``): draw the change ``FIELD(step) − FIELD(diff)`` (see
              :mod:`geoshade.iso.diff`); None (the default): the field itself
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

    level: Any = option(
        None, type=float, metavar="S", group="shown", control="number", example=0.4,
        help="the isosurface value S* (a node is below it when S < S*; default: the middle of "
             "the initial step's values)")   # a float once the View is set up
    step: Any = option(None, **STEP)
    diff: Any = option(
        None, group="shown", metavar="STEP", control="steps", example=0,
        help="draw the isosurface of the change since step STEP (an index, R36 or a date, as "
             "--step): FIELD at --step minus FIELD at STEP on the active cells (e.g. ΔSWAT = "
             "0.2 with --level 0.2; without --level half the largest change, said); a "
             "colour-by quantity that changes is drawn as its change, on a diverging colour "
             "map centred on 0; the title names both steps")
    keyword: str | None = option(
        None, flag=None, group="shown", control="keyword",
        help="the quantity of a corner-point grid to show (default SWAT), when a grid is given")
    color_by: str | None = option(
        None, metavar="NAME", group="colour", control="color_by",
        help="colour the surface by another quantity of the file (e.g. PRESSURE)")
    patch_level: int = option(
        DEFAULT_PATCH_LEVEL, type=int, metavar="L", group="method", example=4, limits=(1, 64),
        help="patch-quads of (L+1)² cells, 1..64 (default 8; the paper: 64)")
    skip_patches: bool = option(
        True, form="switch", group="method", aliases=(("--no-skip", False),), control="",
        example=False,
        help="march only the patches whose min/max can hold the level (--no-skip: every patch)")
    slice_axis: str = option(
        "auto", choices=("auto", *mc.SLICE_AXES), group="method", example="z",
        help="axis the slices of patch-quads are stacked along (auto: the one leaving the "
             "fewest cells to march; the paper: z)")
    prefetch: bool = option(True, form="switch", group="method", control="",
                            help="prepare the next step in a background thread")
    mesh_cache: bool = option(
        True, form="switch", group="method", control="", example=False,
        help="re-draw the surface captured when it was last marched (--no-mesh-cache: march "
             "every frame, the paper)")
    caps: bool = option(
        False, form="switch", group="shown", example=True,
        help="close the surface along inactive (ACTNUM 0), NaN and infinite cells, halfway to "
             "them (default: open there, as at the grid's boundary)")

    PART: ClassVar[str] = "iso"
    DEPRECATED: ClassVar[dict] = {"z_scale": ("exaggeration", None),
                                  "base_color": ("solid_color", None)}
    PRESETS: ClassVar[dict] = {"paper": (
        "the paper's method exactly: --patch-level 64 --no-skip --slice-axis z --no-mesh-cache",
        {"patch_level": PAPER_PATCH_LEVEL, "skip_patches": False, "slice_axis": "z",
         "mesh_cache": False})}

    @staticmethod
    @checks("level")
    def check_level(value, model=None):
        return None if value is None else check_level(value)

    @staticmethod
    @checks("step")
    def check_step(value, model):
        if model is None:
            return value
        return resolve_step(value, model.nsteps, dates=field_dates(model),
                            reports=field_reports(model), where=model.source or model.name,
                            default=(model.meta or {}).get("default_step", -1))

    @staticmethod
    @checks("diff")
    def check_diff(value, model):
        """The step a change is taken from, resolved as ``step`` is (by date where a date is
        given, never by position); a static keyword or a field of one step refuses it."""
        if value is None or model is None:
            return value
        check_diff_field(model)
        return resolve_step(value, model.nsteps, dates=field_dates(model),
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
        # a quantity of the field's file not read yet is read by the View when it is chosen
        known = {**dict.fromkeys((model.meta or {}).get("quantities") or ()), **model.properties}
        return resolve_name(value, known, "color_by", model.source or model.name)

    @staticmethod
    @checks("patch_level")
    def check_patch_level(value, model=None):
        return check_number(value, "patch_level", 1, 64, integer=True)


__all__ = ["DEFAULT_KEYWORD", "DEFAULT_PATCH_LEVEL", "METHOD", "PAPER_PATCH_LEVEL", "IsoOptions",
           "check_level", "field_dates", "with_color_by"]
