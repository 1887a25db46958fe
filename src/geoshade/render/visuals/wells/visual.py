"""Well trajectories as impostor tubes and markers as impostor spheres (the paper's Section on
3D tubes).

Tubes: the points of every trajectory plus an extrapolated point at each end go into one vertex
buffer; four indices per segment (``a0 a1 a2 a3``) are drawn as ``lines_adjacency`` and the
geometry shader builds the paper's camera-facing plane with mitre joins (``tube.geom``); the
fragment shader shades it as a cylinder and, by default, writes the cylinder's exact depth.
Spheres: one ``vec4`` (centre, radius) per sphere, a camera-facing square from the geometry
shader and an exact ray–sphere intersection in the fragment shader (silhouette, normal, depth).
Every trajectory point also gets a sphere of the tube's radius (round joins and end caps; a
segment seen end-on is such a disc).
"""

from __future__ import annotations

import moderngl
import numpy as np

from geoshade.render.camera import Camera
from geoshade.render.resources import GpuCache
from geoshade.render.shaders import ProgramSpec, load_program

PKG = __package__
#: every program this visual builds: impostor tubes (exact or the paper's shading), spheres
PROGRAMS = [
    ProgramSpec("tube", {"vert": "tube.vert", "geom": "tube.geom", "frag": "tube.frag"},
                ({"TUBE_EXACT": 1}, {"TUBE_EXACT": 0})),
    ProgramSpec("sphere", {"vert": "sphere.vert", "geom": "sphere.geom", "frag": "sphere.frag"}),
]
TUBE_COLOR = (0.20, 0.22, 0.28)
MARKER_COLOR = (0.95, 0.55, 0.10)
#: marker radius in tube radii
MARKER_SCALE = 1.8


