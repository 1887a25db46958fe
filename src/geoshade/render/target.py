"""Offscreen render targets and frame timing."""

from __future__ import annotations

import time

import moderngl
import numpy as np

from geoshade.errors import InputError


def neutral_framebuffer(ctx: moderngl.Context) -> moderngl.Framebuffer:
    """A 1×1 framebuffer that lives as long as the context, bound before releasing others.

    moderngl re-binds the last bound framebuffer when it creates a new one; if that one was
    released, GL reports INVALID_OPERATION.
    """
    extra = ctx.extra if isinstance(ctx.extra, dict) else {}
    ctx.extra = extra
    if "neutral_fbo" not in extra:
        extra["neutral_fbo"] = ctx.simple_framebuffer((1, 1))
    return extra["neutral_fbo"]


class Offscreen:
    """An RGBA8 colour + 32-bit float depth framebuffer of ``size`` (width, height)."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]):
        w, h = (int(v) for v in size)
        limit = ctx.info.get("GL_MAX_RENDERBUFFER_SIZE", 8192)
        if not (1 <= w <= limit and 1 <= h <= limit):
            raise InputError(f"size: {w}x{h} is outside 1..{limit} pixels per side")
        self.ctx, self.size = ctx, (w, h)
        self.color = ctx.texture((w, h), 4, dtype="f1")
        self.depth = ctx.depth_texture((w, h))
        self.fbo = ctx.framebuffer(color_attachments=[self.color], depth_attachment=self.depth)

    @property
    def aspect(self) -> float:
        return self.size[0] / self.size[1]

    def clear(self, background=(1.0, 1.0, 1.0, 1.0)) -> None:
        self.fbo.use()
        self.fbo.clear(*background, depth=1.0)

    def read(self) -> np.ndarray:
        """The colour buffer as ``(height, width, 4) uint8``, row 0 at the top."""
        w, h = self.size
        data = self.fbo.read(components=4, dtype="f1", alignment=1)
        return np.frombuffer(data, np.uint8).reshape(h, w, 4)[::-1].copy()

    def release(self) -> None:
        # moderngl re-binds the framebuffer bound last when it makes the next one: never leave
        # a released framebuffer bound
        neutral_framebuffer(self.ctx).use()
        for o in (self.fbo, self.color, self.depth):
            o.release()


def time_frames(ctx: moderngl.Context, draw, frames: int = 5) -> tuple[float, float]:
    """(first_ms, median_ms) of ``draw()`` each followed by ``ctx.finish()``.

    The first frame is reported apart (it includes shader warm-up); the median is over the rest.
    """
    times = []
    for _ in range(max(1, frames)):
        t0 = time.perf_counter()
        draw()
        ctx.finish()
        times.append((time.perf_counter() - t0) * 1000.0)
    rest = times[1:] or times
    return times[0], float(np.median(rest))
