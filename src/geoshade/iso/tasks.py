"""One-shot functions of the iso part: ``render``, ``export_mesh``, ``animate``."""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

from geoshade.iso.api import DEFAULT_PATCH_LEVEL, EmptySurfaceWarning, OutsideValuesWarning
from geoshade.iso.view import IsoView
from geoshade.models.field import FieldSeries, TriangleMesh


def render(field: FieldSeries, level, step=None, color_by=None, camera=None, size=(1024, 768),
           view: str = "iso", azimuth=None, elevation=None, zoom: float = 1.0,
           ortho: bool = False, transparent: bool = False, colormap: str = "viridis",
           color_range=None, patch_level: int = DEFAULT_PATCH_LEVEL, skip_patches: bool = True,
           slice_axis: str = "auto", z_scale: float = 1.0, frames: int = 5,
           count: bool = True, mesh=None, mesh_cache: bool = True,
           ctx=None) -> tuple[np.ndarray, dict]:
    """Render the isosurface ``S = level`` of one step of ``field``.

    Parameters
    ----------
    field : FieldSeries
    level : float
        ``S*``; a level outside the step's values draws nothing and warns
        (:class:`EmptySurfaceWarning`).
    step : int, optional
        Default: the last step.
    color_by : str, optional
        A ``field.properties`` name to colour the surface by.
    camera : Camera, optional
        Default: framed on the field's bounds from ``view``/``azimuth``/``elevation``/``zoom``.
    frames : int
        Frames drawn for timing; ``frame_ms`` is the median after the first.
    patch_level, skip_patches, slice_axis
        The patch-quads: see :class:`IsoView` (``patch_level=64, skip_patches=False,
        slice_axis="z"`` is the paper's method exactly).
    z_scale : float
        Vertical exaggeration (1 = true geometry).
    mesh : str or Path, optional
        Also write the drawn triangles (transform feedback) to this ``.ply/.obj/.stl``.
    mesh_cache : bool
        Timed frames after the first re-draw the captured surface (see :class:`IsoView`);
        False marches every frame, as the paper does.

    Returns
    -------
    image : (h, w, 4) uint8
    stats : dict
        ``width height method frame_ms gpu_bytes cells triangles`` and more (see
        :meth:`IsoView.draw`); ``mesh_vertices``/``mesh_faces`` when a mesh was written.

    Examples
    --------
    >>> import geoshade.iso
    >>> from geoshade.compute.displacement import displacement_field
    >>> f = displacement_field((24, 16, 16), steps=2)
    >>> img, st = geoshade.iso.render(f, 0.5, size="64x48")     # doctest: +SKIP
    >>> img.shape, st["method"]                                   # doctest: +SKIP
    ((48, 64, 4), 'tessellation')
    """
    v = IsoView(field, level, step=step, color_by=color_by, color_range=color_range,
                colormap=colormap, size=size, patch_level=patch_level,
                skip_patches=skip_patches, slice_axis=slice_axis, prefetch=False,
                z_scale=z_scale, mesh_cache=mesh_cache, ctx=ctx)
    try:
        cam = camera or v.camera(view=view, azimuth=azimuth, elevation=elevation, zoom=zoom,
                                 ortho=ortho)
        img, stats = v.draw(cam, transparent=transparent, frames=frames, count=count)
        if mesh is not None:
            m = v.mesh()
            from geoshade.io.mesh import write_mesh

            write_mesh(mesh, m)
            stats["mesh"] = str(mesh)
            stats["mesh_vertices"], stats["mesh_faces"] = m.n_vertices, m.n_faces
        return img, stats
    finally:
        v.release()