def tube_buffers(paths) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) float32 and ``lines_adjacency`` indices (segments, 4) uint32.

    Each path ``p_0 .. p_{m-1}`` is stored as ``2p_0 - p_1, p_0, .., p_{m-1}, 2p_{m-1} -
    p_{m-2}``; segment ``s`` of a path uses the stored points ``s .. s+3``.

    >>> v, i = tube_buffers([np.array([[0, 0, 0], [0, 0, 1.0], [0, 1, 1]])])
    >>> v[:, 2].tolist(), i.tolist()
    ([-1.0, 0.0, 1.0, 1.0, 1.0], [[0, 1, 2, 3], [1, 2, 3, 4]])
    """
    verts, idx, base = [], [], 0
    for p in paths:
        p = np.asarray(p, np.float64).reshape(-1, 3)
        if len(p) < 2:
            continue
        ext = np.concatenate([2 * p[:1] - p[1:2], p, 2 * p[-1:] - p[-2:-1]])
        segs = len(p) - 1
        s = np.arange(segs, dtype=np.int64)[:, None] + np.arange(4)[None, :] + base
        verts.append(ext)
        idx.append(s)
        base += len(ext)
    if not verts:
        return np.zeros((0, 3), np.float32), np.zeros((0, 4), np.uint32)
    return (np.concatenate(verts).astype(np.float32),
            np.concatenate(idx).astype(np.uint32))


def _colors(colors, counts, default) -> np.ndarray:
    """(sum(counts), 3) float32: one RGB per item, from one RGB per group (or per item)."""
    total = int(sum(counts))
    if colors is None:
        return np.tile(np.asarray(default, np.float32), (total, 1))
    out = []
    for c, n in zip(colors, counts, strict=True):
        c = np.asarray(c, np.float32)
        out.append(np.broadcast_to(c.reshape(-1, 3) if c.size != 3 else c, (n, 3)))
    return np.concatenate(out).astype(np.float32) if out else np.zeros((0, 3), np.float32)


class WellsVisual:
    """GPU state and drawing of well tubes and marker spheres.

    Parameters
    ----------
    ctx : moderngl.Context
    paths : list of (n, 3) float
        Trajectories in world coordinates minus the origin of the model matrix given to draw.
    markers : list of (m, 3) float
        Marker positions (same coordinates).
    radius : float
        Tube radius (world units); markers are ``MARKER_SCALE`` times larger.
    exact : bool
        Exact cylinder normal and depth (default); False reproduces the paper's shading.
    joints : bool
        Spheres of the tube radius at every trajectory point.
    path_colors : list, optional
        One RGB (0..1) per path, or an (n, 3) array per path (segment ``s`` takes the colour of
        its point ``s``); default ``tube_color``. Joints take their point's colour.
    marker_colors : list, optional
        One RGB per marker group, or an (m, 3) array per group; default ``marker_color``.
    """

    def __init__(self, ctx: moderngl.Context, paths, markers=(), radius: float = 1.0,
                 exact: bool = True, joints: bool = True, tube_color=TUBE_COLOR,
                 marker_color=MARKER_COLOR, marker_radius: float | None = None,
                 path_colors=None, marker_colors=None):
        self.ctx, self.radius = ctx, float(radius)
        self.tube_color, self.marker_color = tuple(tube_color), tuple(marker_color)
        self.cache = GpuCache(ctx)
        self.tube_prog = load_program(ctx, PKG, {"vert": "tube.vert", "geom": "tube.geom",
                                                 "frag": "tube.frag"},
                                      {"TUBE_EXACT": int(bool(exact))})
        self.sphere_prog = load_program(ctx, PKG, {"vert": "sphere.vert",
                                                   "geom": "sphere.geom",
                                                   "frag": "sphere.frag"})
        paths = [np.asarray(p, np.float64).reshape(-1, 3) for p in paths]
        self.n_wells = len(paths)
        point_rgb = _colors(path_colors, [len(p) for p in paths], self.tube_color)
        verts, idx = tube_buffers(paths)
        self.n_segments = len(idx)
        self.vaos: list[tuple[moderngl.VertexArray, str, int]] = []
        if self.n_segments:
            vb = self.cache.buffer("tube_points", verts)
            cb = self.cache.buffer("tube_colors", _extended(point_rgb, paths))
            ib = self.cache.buffer("tube_segments", idx)
            vao = ctx.vertex_array(self.tube_prog, [(vb, "3f4", "position"),
                                                    (cb, "3f4", "rgb")],
                                   index_buffer=ib, index_element_size=4)
            self.vaos.append((vao, "tube", idx.size))
        mr = self.radius * MARKER_SCALE if marker_radius is None else float(marker_radius)
        groups = []
        if joints and paths:
            groups.append(("joints", np.concatenate(paths), self.radius, point_rgb))
        mk = [np.asarray(m, np.float64).reshape(-1, 3) for m in markers]
        if mk and sum(len(m) for m in mk):
            groups.append(("markers", np.concatenate(mk), mr,
                           _colors(marker_colors, [len(m) for m in mk], self.marker_color)))
        self.n_markers = int(sum(len(m) for m in mk))
        for name, pts, r, rgb in groups:
            data = np.concatenate([pts, np.full((len(pts), 1), r), rgb], axis=1)
            buf = self.cache.buffer(name, data.astype(np.float32))
            vao = ctx.vertex_array(self.sphere_prog, [(buf, "4f4 3f4", "sphere", "rgb")])
            self.vaos.append((vao, "sphere", len(pts)))

    @property
    def gpu_bytes(self) -> int:
        return self.cache.nbytes

    def draw(self, camera: Camera, model: np.ndarray, shading: dict,
             fbo: moderngl.Framebuffer | None = None, xray: bool = False) -> None:
        """Draw into the bound framebuffer (depth-tested with what is already there).

        ``xray`` (needs ``fbo``, the bound framebuffer): first draw the parts hidden behind
        what the framebuffer holds (depth test GREATER, no depth writes) on top of it as a
        half-tone of a lighter colour, so wells inside an opaque grid stay visible; then the
        wells as usual. The half-tone pass comes first so that it compares with the grid's
        depth only (never with the wells' own surfaces: a joint sphere behind its tube).
        """
        ctx = self.ctx
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        mv = camera.view_matrix() @ np.asarray(model, np.float64)
        proj = camera.projection_matrix()
        for prog in (self.tube_prog, self.sphere_prog):
            for name, value in {"mv": mv, "proj": proj, "radius": self.radius,
                                "ortho": int(camera.ortho), **shading}.items():
                try:
                    u = prog[name]
                except KeyError:
                    continue
                if isinstance(value, np.ndarray):
                    u.write(np.asarray(value, "f4").T.tobytes())
                else:
                    u.value = value
        if xray and fbo is not None and self.vaos:
            fbo.depth_mask = False
            ctx.depth_func = ">"
            try:
                self._render(1)
            finally:
                ctx.depth_func = "<"
                fbo.depth_mask = True
        self._render(0)

    def _render(self, xray: int) -> None:
        for prog in (self.tube_prog, self.sphere_prog):
            prog["xray"].value = xray
        for vao, kind, n in self.vaos:
            if kind == "tube":
                vao.render(moderngl.LINES_ADJACENCY, vertices=n)
            else:
                vao.render(moderngl.POINTS, vertices=n)

    def release(self) -> None:
        for vao, *_ in self.vaos:
            vao.release()
        self.vaos = []
        self.tube_prog.release()
        self.sphere_prog.release()
        self.cache.release()


def _extended(rgb: np.ndarray, paths) -> np.ndarray:
    """The per-point colours laid out as :func:`tube_buffers` lays out the points (each path
    with one extrapolated point at either end, paths of one point left out)."""
    out, base = [], 0
    for p in paths:
        n = len(p)
        if n >= 2:
            c = rgb[base:base + n]
            out.append(np.concatenate([c[:1], c, c[-1:]]))
        base += n
    return np.concatenate(out).astype(np.float32) if out else np.zeros((0, 3), np.float32)
