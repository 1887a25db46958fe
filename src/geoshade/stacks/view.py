"""``StacksView``: a live ray-cast view of a stack model with the geologist's tools."""

from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.compute.stacks import LAYOUT_NAMES, gpu_intervals, synthetic_layers
from geoshade.models.stacks import EMPTY, StackModel
from geoshade.models.volume import VoxelVolume
from geoshade.render.view import Job, View, fmt_int
from geoshade.stacks.convert import convert
from geoshade.stacks.options import (
    StacksOptions,
    drape_on_model,
    index_section,
    model_box,
    section_box,
)
from geoshade.stacks.terrain import elevation_colours
from geoshade.styles.annotate import ColorBar, Legend, exaggeration_text
from geoshade.styles.options import Plane
from geoshade.styles.shading import shading_uniforms
from geoshade.styles.units import length_unit


def adaptive_kernel(shape) -> int:
    """The paper's adaptive normal kernel: k in 5..9 by the grid size (5 up to 256 columns a
    side, 7 up to 512, 9 beyond).

    >>> adaptive_kernel((200, 250)), adaptive_kernel((400, 500)), adaptive_kernel((800, 1000))
    (5, 7, 9)
    """
    n = max(shape)
    return 5 if n <= 256 else 7 if n <= 512 else 9


