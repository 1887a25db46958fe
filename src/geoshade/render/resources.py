"""GPU objects as caches owned by a visual: created through here, counted, released explicitly."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import ClassVar

import moderngl
import numpy as np

from geoshade.errors import GPUMemoryError

#: OpenGL's GL_DEPTH_CLAMP (core since 3.2; moderngl has no flag for it)
GL_DEPTH_CLAMP = 0x864F


@contextmanager
def unclipped(ctx: moderngl.Context) -> Iterator[None]:
    """Draw a ray caster's proxy without clipping it at the near and far planes.

    The proxy's back faces start the rays: a back face beyond the far plane would leave its
    pixels without a fragment, hence without a ray, although the model lies on it before the far
    plane (a whole box seen from inside drew fewer voxels than the same box in bricks). The
    shaders clip each ray at both planes themselves."""
    ctx.enable_direct(GL_DEPTH_CLAMP)
    try:
        yield
    finally:
        ctx.disable_direct(GL_DEPTH_CLAMP)


class GpuCache:
    """Named buffers and textures of one visual, with exact byte accounting.

    Re-creating a name releases the old object first; :meth:`update` writes new data into an
    existing object of the same size without reallocating.
    """

    _BYTES: ClassVar[dict[str, int]] = {"u1": 1, "i1": 1, "f1": 1, "u2": 2, "i2": 2, "f2": 2,
                                       "u4": 4, "i4": 4, "f4": 4}

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._objects: dict[str, tuple[object, int]] = {}

    # ------------------------------------------------------------------------------------------
    def _put(self, name: str, obj, nbytes: int):
        self.drop(name)
        self._objects[name] = (obj, int(nbytes))
        return obj

    def texture3d(self, name: str, data: np.ndarray, components: int = 1, dtype: str = "u1",
                  filter_nearest: bool = True) -> moderngl.Texture3D:
        """Upload a ``(depth, height, width[, components])`` array as a 3D texture."""
        arr = np.ascontiguousarray(data)
        d, h, w = arr.shape[:3]
        limit = self.ctx.info.get("GL_MAX_3D_TEXTURE_SIZE", 2048)
        if max(d, h, w) > limit:
            raise GPUMemoryError(f"{name}: 3D texture {w}×{h}×{d} exceeds this GPU's limit of "
                                 f"{limit} per axis; choose a smaller box or render in bricks")
        tex = self._alloc(lambda: self.ctx.texture3d((w, h, d), components, arr, dtype=dtype,
                                                     alignment=1), name, arr.nbytes)
        if filter_nearest:
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        tex.repeat_x = tex.repeat_y = tex.repeat_z = False
        return self._put(name, tex, w * h * d * components * self._BYTES[dtype])

    def texture2d(self, name: str, data: np.ndarray, components: int = 4, dtype: str = "f1"
                  ) -> moderngl.Texture:
        arr = np.ascontiguousarray(data)
        h, w = arr.shape[:2]
        tex = self._alloc(lambda: self.ctx.texture((w, h), components, arr, dtype=dtype,
                                                   alignment=1), name, arr.nbytes)
        tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        tex.repeat_x = tex.repeat_y = False
        return self._put(name, tex, w * h * components * self._BYTES[dtype])

    def buffer(self, name: str, data=None, reserve: int = 0) -> moderngl.Buffer:
        if data is not None:
            arr = np.ascontiguousarray(data)
            buf = self._alloc(lambda: self.ctx.buffer(arr), name, arr.nbytes)
            return self._put(name, buf, arr.nbytes)
        buf = self._alloc(lambda: self.ctx.buffer(reserve=max(int(reserve), 4)), name, reserve)
        return self._put(name, buf, max(int(reserve), 4))

    def _alloc(self, make, name: str, nbytes: int):
        try:
            obj = make()
        except Exception as exc:
            raise GPUMemoryError(f"{name}: the GPU could not allocate {nbytes / 2**20:.1f} MiB "
                                 f"({str(exc).strip().splitlines()[0] if str(exc) else exc!r})"
                                 ) from None
        err = self.ctx.error
        if err == "GL_OUT_OF_MEMORY":
            obj.release()
            raise GPUMemoryError(f"{name}: out of GPU memory allocating {nbytes / 2**20:.1f} MiB")
        return obj

    def get(self, name: str):
        entry = self._objects.get(name)
        return entry[0] if entry else None

    def drop(self, name: str) -> None:
        entry = self._objects.pop(name, None)
        if entry is not None:
            entry[0].release()

    def release(self) -> None:
        for name in list(self._objects):
            self.drop(name)

    @property
    def nbytes(self) -> int:
        """Exact bytes of every buffer and texture this cache holds."""
        return sum(n for _, n in self._objects.values())

    def breakdown(self) -> dict[str, int]:
        """Bytes by name; an object named ``name@k`` (part ``k`` of ``name``: a buffer made in
        blocks) counts under ``name``."""
        out: dict[str, int] = {}
        for k, (_, n) in self._objects.items():
            base = k.split("@", 1)[0]
            out[base] = out.get(base, 0) + n
        return out
