"""Write animation frames to MP4 (imageio + imageio-ffmpeg) or GIF (Pillow), atomically.

The file is written under a temporary name in the destination folder and renamed at
:meth:`VideoWriter.close`; an interrupted animation leaves no half-written file.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from geoshade.errors import InputError, require
from geoshade.io.output import publish

#: suffixes written through ffmpeg (H.264) and through Pillow
VIDEO_SUFFIXES = (".mp4", ".m4v", ".mov", ".mkv")
GIF_SUFFIXES = (".gif",)


class VideoWriter:
    """``append(rgb)`` frames of one size, then ``close()`` (or use it as a context manager).

    Parameters
    ----------
    path : str or Path
        ``.mp4`` (also ``.m4v .mov .mkv``) or ``.gif``.
    fps : float
        Frames per second.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> out = os.path.join(tempfile.mkdtemp(), "a.gif")
    >>> with VideoWriter(out, fps=2) as w:
    ...     w.append(np.zeros((8, 8, 4), np.uint8)); w.append(np.full((8, 8, 3), 255, np.uint8))
    >>> os.path.getsize(out) > 0
    True
    """

    def __init__(self, path, fps: float = 4.0):
        self.path = Path(path)
        suffix = self.path.suffix.lower()
        if suffix not in VIDEO_SUFFIXES + GIF_SUFFIXES:
            raise InputError(f"{path}: unknown animation format {suffix or '(no suffix)'!r}; "
                             "expected .mp4 or .gif")
        folder = self.path.parent if str(self.path.parent) else Path(".")
        if not folder.is_dir():
            raise InputError(f"{path}: output folder {folder} does not exist")
        if not fps > 0:
            raise InputError(f"fps: expected a positive number, got {fps}")
        self.fps, self.gif = float(fps), suffix in GIF_SUFFIXES
        fd, tmp = tempfile.mkstemp(prefix=f".{self.path.stem}.", suffix=suffix, dir=folder)
        os.close(fd)
        self.tmp = Path(tmp)
        self.frames: list = []
        self.size = None
        self.count = 0
        self._writer = None

    def append(self, rgba: np.ndarray) -> None:
        img = np.ascontiguousarray(np.asarray(rgba, np.uint8)[..., :3])
        if self.size is None:
            self.size = img.shape[:2]
        elif img.shape[:2] != self.size:
            raise InputError(f"{self.path}: frame of {img.shape[1]}x{img.shape[0]} after "
                             f"frames of {self.size[1]}x{self.size[0]}")
        if self.gif:
            self.frames.append(Image.fromarray(img, "RGB").quantize(colors=256))
        else:
            if self._writer is None:
                require("imageio_ffmpeg", "video", "writing MP4 video")
                imageio = require("imageio.v2", "video", "writing MP4 video")

                self._writer = imageio.get_writer(
                    self.tmp, format="FFMPEG", mode="I", fps=self.fps, codec="libx264",
                    quality=8, pixelformat="yuv420p", macro_block_size=2,
                    ffmpeg_log_level="error")
            h, w = img.shape[:2]
            if h % 2 or w % 2:  # yuv420p needs even sides: repeat the last row/column
                img = np.pad(img, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
            self._writer.append_data(img)
        self.count += 1

    def close(self) -> Path:
        try:
            if self.count == 0:
                raise InputError(f"{self.path}: no frames to write")
            if self.gif:
                first, *rest = self.frames
                first.save(self.tmp, format="GIF", save_all=True, append_images=rest,
                           duration=round(1000 / self.fps), loop=0)
            else:
                self._writer.close()
                self._writer = None
            publish(self.tmp, self.path)
        finally:
            self.abort()
        return self.path

    def abort(self) -> None:
        """Drop the temporary file (after an error); the destination is left untouched."""
        if self._writer is not None:
            try:
                self._writer.close()
            except Exception:  # the writer may be broken already
                pass
            self._writer = None
        self.frames = []
        self.tmp.unlink(missing_ok=True)

    def __enter__(self) -> VideoWriter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()
