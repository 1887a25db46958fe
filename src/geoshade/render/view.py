"""The View shape every part extends: options before GL, framing, draw, stats, release.

::

    geoshade.load(path) ─▶ model ─▶ geoshade.view(model, **options) ─▶ View ─▶ draw()
                                                                              ─▶ (rgba, stats)

A :class:`View` owns what is the same in every part:

- its options, one frozen :class:`~geoshade.styles.options.ViewOptions` subclass per part,
  parsed and checked in ``__init__`` *before* the GL context is asked for, so bad options give
  the same one-line error on a machine without OpenGL;
- the camera framing, from the model's bounds only (:meth:`Camera.framed`, the tight fit), so
  two pictures that differ in selection, filter, step or colour are pixel-aligned;
- the offscreen target, the timing of frames, the optional counting pass, the base stats
  (``width height method frame_ms first_frame_ms gpu_bytes renderer`` + the part's counts),
  the one :class:`~geoshade.errors.EmptySceneWarning`;
- changes: :meth:`update` (now) and :meth:`jobs` (long work split into a CPU half that runs on
  any thread and a GL half, for viewers that keep their window alive);
- :meth:`release` and ``with`` (after release ``gpu_bytes`` is 0).

A part adds only what is its own: ``_setup`` (visuals), ``_frame`` (one frame), ``_stats``
(its counts), ``_empty_reason``, ``bounds``, ``_apply_options`` (what a change redoes) and
``_gpu_objects``. No module-level moderngl import here: options are checked without GL.
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar, Generic, TypeVar

import numpy as np

from geoshade.errors import EmptySceneWarning, InputError, where
from geoshade.render.camera import Camera
from geoshade.render.pick import pick_view
from geoshade.render.state import view_state
from geoshade.scheduler import SchedulerSession
from geoshade.styles.annotate import (
    Annotations,
    ColorBar,
    Legend,
    ScaleBar,
    annotate,
    font_px,
    triad_axes,
    warm_up,
)
from geoshade.styles.options import SHORTHAND_FIELD, CameraSpec, ViewOptions

#: ``progress(done, total)``, as io and compute take it
Progress = Callable[[int, int], Any]
#: the options class of a part's View
OptionsT = TypeVar("OptionsT", bound=ViewOptions)
#: the smallest picture (w, h) that carries annotations: below it they would cover the model
MIN_ANNOTATED = (200, 150)


@dataclass
class Job:
    """Long work split in two: ``compute`` (CPU only, any thread) and ``apply`` (GL thread).

    key:     jobs with the same key supersede each other (only the newest is applied)
    label:   what a progress bar says
    compute: ``compute(progress) -> result``; never touches OpenGL
    apply:   ``apply(result)``; runs on the thread that owns the GL context
    """

    key: str
    label: str
    compute: Callable[[Progress | None], Any]
    apply: Callable[[Any], None]
    #: the option values this job makes current when applied (pending until then)
    applies: dict = dataclasses.field(default_factory=dict)

    def run(self, progress: Progress | None = None) -> None:
        """Both halves on this thread (scripts, notebooks, ``--screenshot``)."""
        self.apply(self.compute(progress))


class View(Generic[OptionsT]):
    """Base class of the parts' Views (see the module's description).

    Parameters
    ----------
    model
        What the part shows (``model_types``; :meth:`coerce` may convert, e.g. labelled voxels
        to stacks).
    ctx : moderngl.Context, optional
        Default: the process-wide headless context.
    progress : callable(done, total), optional
        Called during long CPU work (selection maps, faces, conversion).
    options : ViewOptions, optional
        Options to start from; keyword arguments change them.
    prepared : dict, optional
        CPU results of :meth:`prepare_open` for these options (computed on another thread).
    **kw
        The part's options by name (see its ``Options``), plus the camera shorthands
        ``view azimuth elevation zoom ortho``.
    """

    #: the part's name (``core grid iso stacks``) and a title for viewers
    kind: ClassVar[str] = ""
    title: ClassVar[str] = ""
    #: the part's options class
    Options: ClassVar[type[Any]] = ViewOptions
    #: the model classes this View shows
    model_types: ClassVar[tuple[type, ...]] = ()
    #: the part has a vertical exaggeration option
    has_exaggeration: ClassVar[bool] = False
    #: the counted draw costs what a plain one does: one frame is timed and counted at once
    count_in_frame: ClassVar[bool] = False

    options: OptionsT
    #: the offscreen target of the last draw (made again when the size changes)
    target: Any
    def __init__(self, model, *, ctx=None, progress: Progress | None = None,
                 options: OptionsT | None = None, prepared: dict | None = None, **kw):
        model = self.coerce(model, kw, progress)
        opts = self.Options.parse(model, base=options, **kw)  # every cheap check, before GL
        if getattr(opts, "annotations", False):   # their imports, while the data opens
            warm_up()
        opts = opts.resolve(model, progress)  # the data work (e.g. Otsu), once
        self.model = model
        self.options = opts
        self.progress = progress
        self.prepared = dict(prepared or {})
        self.target = None
        #: (camera, size, counted) of the last draw: what :meth:`pick` looks through (counted:
        #: the picture is the counting frame, which a part may draw differently, e.g. unculled)
        self._last_frame: tuple[Camera, tuple[int, int], bool] | None = None
        self._released = False
        self._pending: dict = {}
        self._annotation_cache: dict = {}
        self._ambient: Any = None
        if ctx is None:
            from geoshade.render.context import get_context

            ctx = get_context()
        self.ctx = ctx
        #: where this View's dask work runs: one cluster for the View's life (started or
        #: connected on first use, closed by :meth:`release`)
        self.work = SchedulerSession(getattr(opts, "scheduler", None))
        try:
            self._setup()
        except BaseException:
            self.work.close()   # a cluster started here does not outlive a failed View
            raise

    # --- the model ---------------------------------------------------------------------------
    @classmethod
    def accepts(cls, model) -> bool:
        """True when this View can show ``model`` (possibly after :meth:`coerce`)."""
        return isinstance(model, cls.model_types)

    @classmethod
    def coerce(cls, model, options: dict, progress: Progress | None = None):
        """``model`` as this View needs it (CPU only); refuses what it cannot show."""
        if not isinstance(model, cls.model_types):
            want = " or ".join(t.__name__ for t in cls.model_types)
            raise InputError(f"{where(getattr(model, 'name', ''))}{cls.kind or 'view'}: expected "
                             f"a {want}, got {type(model).__name__}")
        return model

    @classmethod
    def prepare_open(cls, model, progress: Progress | None = None, options=None,
                     **kw) -> tuple[Any, dict]:
        """CPU work of opening ``model`` with ``options`` (the part's options object, resolved,
        or the options by name in ``kw``), on any thread: ``(model, prepared)`` to pass to the
        constructor (``cls(model, prepared=prepared, options=options)``), which then only
        uploads. Parts override it where opening is long (selection maps, conversion)."""
        return cls.coerce(model, kw, progress), {}

    @classmethod
    def opening_options(cls, model, progress: Progress | None = None, options=None, **kw):
        """The options :meth:`prepare_open` works with: ``options`` as given (already resolved
        once), else parsed from ``kw`` and resolved."""
        if options is not None:
            return options
        return cls.Options.parse(model, **kw).resolve(model, progress)

    @classmethod
    def demo(cls) -> tuple[Any, dict]:
        """A small synthetic model of this part and options to open it with."""
        raise NotImplementedError

    # --- framing ---------------------------------------------------------------------------------
    def bounds(self) -> np.ndarray:
        """(2, 3) world bounds the camera frames: the model's only (exaggeration applied)."""
        raise NotImplementedError

    def frame_points(self) -> np.ndarray | None:
        """(n, 3) world points that must fit in the picture (default: the bounds' corners)."""
        return None

    def camera(self, view=None, azimuth=None, elevation=None, zoom=None, ortho=None) -> Camera:
        """The camera framed on :meth:`bounds` from ``view`` (a name or a
        :class:`CameraSpec`; default the options' camera), independent of everything but the
        model and the exaggeration."""
        spec = CameraSpec.parse(self.options.camera if view is None else view, azimuth=azimuth,
                                elevation=elevation, zoom=zoom, ortho=ortho)
        w, h = self.size
        return Camera.framed(self.bounds(), spec, aspect=w / h, points=self.frame_points(),
                             viewport=self.viewport())

    def viewport(self) -> tuple | None:
        """The part of the picture the model is framed into (NDC): with annotations, the room
        of the title (top) and of the colour bar or legend (right) is kept free; the same for
        every colouring, so changing it never moves the framing."""
        if not (self.options.annotations and self._annotations_fit(self.size)):
            return None

        w, h = self.size
        f = font_px(h)
        top = (2.9 * 1.35 * f + 0.8 * f) / h       # two title lines and the margin
        right = (0.022 * w + 7.5 * f) / w           # bar and tick labels (or a legend column)
        return (-0.97, -0.97, 1.0 - 2.0 * right, 1.0 - 2.0 * top)

    def _camera_for(self, camera) -> Camera:
        if isinstance(camera, Camera):
            return camera
        return self.camera(camera)

    # --- options ---------------------------------------------------------------------------------
    @property
    def size(self) -> tuple[int, int]:
        return self.options.size

    @size.setter
    def size(self, value) -> None:
        self.options = self.options.replace(self.model, size=value)

    def resize(self, width: int, height: int) -> None:
        """Picture size in pixels; the target is made again on the next draw."""
        self.size = (max(1, int(width)), max(1, int(height)))

    @property
    def exaggeration(self) -> float | None:
        """The vertical exaggeration, None where the part has none."""
        return float(getattr(self.options, "exaggeration", 1.0)) if self.has_exaggeration \
            else None

    def set_exaggeration(self, factor: float) -> None:
        if not self.has_exaggeration:
            raise InputError(f"exaggeration: the {self.kind} view has no vertical exaggeration")
        self.update(exaggeration=factor)

    def state(self, camera=None) -> dict:
        """What reopens this picture, as plain JSON values by the names ``geoshade.view``
        takes: every option not at its default and the camera (``camera``: the one the
        picture is drawn with, e.g. a viewer's turned camera). ``geoshade.view(model,
        **view.state(cam))`` draws what ``view.draw(cam)`` draws (:mod:`geoshade.render.
        state`)."""
        return view_state(self, camera)

    def settings(self) -> dict:
        """The current options as plain values, by the names :meth:`update` takes."""
        skip = {"size", "camera", "transparent", "background"}
        return {k: v for k, v in self.options.as_dict().items() if k not in skip}

    def jobs(self, **changes) -> list[Job]:
        """Check ``changes`` (all of them, before any work), apply the quick ones now and
        return the long ones as :class:`Job` s (CPU half + GL half) still to run."""
        if not changes:
            return []
        self._refuse_fixed(changes)
        new = self.options.replace(self.model, **changes)  # all checked before any work
        # changes of jobs not yet applied are carried into the new ones (which supersede them)
        given = {self._renamed(n) for n in changes}
        carry = {k: v for k, v in self._pending.items() if k not in given}
        if carry:
            new = new.replace(self.model, **carry)
        # the camera and colour shorthands change their value object (one table of them); what
        # resolving the options changed with them is changed too (no deck wells: no wells)
        names = {SHORTHAND_FIELD.get(n, n) for n in given | set(carry)}
        names |= {f.name for f in dataclasses.fields(new)
                  if _differs(getattr(new, f.name), getattr(self.options, f.name))}
        jobs = self._apply_options(new, names) or []
        for job in jobs:
            self._pending.update(job.applies)
            job.apply = self._tracked(job.apply, dict(job.applies))
        return jobs

    def _refuse_fixed(self, changes: dict) -> None:
        """One line for a change of an option fixed when the View opens (its declaration says
        ``live=False``: where the work runs, the backend, the GPU budget...)."""
        fixed = sorted(n for n in changes if not self.Options.live(self._renamed(n)))
        if not fixed:
            return
        try:   # the same value again (as a viewer sends its settings back) is no change
            probe = self.options.replace(None, **{n: changes[n] for n in fixed})
            same = all(not _differs(getattr(probe, self._renamed(n)),
                                    getattr(self.options, self._renamed(n))) for n in fixed)
        except InputError:
            same = False
        if not same:
            now = getattr(self.options, self._renamed(fixed[0]))
            raise InputError(f"{', '.join(fixed)}: fixed when the {self.kind} view opens (it is "
                             f"{now}); open a new View to change it")

    def _renamed(self, name: str) -> str:
        dep = self.Options.DEPRECATED.get(name)
        return dep[0] if dep else name

    def _tracked(self, apply, applies: dict):
        def run(result) -> None:
            apply(result)
            for k, v in applies.items():
                if k in self._pending and self._pending[k] is v:
                    del self._pending[k]

        return run

    def update(self, **changes) -> None:
        """Change options by name and redo only what they need, now, on this thread."""
        for job in self.jobs(**changes):
            job.run(self.progress)

    def _set(self, **values) -> None:
        """Make already checked option values current (parts call this when applying)."""
        self.options = dataclasses.replace(self.options, **values)

    # --- drawing ---------------------------------------------------------------------------------
    def _target_for(self, size):
        from geoshade.render.target import Offscreen

        if self.target is None or self.target.size != tuple(size):
            if self.target is not None:
                self.target.release()
            self.target = Offscreen(self.ctx, size)
        return self.target

    def draw(self, camera=None, *, frames: int = 1, count: bool = True, warn: bool = True,
             transparent: bool | None = None, background=None,
             target=None) -> tuple[np.ndarray, dict]:
        """Render one picture.

        Parameters
        ----------
        camera : Camera, CameraSpec, view name or None
            None: the options' camera framed on the model.
        frames : int
            Frames drawn for timing; ``frame_ms`` is the median after the first.
        count : bool
            Also run the part's counting pass (GPU primitive/voxel counts in the stats).
        warn : bool
            Issue the warnings (an empty scene, ...) as Python warnings too; they are always in
            ``stats["warning"]``.
        transparent, background : optional
            This frame only: override the options' ``transparent`` and ``background``.

        Returns
        -------
        image : (h, w, 4) uint8
            RGBA, row 0 at the top.
        stats : dict
            ``width height method frame_ms first_frame_ms gpu_bytes renderer`` and the part's
            counts; ``warning`` when something was off.
        """
        from geoshade.render.target import time_frames

        if self._released:
            raise InputError(f"{self.kind} view: draw() after release()")
        target = target if target is not None else self._target_for(self.size)
        cam = self._camera_for(camera).with_aspect(target.aspect)
        self._last_frame = (cam, tuple(target.size), bool(count))
        if transparent is not None or background is not None:
            self.options = self.options.replace(
                self.model, **{k: v for k, v in (("transparent", transparent),
                                                 ("background", background)) if v is not None})
        o = self.options
        bg = (*o.background[:3], 0.0 if o.transparent else 1.0)

        occlusion = self.occlusion()

        def frame(count_now: bool = False) -> dict:
            target.clear(bg)
            out = self._frame(cam, target, count_now) or {}
            if occlusion is not None:
                self._ambient_pass().apply(target, cam, occlusion[0], occlusion[1],
                                           self.bounds())
            return out

        counts: dict = {}
        if count and frames <= 1 and self.count_in_frame:
            t0 = time.perf_counter()
            counts = frame(True)
            self.ctx.finish()
            first_ms = median_ms = (time.perf_counter() - t0) * 1000
        else:
            first_ms, median_ms = time_frames(self.ctx, frame, frames=max(1, int(frames)))
            if count:
                counts = frame(True)
        img = self._finish_image(target.read())
        w, h = target.size
        stats = {"width": w, "height": h, "method": self.method_name(),
                 "frame_ms": round(median_ms, 3), "first_frame_ms": round(first_ms, 3),
                 "gpu_bytes": int(self.gpu_bytes), "kind": self.kind}
        stats.update(self._stats(counts))
        if occlusion is not None:
            occ, radius = occlusion
            stats["occlusion"] = {"strength": occ.strength, "radius": radius,
                                  "depth_cue": occ.depth_cue}
        stats["renderer"] = self.ctx.info.get("GL_RENDERER")
        notes = list(self._notes(stats))
        reason = self._empty_reason(stats)
        if reason:
            notes.insert(0, (reason, EmptySceneWarning))
        if notes:
            stats["warning"] = "; ".join(m for m, _ in notes)
            if warn:
                for msg, cat in notes:
                    warnings.warn(msg, cat, stacklevel=2)
        if self.options.annotations and not self._annotations_fit(target.size):
            stats["annotations"] = {"skipped": f"a {w}x{h} picture is too small for them "
                                               f"(at least {MIN_ANNOTATED[0]}x"
                                               f"{MIN_ANNOTATED[1]})"}
        elif self.options.annotations:

            t0 = time.perf_counter()
            img, layout = annotate(img, self.annotations(cam, stats, target.size),
                                   cache=self._annotation_cache)
            layout["ms"] = round((time.perf_counter() - t0) * 1000, 3)
            stats["annotations"] = layout
        return img, stats

    # --- picking -------------------------------------------------------------------------------
    def pick(self, x: float, y: float, camera=None):
        """What pixel ``(x, y)`` of the picture shows: a :class:`~geoshade.render.pick.Pick`
        (cell, voxel, interval or surface point; its value, depth and position), or None where
        the pixel's ray meets nothing shown.

        ``x, y``: column and row, origin top-left as in the image array (the pixel's centre is
        cast). The camera and size are those of the last :meth:`draw` unless ``camera`` (a
        :class:`Camera`, a spec or a view name) is given. The ray is cast on the CPU through
        what is shown now (slice, filter, plane, selection, hidden materials, the surface of
        the shown step), so a pick is the same on every GPU. Each part's picker lives in
        ``geoshade.<part>.pick``.

        Examples
        --------
        >>> import numpy as np, geoshade
        >>> vol = geoshade.models.VoxelVolume(np.arange(64, dtype=np.uint8).reshape(4, 4, 4))
        >>> with geoshade.view(vol, select=(0, 63), view="top", ortho=True, size=(40, 40),
        ...                    annotations=False) as v:
        ...     _ = v.draw()
        ...     p = v.pick(5, 5)
        >>> p.index, p.value
        ((0, 3, 3), 60)
        """

        return pick_view(self, x, y, camera)

    # --- annotations ---------------------------------------------------------------------------
    def annotations(self, camera: Camera, stats: dict, size=None):
        """What is drawn over the picture (:class:`geoshade.styles.annotate.Annotations`):
        the part's title and time, its colour bar or legend, the axes triad and, in an
        orthographic map view (top or bottom), a scale bar in the model's length unit."""

        h = (size or self.size)[1]
        title, subtitle = self._title(stats)
        key = self._color_key(stats)
        labels, axes = self._triad()
        scalebar = None
        if camera.ortho and abs(camera.elevation) > 89.9:
            scalebar = ScaleBar(camera.units_per_pixel(h), self._length_unit())
        return Annotations(title, subtitle,
                           colorbar=key if isinstance(key, ColorBar) else None,
                           legend=key if isinstance(key, Legend) else None,
                           triad=triad_axes(camera.view_matrix(), labels, axes),
                           scalebar=scalebar)

    @staticmethod
    def _annotations_fit(size) -> bool:
        return size[0] >= MIN_ANNOTATED[0] and size[1] >= MIN_ANNOTATED[1]

    def _title(self, stats: dict) -> tuple[str, str]:
        """(title, subtitle: the time) of the picture."""
        return str(getattr(self.model, "name", "") or self.title), ""

    def _color_key(self, stats: dict):
        """The colour bar or legend of the picture (None: none)."""
        return None

    def _triad(self) -> tuple[tuple[str, str, str], Any]:
        """Labels of the triad's axes and their world vectors (None: x, y, z = E, N, up)."""
        return ("E", "N", "Up"), None

    def _length_unit(self) -> str:
        return ""

    # --- hooks of the parts --------------------------------------------------------------------
    def _setup(self) -> None:
        """Make the visuals (GL thread)."""

    def _frame(self, camera: Camera, target, count: bool) -> dict | None:
        """Draw one frame into the cleared ``target``; with ``count`` return the GPU counts."""
        raise NotImplementedError

    def _finish_image(self, img: np.ndarray) -> np.ndarray:
        return img

    def method_name(self) -> str:
        return self.kind

    def _stats(self, counts: dict) -> dict:
        return dict(counts)

    def _empty_reason(self, stats: dict) -> str | None:
        """Why the picture is an empty scene (None: it is not)."""
        return None

    def _notes(self, stats: dict) -> list[tuple[str, type[Warning]]]:
        """Other warnings of this frame, ``(message, category)``."""
        return []

    def _apply_options(self, new: OptionsT, changed: set[str]) -> list[Job] | None:
        """Make ``new`` current; redo what ``changed`` needs. The default covers options that
        only matter at draw time (camera, size, background)."""
        self.options = new
        return []

    def _gpu_objects(self) -> list:
        """The visuals (objects with ``gpu_bytes`` and ``release()``) this View owns now
        (default: ``self.visual`` when there is one)."""
        vis = getattr(self, "visual", None)
        return [] if vis is None else [vis]

    # --- read-outs -------------------------------------------------------------------------------
    @property
    def gpu_bytes(self) -> int:
        """Bytes of GPU memory the View's visuals hold now (0 after :meth:`release`)."""
        return int(sum(int(getattr(o, "gpu_bytes", 0) or 0) for o in self._gpu_objects()))

    def readout(self, stats: dict) -> str:
        """The part's counts for a status line."""
        return ""

    def summary(self, stats: dict) -> str:
        """One line for the command line: size, method, the part's counts, time and memory."""
        more = self.readout(stats)
        return (f"{stats['width']}x{stats['height']} {stats['method']}"
                + (f", {more}" if more else "")
                + f", {stats['frame_ms']:.1f} ms/frame, "
                f"{stats['gpu_bytes'] / 2**20:.2f} MiB on the GPU")

    # --- lifetime --------------------------------------------------------------------------------
    def _release_part(self) -> None:
        """Drop the released visuals; release what the part holds beyond them (threads)."""
        if "visual" in self.__dict__:   # a part's own attribute (a part may make it a property)
            self.__dict__["visual"] = None

    # --- ambient occlusion --------------------------------------------------------------------
    def occlusion(self):
        """``(Occlusion, radius in model units)`` to apply over the picture, or None (the
        default: a part turns it on where it helps, e.g. a core drawn in one solid colour)."""
        return None

    def _ambient_pass(self):
        if self._ambient is None:
            from geoshade.render.visuals.ambient.visual import AmbientPass

            self._ambient = AmbientPass(self.ctx)
        return self._ambient

    def release(self) -> None:
        """Free every GPU object of the View (idempotent)."""
        for obj in self._gpu_objects():
            obj.release()
        self._release_part()
        if getattr(self, "work", None) is not None:
            self.work.close()
        if self._ambient is not None:
            self._ambient.release()
            self._ambient = None
        if self.target is not None:
            self.target.release()
            self.target = None
        self._released = True

    @property
    def released(self) -> bool:
        return self._released

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.release()


