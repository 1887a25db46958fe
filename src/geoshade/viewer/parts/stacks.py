"""Stacks part adapter: materials (visibility, opacity, legend), section plane, borehole mode,
drape, vertical exaggeration (forwarded to :class:`geoshade.stacks.StacksView`)."""

from __future__ import annotations

import dataclasses

import numpy as np

from geoshade.errors import InputError
from geoshade.models.stacks import StackModel
from geoshade.models.volume import VoxelVolume
from geoshade.viewer.parts.base import Job, Part, auto_exaggeration, fmt_int, unknown_settings

_SETTINGS = ("hidden", "opacity", "section", "boreholes", "drape", "legend", "exaggeration")


def section_plane(model: StackModel, axis: str, fraction: float, flip: bool = False):
    """World plane ``(nx, ny, nz, d)`` across ``axis`` at ``fraction`` of the occupied box;
    the side ``n·p > d`` is cut away (the far side unless ``flip``).

    >>> from geoshade.compute.stacks import synthetic_layers
    >>> section_plane(synthetic_layers(10, 8, 12), "x", 0.5)
    (1.0, 0.0, 0.0, 5.0)
    """
    if axis not in ("x", "y", "z"):
        raise InputError(f"section: expected axis x, y or z, got {axis!r}")
    k = "xyz".index(axis)
    b = model.bounds()
    lo, hi = float(b[0, k]), float(b[1, k])
    if axis == "z":  # the levels that hold material, so the plane always crosses it
        zl, zh = model.occupied_levels()
        lo, hi = (model.origin[2] + zl * model.spacing[2], model.origin[2] + zh * model.spacing[2])
    f = float(np.clip(fraction, 0.01, 0.99))
    n = np.zeros(3)
    n[k] = -1.0 if flip else 1.0
    d = n[k] * (lo + f * (hi - lo))
    return (float(n[0]), float(n[1]), float(n[2]), float(d))


def demo_drape(model: StackModel, size: int = 256) -> np.ndarray:
    """A synthetic 'orthophoto' (h, w, 4) uint8 for the demo: fields and a river."""
    y, x = np.mgrid[0:size, 0:size] / size
    fields = ((np.floor(x * 8) + np.floor(y * 6)) % 3)[..., None] * np.array([20, 35, 10])
    base = np.array([120, 150, 80]) + fields
    river = np.abs(y - 0.5 - 0.15 * np.sin(x * 9)) < 0.025
    rgb = np.where(river[..., None], np.array([70, 110, 200]), base)
    return np.concatenate([rgb, np.full((size, size, 1), 255)], axis=2).astype(np.uint8)


class StacksPart(Part):
    """The stack-model view.

    Settings: ``hidden`` (material codes not drawn), ``opacity`` ({code: 0..1}),
    ``section`` (None or ``(axis, fraction, flip)`` or a world plane ``(nx, ny, nz, d)``),
    ``boreholes`` (bool), ``drape`` (bool: the drape image on or off), ``legend`` (bool).
    """

    kind = "stacks"
    title = "geological stacks"
    exaggeration = True

    def __init__(self, model, size=(800, 600), hidden=(), opacity=None, section=None,
                 boreholes: bool = False, drape=None, legend: bool = True,
                 exaggeration: float | None = None, drape_image=None, ctx=None):
        from geoshade.stacks import StacksView, convert

        model = convert(model) if not isinstance(model, StackModel) else model
        self.model = model
        if exaggeration is None:  # thin layers over a wide area: a round factor that shows them
            zl, zh = model.occupied_levels()
            b = model.bounds()
            b[:, 2] = model.origin[2] + np.array([zl, zh]) * model.spacing[2]
            exaggeration = auto_exaggeration(b)
        self.view = StacksView(model, size=size, exaggeration=exaggeration, ctx=ctx)
        self.drape_image = drape_image
        self.legend = bool(legend)
        self.hidden: list[int] = []
        self.opacity: dict[int, float] = {}
        self.section_spec = None
        self.drape_on = False
        self.apply(hidden=hidden, opacity=opacity or {}, section=section, boreholes=boreholes,
                   drape=bool(drape) if drape is not None else drape_image is not None)

    @classmethod
    def accepts(cls, model) -> bool:
        return isinstance(model, StackModel) or (
            isinstance(model, VoxelVolume) and bool((model.meta or {}).get("legend")))

    @classmethod
    def precompute(cls, model, settings: dict, progress=None) -> dict:
        """CPU half of opening (any thread): a labelled volume becomes stacks."""
        from geoshade.stacks import convert

        return {} if isinstance(model, StackModel) else {"model": convert(model,
                                                                         progress=progress)}

    @classmethod
    def demo(cls):
        from geoshade.compute.stacks import synthetic_layers

        m = synthetic_layers(64, 48, 40, max_intervals=8, seed=2, spacing=(25.0, 25.0, 1.0))
        bh = np.zeros(m.ncols, bool)
        bh[np.ravel_multi_index((np.arange(4, 48, 9)[:, None], np.arange(4, 64, 9)[None]),
                                (48, 64)).ravel()] = True
        m = dataclasses.replace(m, borehole=bh)
        return m, {"exaggeration": 10.0, "drape_image": demo_drape(m)}

    def materials(self) -> list[tuple[int, str, tuple[int, int, int, int]]]:
        """(code, name, rgba) of every material of the legend."""
        lg = self.model.legend
        return [(int(c), str(n), tuple(int(v) for v in rgba))
                for c, n, rgba in zip(lg.codes, lg.names, lg.rgba, strict=True)]

    def _plane(self, spec):
        if spec is None:
            return None
        if len(spec) == 3 and isinstance(spec[0], str):
            return section_plane(self.model, *spec)
        return tuple(float(v) for v in spec)

    def _draw(self, camera, count: bool):
        return self.view.draw(camera, frames=1, legend=self.legend)

    def settings(self) -> dict:
        return {"hidden": list(self.hidden), "opacity": dict(self.opacity),
                "section": self.section_spec, "boreholes": self.view.boreholes,
                "drape": self.drape_on, "legend": self.legend}

    def apply(self, **settings) -> list[Job]:
        extra = set(settings) - set(_SETTINGS)
        if extra:
            raise unknown_settings(self, extra)
        v = self.view
        if "hidden" in settings or "opacity" in settings:
            hidden = [int(c) for c in settings.get("hidden", self.hidden)]
            opacity = {int(k): float(a) for k, a in settings.get("opacity", self.opacity).items()}
            v.set_opacity(opacity, hide=hidden)
            self.hidden, self.opacity = hidden, opacity
        if "section" in settings:
            v.set_section(self._plane(settings["section"]))
            self.section_spec = settings["section"]
        if "boreholes" in settings:
            v.set_boreholes(bool(settings["boreholes"]))
        if "drape" in settings:
            on = bool(settings["drape"])
            if on and self.drape_image is None:
                raise InputError("drape: no drape image; give one (drape_image=PATH or array, "
                                 "geoshade view --drape IMAGE)")
            v.set_drape(self.drape_image if on else None)
            self.drape_on = on
        if "legend" in settings:
            self.legend = bool(settings["legend"])
        if "exaggeration" in settings:
            self.set_exaggeration(settings["exaggeration"])
        return []

    def readout(self, stats: dict) -> str:
        hidden = len(stats.get("hidden") or [])
        return (f"{stats.get('method')} · {fmt_int(stats.get('columns'))} columns · "
                f"{fmt_int(stats.get('intervals'))} intervals · {hidden} hidden · "
                f"{stats.get('mrays_per_s', 0):.1f} Mrays/s")