def export_mesh(field: FieldSeries, level, path=None, step=None, color_by=None,
                color_range=None, ctx=None) -> TriangleMesh:
    """The isosurface's triangles as the GPU emits them (transform feedback), optionally written.

    Parameters
    ----------
    path : str or Path, optional
        ``.ply``, ``.obj`` or ``.stl`` to write (atomically).

    Returns
    -------
    TriangleMesh
        World coordinates, welded vertices, normals towards lower values.

    Examples
    --------
    >>> from geoshade.compute.displacement import displacement_field
    >>> m = export_mesh(displacement_field((24, 16, 16), steps=2), 0.5)   # doctest: +SKIP
    >>> m.n_faces > 0                                                      # doctest: +SKIP
    True
    """
    v = IsoView(field, level, step=step, color_by=color_by, color_range=color_range,
                size=(1, 1), prefetch=False, ctx=ctx)
    try:
        reason = v.empty_reason()
        if reason is not None:
            warnings.warn(f"{field.name or 'field'} at step {v.step}: {reason}; the mesh is empty",
                          EmptySurfaceWarning, stacklevel=2)
        m = v.mesh()
        if path is not None:
            from geoshade.io.mesh import write_mesh

            write_mesh(path, m)
        return m
    finally:
        v.release()


def animate(field: FieldSeries, level, output, size=(1920, 1080), fps: float = 4.0,
            steps=None, color_by=None, color_range=None, view: str = "iso", azimuth=None,
            elevation=None, zoom: float = 1.0, ortho: bool = False, colormap: str = "viridis",
            patch_level: int = DEFAULT_PATCH_LEVEL, skip_patches: bool = True,
            slice_axis: str = "auto", z_scale: float = 1.0, progress=None, ctx=None) -> dict:
    """Render every step (or ``steps``) into an ``.mp4`` or ``.gif``, with one fixed camera.

    The next step is prepared in a background thread while the current one is drawn; the file is
    written atomically. Steps where the level is outside the values are drawn empty and named in
    one warning at the end.

    Parameters
    ----------
    output : str or Path
        ``.mp4`` (H.264 through imageio-ffmpeg) or ``.gif`` (Pillow).
    progress : callable(done, total), optional
        Called after each frame (the CLI drives a tqdm bar with it).

    Returns
    -------
    dict
        ``output frames width height fps frame_ms`` (median draw), ``step_switch_ms`` (median),
        ``triangles`` (per step), ``empty_steps``, ``seconds``.
    """
    from geoshade.iso.video import VideoWriter

    t_start = time.perf_counter()
    order = list(range(field.nsteps)) if steps is None else [field.check_step(s) for s in steps]
    writer = VideoWriter(output, fps=fps)
    v = None
    try:
        v = IsoView(field, level, step=order[0], color_by=color_by, color_range=color_range,
                    colormap=colormap, size=size, patch_level=patch_level,
                    skip_patches=skip_patches, slice_axis=slice_axis, z_scale=z_scale,
                    mesh_cache=False, ctx=ctx)  # one frame per step: nothing to re-draw
        cam = v.camera(view=view, azimuth=azimuth, elevation=elevation, zoom=zoom, ortho=ortho)
        frame_ms, switch_ms, tris, empty, nonfinite = [], [], [], [], 0
        for i, k in enumerate(order):
            if i:
                v.set_step(k)
                switch_ms.append(v.switch_ms)
            img, st = v.draw(cam, frames=1, count=True, warn=False)
            writer.append(img)
            frame_ms.append(st["frame_ms"])
            tris.append(st["triangles"])
            if v.empty_reason() is not None:
                empty.append(k)
            nonfinite = max(nonfinite, st["nonfinite"])
            if progress is not None:
                progress(i + 1, len(order))
        writer.close()
    except BaseException:
        writer.abort()
        raise
    finally:
        if v is not None:
            v.release()
    if empty:
        warnings.warn(f"{field.name or 'field'}: level {float(level):g} is outside the values at "
                      f"step(s) {empty}; those frames are empty", EmptySurfaceWarning,
                      stacklevel=2)
    if nonfinite:
        warnings.warn(f"{field.name or 'field'}: up to {nonfinite:,} nodes per step are NaN or "
                      "infinite; they are treated as outside the surface", OutsideValuesWarning,
                      stacklevel=2)
    return {
        "output": str(Path(output)), "frames": len(order), "width": int(img.shape[1]),
        "height": int(img.shape[0]), "fps": float(fps),
        "frame_ms": float(np.median(frame_ms)),
        "step_switch_ms": float(np.median(switch_ms)) if switch_ms else 0.0,
        "triangles": tris, "empty_steps": empty, "steps": order,
        "seconds": round(time.perf_counter() - t_start, 3),
    }