class StacksView(View[StacksOptions]):
    """A live view of one stack model: change layout, opacity, plane, boreholes, drape,
    exaggeration or camera and draw again; only what changed is redone (a new opacity
    re-uploads the palette alone, a new layout re-packs the stacks).

    ``model`` may also be anything :func:`geoshade.stacks.convert` takes (a labelled volume,
    an array, a file): it is converted first (options ``variable``, ``empty``, ``logs``).

    Options: see :class:`~geoshade.stacks.options.StacksOptions`.

    Examples
    --------
    >>> from geoshade.compute.stacks import synthetic_layers
    >>> with StacksView(synthetic_layers(16, 12, 20), layout="textures", size=(64, 48)) as v:
    ...     v.update(hide=[1])
    ...     img, stats = v.draw()
    >>> stats["hidden"], img.shape
    ([1], (48, 64, 4))
    """

    kind = "stacks"
    title = "geological stacks"
    Options = StacksOptions
    model_types = (StackModel,)
    has_exaggeration = True

    options: StacksOptions
    visual: Any
    drape: Any

    @classmethod
    def accepts(cls, model) -> bool:
        return isinstance(model, StackModel) or (
            isinstance(model, VoxelVolume) and bool((model.meta or {}).get("legend")))

    @classmethod
    def coerce(cls, model, options: dict, progress=None):
        if isinstance(model, StackModel):
            return model

        empty = options.get("empty")
        return convert(model, variable=options.get("variable"), empty=empty,
                       boreholes=options.get("logs", "auto"), progress=progress)

    @classmethod
    def demo(cls):

        m = synthetic_layers(64, 48, 40, max_intervals=8, seed=2, spacing=(25.0, 25.0, 1.0))
        bh = np.zeros(m.ncols, bool)
        bh[np.ravel_multi_index((np.arange(4, 48, 9)[:, None], np.arange(4, 64, 9)[None]),
                                (48, 64)).ravel()] = True
        m = dataclasses.replace(m, borehole=bh)
        return m, {"exaggeration": 10.0, "drape": demo_drape(m), "legend": True}

    # --- set-up ----------------------------------------------------------------------------------
    def _setup(self) -> None:


        self.gpu = gpu_intervals(self.model)
        # a terrain from one DEM: each column's material is its elevation band (palette 1..n)
        self.elevation = elevation_colours(self.model)
        if self.elevation is not None:
            g = self.gpu
            col = np.repeat(np.arange(g.count.size), g.count)
            band = self.elevation.band[col]
            self.gpu = replace(g, mat=np.where(g.mat > 0, 1 + np.maximum(band, 0),
                                               0).astype(g.mat.dtype))
        self.shading = shading_uniforms()
        self.visual = None
        self.upload_ms = 0.0
        self.drape = None
        self._make_visual()
        self._set_drape()

    @property
    def layout(self) -> str:
        return self.options.layout

    @property
    def walk(self) -> str:
        return self.options.walk

    @property
    def kernel(self) -> int:
        k = self.options.kernel
        return adaptive_kernel(self.model.shape) if k is None else int(k)

    @property
    def section(self):
        """The shader's index-space section (None: no plane)."""
        p = self.options.plane
        return None if p is None else index_section(self.model, p)

    @property
    def boreholes(self) -> bool:
        return self.options.boreholes

    def _make_visual(self) -> None:
        from geoshade.render.visuals.stacks.visual import StacksVisual

        if self.visual is not None:
            self.visual.release()
            self.visual = None
        t0 = time.perf_counter()
        self.visual = StacksVisual(self.ctx, self.gpu, self.palette(), layout=self.layout,
                                   walk=self.walk)
        if self.drape is not None:
            self.visual.set_drape(*self.drape)
        self.ctx.finish()
        self.upload_ms = (time.perf_counter() - t0) * 1000

    def opacity(self) -> np.ndarray:
        """(P,) opacity factor of each legend entry: the options' ``opacity``, 0 if hidden."""
        lg, o = self.model.legend, self.options
        op = np.ones(len(lg), float)
        for c, a in (o.opacity or {}).items():
            op[int(lg.index_of(np.array([c]))[0]) - 1] = a
        for c in o.hide:
            op[int(lg.index_of(np.array([c]))[0]) - 1] = 0.0
        return op

    def palette(self) -> np.ndarray:
        """``(P + 1, 4) uint8``: entry 0 empty, then the legend, alpha scaled by the opacity (a
        terrain coloured by elevation: its bands, with the terrain's opacity)."""
        ec = getattr(self, "elevation", None)
        if ec is not None:
            rgba = ec.levels.astype(float)
            rgba[:, 3] *= float(self.opacity()[0])
        else:
            rgba = self.model.legend.rgba.astype(float)
            rgba[:, 3] *= self.opacity()
        pal = np.zeros((len(rgba) + 1, 4), np.uint8)
        pal[1:] = np.clip(np.round(rgba), 0, 255).astype(np.uint8)
        return pal

    def _set_drape(self) -> None:
        """Upload the options' drape (a georeferenced GeoTIFF lands where its tags say; other
        images cover the whole grid)."""
        image = self.options.drape
        if image is None:
            self.drape = None
            self.visual.set_drape(None)
            return
        extent = None
        self.drape_covered = 1.0
        if isinstance(image, str | Path):
            from geoshade.io.layers.dem import is_georeferenced

            if is_georeferenced(image):


                with warnings.catch_warnings():  # the options' check warned already
                    warnings.simplefilter("ignore")
                    img, self.drape_covered = drape_on_model(image, self.model)
                self.drape = (img, None)
                self.visual.set_drape(*self.drape)
                return
            from geoshade.io.volumes.image import read_image

            image, extent = read_image(image)
        img = np.asarray(image)
        rect = None
        if extent is not None:
            (x0, y0, _), (dx, dy, _) = self.model.origin, self.model.spacing
            rect = ((extent[0] - x0) / dx, (extent[1] - y0) / dy,
                    (extent[2] - extent[0]) / dx, (extent[3] - extent[1]) / dy)
        self.drape = (img.astype(np.uint8), rect)
        self.visual.set_drape(*self.drape)

    def section_plane(self, axis: str, fraction: float, flip: bool = False) -> Plane:
        """The plane across ``axis`` at ``fraction`` of the model's box keeping the near side
        (the far side with ``flip``): the section control."""
        return Plane.across(section_box(self.model), axis, fraction, flip)

    def materials(self) -> list[tuple[int, str, tuple[int, ...]]]:
        """(code, name, rgba) of every material of the legend."""
        lg = self.model.legend
        return [(int(c), str(n), tuple(int(v) for v in rgba))
                for c, n, rgba in zip(lg.codes, lg.names, lg.rgba, strict=True)]

    # --- changes ---------------------------------------------------------------------------------
    def _apply_options(self, new: StacksOptions, changed: set[str]) -> list[Job]:
        self.options = new
        if {"layout", "walk"} & changed:
            self._make_visual()
        elif {"hide", "opacity"} & changed:
            self.visual.set_palette(self.palette())
        if "drape" in changed:
            self._set_drape()
        return []

    # --- geometry ------------------------------------------------------------------------------
    def zlo(self) -> float:
        return float(np.floor(self.model.occupied_levels()[0]))

    def model_matrix(self) -> np.ndarray:
        """4×4: index space (columns, levels) -> display world (vertical exaggeration)."""
        (dx, dy, dz), (x0, y0, z0) = self.model.spacing, self.model.origin
        f = self.options.exaggeration
        m = np.diag([dx, dy, dz * f, 1.0])
        m[:3, 3] = (x0, y0, z0 * f)
        return m

    def bounds(self) -> np.ndarray:
        """(2, 3) display-world bounds of the box (model only: independent of the settings)."""
        lo, hi = self.visual.box(self.zlo())
        m = self.model_matrix()
        return np.stack([m[:3, :3] @ lo + m[:3, 3], m[:3, :3] @ hi + m[:3, 3]])

    def params(self):
        from geoshade.render.visuals.stacks.visual import RayParams

        g, o = self.gpu, self.options
        col = np.repeat(np.arange(g.count.size), g.count)
        prev = np.zeros(g.n, np.float32)
        if g.n:
            prev[1:] = np.where(col[1:] == col[:-1], g.end[:-1], 0.0)
        thick = (g.end - prev)[g.mat > 0]
        mean = float(thick.mean()) if thick.size else 1.0
        ref = mean * self.model.spacing[2] * o.exaggeration
        return RayParams(section=self.section, boreholes_only=o.boreholes, ref_length=ref,
                         walk_from=o.walk_from, kernel=self.kernel, sigma=o.smooth,
                         lighting=o.lighting, drape_mix=o.drape_mix, brick_skip=o.brick_skip,
                         smooth_top=self.smooth_top, top_normals=o.top_normals)

    @property
    def smooth_top(self) -> bool:
        """The top is interpolated between column centres (``top``: ``smooth``, or ``auto``
        on a model made from DEMs)."""
        t = self.options.top
        return t == "smooth" or (t == "auto" and bool(self.model.meta.get("terrain")))

    # --- drawing ------------------------------------------------------------------------------
    def _frame(self, camera, target, count: bool) -> dict:
        self.visual.draw(camera, self.model_matrix(), self.params(), self.shading, target,
                         zlo=self.zlo())
        return {}

    def _finish_image(self, img: np.ndarray) -> np.ndarray:
        if self.options.transparent:
            a = img[..., 3:4].astype(float)
            img[..., :3] = np.where(a > 0, np.clip(img[..., :3] / np.maximum(a, 1) * 255, 0,
                                                   255), 0).astype(np.uint8)
        return img

    def method_name(self) -> str:
        return self.layout

    def _stats(self, counts: dict) -> dict:
        m, o = self.model, self.options
        return {
            "layout_name": LAYOUT_NAMES[self.layout], "walk": self.walk,
            "walk_from": o.walk_from,
            "layout_bytes": int(self.visual.layout_bytes),
            "layout_wasted_bytes": int(self.visual.plan["wasted"]),
            "columns": m.ncols, "intervals": m.nintervals, "max_intervals": m.max_intervals,
            "gpu_intervals": self.gpu.n, "gpu_max_intervals": self.gpu.max_count,
            "borehole_columns": int(m.borehole.sum()), "boreholes_only": o.boreholes,
            "hidden": [int(c) for c, a in zip(m.legend.codes, self.opacity(), strict=True)
                       if a == 0],
            "plane": None if o.plane is None else o.plane.text(),
            "section": None if self.section is None else list(self.section),
            "exaggeration": o.exaggeration, "kernel": self.kernel, "smooth": o.smooth,
            "drape": self.visual.drape_pixels() > 0,
            "drape_pixels": self.visual.drape_pixels(),
            "drape_covered": (None if self.drape is None
                              else round(float(getattr(self, "drape_covered", 1.0)), 6)),
            "top": "smooth" if self.visual.smooth_top else "flat",
            "brick_skip": o.brick_skip,
            "upload_ms": round(self.upload_ms, 3),
            **({"notes": list(m.meta["notes"])} if m.meta.get("notes") else {}),
        }

    def draw(self, camera=None, **kw):
        img, stats = super().draw(camera, **kw)
        stats["mrays_per_s"] = round(stats["width"] * stats["height"]
                                     / max(stats["frame_ms"], 1e-9) / 1000.0, 3)
        return img, stats

    # --- annotations -----------------------------------------------------------------------------
    def _title(self, stats: dict) -> tuple[str, str]:

        m = self.model
        name = Path(m.name).name if m.name else "stack model"
        var = str(m.meta.get("variable", "") or "")
        more = []
        if self.options.boreholes:
            more.append("borehole columns only")

        more.append(exaggeration_text(self.options.exaggeration))
        more += [str(n).split(": ", 1)[-1] for n in m.meta.get("notes") or ()]   # reprojected
        more = [m for m in more if m]
        return (f"{name} — {var}" if var else name), " · ".join(more)

    def _color_key(self, stats: dict):

        if not self.options.legend:
            return None
        ec = self.elevation
        if ec is not None and self.shown_codes():   # a terrain: its height colour bar
            return ColorBar("elevation", ec.lo, ec.hi, ec.colorbar_palette(),
                            unit=self._length_unit())
        lg = self.model.legend
        shown = self.shown_codes()
        idx = lg.index_of(np.asarray(shown, dtype=lg.codes.dtype)) - 1 if shown else []
        entries = tuple((f"{c} {lg.names[i]}".strip(), tuple(int(v) for v in lg.rgba[i]))
                        for c, i in zip(shown, idx, strict=True))
        return Legend(str(self.model.meta.get("variable", "") or ""), entries)

    def _length_unit(self) -> str:

        return length_unit(self.model.unit) or "m"

    def _empty_reason(self, stats: dict) -> str | None:
        m = self.model
        if self.options.boreholes and not m.borehole.any():
            return "nothing to draw: the model has no borehole column"
        if not self.shown_codes():
            return "nothing to draw: every material is hidden"
        return None

    def shown_codes(self) -> list[int]:
        """The material codes drawn now (present, not hidden, not fully transparent)."""
        m = self.model
        cols = m.column_ids()
        use = m.codes != EMPTY
        if self.options.boreholes:
            use &= m.borehole[cols]
        present = np.unique(m.codes[use])
        if present.size == 0:
            return []
        idx = m.legend.index_of(present) - 1
        alpha = self.opacity()[idx] * m.legend.rgba[idx, 3]
        return [int(c) for c in present[alpha > 0]]

    def readout(self, stats: dict) -> str:
        hidden = len(stats.get("hidden") or [])
        text = (f"{fmt_int(stats.get('columns'))} columns · "
                f"{fmt_int(stats.get('intervals'))} intervals · {hidden} hidden")
        cov = stats.get("drape_covered")
        if cov is not None:
            text += (f" · drape over {100 * cov:.0f} % of the model"
                     + ("" if stats.get("drape") else ", not visible"))
        return text

    def summary(self, stats: dict) -> str:
        return (f"{stats['width']}x{stats['height']} {stats['method']} "
                f"({stats['walk']} walk), {stats['columns']} columns, {stats['intervals']} "
                f"intervals (max {stats['max_intervals']}), {stats['frame_ms']:.1f} ms/frame, "
                f"{stats['mrays_per_s']:.2f} Mrays/s, {stats['gpu_bytes'] / 2**20:.2f} MiB on "
                f"the GPU (layout {stats['layout_bytes'] / 2**20:.3f} MiB)")


def demo_drape(model: StackModel, size: int = 256) -> np.ndarray:
    """A synthetic 'orthophoto' (h, w, 4) uint8 for the demo: fields and a river."""
    y, x = np.mgrid[0:size, 0:size] / size
    fields = ((np.floor(x * 8) + np.floor(y * 6)) % 3)[..., None] * np.array([20, 35, 10])
    base = np.array([120, 150, 80]) + fields
    river = np.abs(y - 0.5 - 0.15 * np.sin(x * 9)) < 0.025
    rgb = np.where(river[..., None], np.array([70, 110, 200]), base)
    return np.concatenate([rgb, np.full((size, size, 1), 255)], axis=2).astype(np.uint8)


__all__ = ["StacksView", "adaptive_kernel", "demo_drape", "model_box"]
