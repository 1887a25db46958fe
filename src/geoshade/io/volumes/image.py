"""Images to drape on a terrain: PNG/JPEG (Pillow) and GeoTIFF (tifffile, georeferenced).

:func:`read_image` returns the pixels as RGBA and, for a GeoTIFF with ``ModelPixelScale`` and
``ModelTiepoint`` tags, the world rectangle the image covers; other images carry no position
and are stretched over the model's X–Y extent by the renderer.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import tifffile
from PIL import Image

from geoshade.errors import GeoshadeError, InputError
from geoshade.io.paths import captured_logs, check_file, check_memory, one_line

TIFF_SUFFIXES = (".tif", ".tiff")
_PIXEL_SCALE, _TIEPOINT = 33550, 33922


def _as_rgba(a: np.ndarray, path) -> np.ndarray:
    a = np.asarray(a)
    if a.ndim == 2:
        a = a[..., None]
    if a.ndim != 3 or a.shape[2] not in (1, 2, 3, 4):
        raise InputError(f"{path}: cannot read image: expected a grey, RGB or RGBA raster, got "
                         f"shape {a.shape}")
    if a.dtype != np.uint8:
        f = a.astype(np.float64)
        lo, hi = np.nanmin(f), np.nanmax(f)
        a = np.zeros(f.shape, np.uint8) if hi <= lo else \
            np.round((f - lo) / (hi - lo) * 255).astype(np.uint8)
    c = a.shape[2]
    if c in (1, 2):
        rgb = np.repeat(a[..., :1], 3, axis=2)
        alpha = a[..., 1:2] if c == 2 else np.full((*a.shape[:2], 1), 255, np.uint8)
    else:
        rgb = a[..., :3]
        alpha = a[..., 3:4] if c == 4 else np.full((*a.shape[:2], 1), 255, np.uint8)
    return np.ascontiguousarray(np.concatenate([rgb, alpha], axis=2))


def _check(path) -> Path:
    """``path`` if it is a regular file (a FIFO would block the reader forever)."""
    try:
        return check_file(path, "an image file")
    except InputError as exc:
        msg = str(exc).replace(f"{path}: ", f"{path}: cannot read image: ", 1)
        raise InputError(msg) from None


def probe_image(path) -> tuple[int, int]:
    """``(width, height)`` of an image file from its header only (nothing decoded), or the same
    one-line error :func:`read_image` gives: options check a drape before any work with it.

    >>> import tempfile, os
    >>> from PIL import Image
    >>> f = os.path.join(tempfile.mkdtemp(), "a.png")
    >>> Image.new("RGB", (4, 3)).save(f)
    >>> probe_image(f)
    (4, 3)
    """
    p = _check(path)
    if p.suffix.lower() in TIFF_SUFFIXES:

        try:
            with captured_logs("tifffile"), tifffile.TiffFile(p) as tf:
                shape = tf.pages[0].shape
        except Exception as exc:
            raise InputError(f"{path}: cannot read image ({one_line(exc)})") from None
        h, w = (shape[1], shape[2]) if len(shape) == 3 and shape[0] in (3, 4) \
            and shape[2] not in (3, 4) else (shape[0], shape[1])
        return int(w), int(h)
    try:
        with Image.open(p) as im:
            return int(im.size[0]), int(im.size[1])
    except Exception as exc:  # Pillow: UnidentifiedImageError, OSError, DecompressionBombError
        raise InputError(f"{path}: cannot read image ({one_line(exc)})") from None


def read_image(path) -> tuple[np.ndarray, tuple[float, float, float, float] | None]:
    """Read a drape image.

    Returns
    -------
    rgba : (h, w, 4) uint8
        Row 0 at the top (north).
    extent : (xmin, ymin, xmax, ymax) or None
        World rectangle of a georeferenced GeoTIFF, else None.

    Raises
    ------
    InputError
        One line when the file is missing or cannot be read as an image.

    Examples
    --------
    >>> import tempfile, os
    >>> from PIL import Image
    >>> f = os.path.join(tempfile.mkdtemp(), "a.png")
    >>> Image.new("RGB", (4, 3), (10, 20, 30)).save(f)
    >>> rgba, extent = read_image(f)
    >>> rgba.shape, rgba[0, 0].tolist(), extent
    ((3, 4, 4), [10, 20, 30, 255], None)
    """
    p = _check(path)
    w, h = probe_image(p)
    check_memory(w * h * 4 * 3, path, f"the {w}×{h} image (RGBA and its conversions)")
    if p.suffix.lower() in TIFF_SUFFIXES:

        try:
            with captured_logs("tifffile"), tifffile.TiffFile(p) as tf:
                page = tf.pages[0]
                arr = page.asarray()
                scale = page.tags.get(_PIXEL_SCALE)
                tie = page.tags.get(_TIEPOINT)
                scale = None if scale is None else tuple(float(v) for v in scale.value)
                tie = None if tie is None else tuple(float(v) for v in tie.value)
        except Exception as exc:
            raise InputError(f"{path}: cannot read image ({one_line(exc)})") from None
        if arr.ndim == 3 and arr.shape[0] in (3, 4) and arr.shape[2] not in (3, 4):
            arr = np.moveaxis(arr, 0, -1)
        rgba = _as_rgba(arr, path)
        extent = None
        if scale and tie and len(scale) >= 2 and len(tie) >= 6:
            h, w = rgba.shape[:2]
            i, j, x, y = tie[0], tie[1], tie[3], tie[4]
            xmin, ymax = x - i * scale[0], y + j * scale[1]
            extent = (xmin, ymax - h * scale[1], xmin + w * scale[0], ymax)
        return rgba, extent
    try:
        with Image.open(p) as im:
            im = im.convert("RGBA")
            arr = np.asarray(im)
    except (GeoshadeError, MemoryError):
        raise
    except Exception as exc:  # Pillow: UnidentifiedImageError, OSError, DecompressionBombError
        raise InputError(f"{path}: cannot read image ({one_line(exc)})") from None
    return np.ascontiguousarray(arr, np.uint8), None