def _differs(a, b) -> bool:
    """Whether two option values differ (arrays compared by identity)."""
    if a is b:
        return False
    try:
        return bool(a != b)
    except (TypeError, ValueError):   # numpy arrays: a new array is a new value
        return True


def cluster_readout(stats: dict) -> str:
    """What a View drawn on a cluster adds to its status line (empty for one process)."""
    d = stats.get("distributed")
    if not d:
        return ""
    return (f" · {len(d.get('bricks_per_worker', {}))} workers, "
            f"{d.get('bytes_moved', 0) / 1024:.0f} KiB/frame, slowest "
            f"{d.get('slowest_worker_ms', 0):.0f} ms")


def cluster_summary(stats: dict, part_word: str) -> str:
    """What a View drawn on a cluster adds to its summary line (``part_word``: what its parts
    are called, "bricks" or "parts"); empty for one process."""
    d = stats.get("distributed")
    if not d:
        return ""
    per = d.get("bricks_per_worker", {})
    return (f"; {len(per)} workers, {part_word} {'/'.join(str(v) for v in per.values())}, "
            f"{d.get('bytes_moved', 0) / 2**20:.2f} MiB moved per frame")


def fmt_int(v) -> str:
    """``1,234`` or ``?`` for None."""
    return "?" if v is None else f"{int(v):,}"


__all__ = ["EmptySceneWarning", "Job", "Progress", "View", "cluster_readout", "cluster_summary",
           "fmt_int"]
