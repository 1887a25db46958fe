"""Ambient occlusion and a depth cue as a pass over a finished picture (colour + depth of an
:class:`~geoshade.render.target.Offscreen`), the same for every method and part that writes
depth: see ``ambient.frag`` and :class:`geoshade.styles.light.Occlusion`."""

from __future__ import annotations

import moderngl
import numpy as np

from geoshade.render.camera import Camera
from geoshade.render.shaders import ProgramSpec
from geoshade.render.target import neutral_framebuffer
from geoshade.styles.light import Occlusion

PKG = __package__
#: the one program: a full-screen triangle and the occlusion/depth-cue shader
PROGRAMS = [ProgramSpec("ambient", {"vert": "fullscreen.vert", "frag": "ambient.frag"})]


def cue_range(camera: Camera, bounds) -> tuple[float, float]:
    """View distances of the nearest and farthest corner of ``bounds`` (2, 3).

    >>> cam = Camera.framed([[0, 0, 0], [1, 1, 1]], "top")
    >>> near, far = cue_range(cam, [[0, 0, 0], [1, 1, 1]])
    >>> round(far - near, 6)
    1.0
    """
    b = np.asarray(bounds, np.float64)
    corners = np.array([[b[i, 0], b[j, 1], b[k, 2], 1.0]
                        for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    z = -(corners @ np.asarray(camera.view_matrix(), np.float64).T)[:, 2]
    return float(z.min()), float(z.max())


class AmbientPass:
    """Applies :class:`Occlusion` to a target in place: renders into a scratch colour texture
    of the target's size (kept while the size stays), then copies it back."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.program = PROGRAMS[0].load(ctx, PKG)
        self.vao = ctx.vertex_array(self.program, [])
        self._scratch: tuple | None = None   # (size, texture, framebuffer)

    @property
    def nbytes(self) -> int:
        """GPU bytes of the scratch picture (RGBA8)."""
        return 0 if self._scratch is None else int(np.prod(self._scratch[0])) * 4

    def _fbo(self, size) -> moderngl.Framebuffer:
        if self._scratch is None or self._scratch[0] != tuple(size):
            self._drop_scratch()
            tex = self.ctx.texture(tuple(size), 4, dtype="f1")
            self._scratch = (tuple(size), tex, self.ctx.framebuffer(color_attachments=[tex]))
        return self._scratch[2]

    def apply(self, target, camera: Camera, occlusion: Occlusion, radius: float, bounds
              ) -> None:
        """Darken ``target`` (an Offscreen drawn with ``camera``) by ``occlusion``; ``radius``
        in model units (view units: the camera's matrices are rigid), ``bounds`` (2, 3) the
        model's, for the depth cue."""
        w, h = target.size
        fbo = self._fbo((w, h))
        proj = np.asarray(camera.projection_matrix(), np.float64)
        prog = self.program
        prog["proj"].write(proj.T.astype("f4").tobytes())
        prog["inv_proj"].write(np.linalg.inv(proj).T.astype("f4").tobytes())
        prog["size"].value = (float(w), float(h))
        prog["radius"].value = float(radius)
        prog["strength"].value = float(occlusion.strength)
        prog["depth_cue"].value = float(occlusion.depth_cue)
        prog["cue_range"].value = cue_range(camera, bounds)
        prog["color_tex"].value = 0
        prog["depth_tex"].value = 1
        depth = target.depth
        compare = depth.compare_func
        depth.compare_func = ""       # sample depth values, not comparisons
        target.color.use(0)
        depth.use(1)
        fbo.use()
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        self.vao.render(moderngl.TRIANGLES, vertices=3)
        depth.compare_func = compare
        self.ctx.copy_framebuffer(target.fbo, fbo)
        target.fbo.use()

    def _drop_scratch(self) -> None:
        if self._scratch is not None:

            neutral_framebuffer(self.ctx).use()
            self._scratch[2].release()
            self._scratch[1].release()
            self._scratch = None

    def release(self) -> None:
        self._drop_scratch()
        self.vao.release()
        self.program.release()
