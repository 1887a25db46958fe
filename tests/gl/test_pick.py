"""``View.pick`` (issue 13, picking): the cell, voxel, interval or surface point a pixel shows.

"Picking returns the cell that a numpy ray–cell intersection gives": every picker is compared
with a brute-force oracle written here (the pixel's ray from the camera's matrices, then every
shown cell's 12 triangles, every selected voxel's box, every voxel of the stack model, every
triangle of the whole isosurface), on a lattice of pixels and on every pixel next to a change of
the picked cell (cell edges), with exaggeration, filters, hidden materials and misses; and with
the GPU's picture (a pixel is background exactly where nothing is picked; the picked cell alone
covers the pixel; without it the pixel changes).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import geoshade
from geoshade.errors import InputError
from tests.compute.test_pick import (
    ORACLE_QUADS,
    oracle_faces,
    oracle_grid_hit,
    oracle_ray_triangle,
)
from tests.gl.grid_support import make_grid

SIZE = (64, 48)


_CAMERAS: dict = {}


def camera_of(view):
    """The camera a plain ``draw()`` of ``view`` uses (framed once per view and options)."""
    key = (id(view), view.options.camera, view.size, view.bounds().tobytes())
    if key not in _CAMERAS:
        w, h = view.size
        _CAMERAS.clear()
        _CAMERAS[key] = view.camera().with_aspect(w / h)
    return _CAMERAS[key]


def pixel_ray(view, x, y):
    """The ray of pixel (x, y) in display world, from the camera's matrices (t 0 near, 1 far)."""
    w, h = view.size
    cam = camera_of(view)
    inv = np.linalg.inv(cam.projection_matrix() @ cam.view_matrix())
    ndc = [(x + 0.5) / w * 2 - 1, 1 - (y + 0.5) / h * 2]
    near, far = inv @ np.array([*ndc, -1.0, 1.0]), inv @ np.array([*ndc, 1.0, 1.0])
    near, far = near[:3] / near[3], far[:3] / far[3]
    return near, far - near


def pick_map(view):
    """Every pixel's pick: (h, w) object array."""
    w, h = view.size
    out = np.empty((h, w), object)
    for y in range(h):
        for x in range(w):
            out[y, x] = view.pick(x, y)
    return out


def key_map(picks, key):
    h, w = picks.shape
    return np.array([[-1 if p is None else key(p) for p in row] for row in picks]).reshape(h, w)


def pixels_to_check(keys, step=4):
    """A lattice of pixels and every pixel whose right or lower neighbour picks differently."""
    edge = np.zeros(keys.shape, bool)
    edge[:, :-1] |= keys[:, :-1] != keys[:, 1:]
    edge[:-1, :] |= keys[:-1, :] != keys[1:, :]
    lattice = np.zeros(keys.shape, bool)
    lattice[::step, ::step] = True
    ys, xs = np.nonzero(edge | lattice)
    return list(zip(xs.tolist(), ys.tolist(), strict=True)), int(edge.sum())




def silhouette_agrees(img, picks) -> int:
    """Pixels where 'nothing picked' and 'background' disagree, away from the silhouette."""
    bg = (img[..., :3] == 255).all(axis=-1)
    none = np.vectorize(lambda p: p is None, otypes=[bool])(picks)
    pad = np.pad(none, 1, mode="edge")
    steady = np.ones_like(none)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            steady &= pad[dy:dy + none.shape[0], dx:dx + none.shape[1]] == none
    return int(np.count_nonzero((bg != none) & steady))


# --- grid ----------------------------------------------------------------------------------------
def _grid():
    c, s = np.cos(0.4), np.sin(0.4)
    mapaxes = [1000 - 100 * s, 2000 + 100 * c, 1000, 2000, 1000 + 100 * c, 2000 + 100 * s]
    return make_grid(nx=6, ny=5, nz=4, throw=6.0, fault_i=3, inactive=[(0, 0, 0), (2, 2, 0)],
                     mapaxes=mapaxes)


def grid_ray(view, x, y):
    """The pixel's ray in the grid's coordinates (x, y, depth): MAPAXES and exaggeration undone."""
    o, d = pixel_ray(view, x, y)
    g, ex = view.grid, view.options.exaggeration
    t = g.map_transform()
    a = np.linalg.inv(t[:2, :2])
    return (np.array([*(a @ (o[:2] - t[:2, 2])), -o[2] / ex]),
            np.array([*(a @ d[:2]), -d[2] / ex]))


def oracle_front(view, faces) -> np.ndarray:
    """The faces the GPU's back-face cull keeps (a frame drawn without the counting pass): the
    geometry shader's test, in view space."""
    from geoshade.grid.geometry import model_matrix

    g, (cells, face, _) = view.grid, faces
    corners = g.corners()[cells[:, 0], cells[:, 1], cells[:, 2]]
    quad = corners[np.arange(len(face))[:, None], ORACLE_QUADS[face]]  # (n, 4, 3)
    cam = camera_of(view)
    mv = cam.view_matrix() @ model_matrix(g, np.zeros(3), view.options.exaggeration)
    p = quad @ mv[:3, :3].T + mv[:3, 3]
    n = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
    to_eye = np.array([0.0, 0.0, 1.0]) if cam.ortho else -p.mean(axis=1)
    sign = np.sign(np.linalg.det(mv[:3, :3])) * view.visual.orientation
    return sign * (n * to_eye).sum(axis=-1) >= 0


def check_grid_pick(view, faces, x, y, p, keep=None) -> None:
    """``p`` against the oracle: the faces drawn (:func:`oracle_faces`) of the shown cells
    (``keep``: those the cull keeps)."""
    g = view.grid
    o, d = grid_ray(view, x, y)
    t = oracle_grid_hit(g, faces, o, d, keep)
    if not np.isfinite(t).any():
        assert p is None, (x, y)
        return
    assert p is not None, (x, y)
    assert p.t == pytest.approx(t.min(), abs=1e-9)
    assert t[p.index] <= t.min() + 1e-9, (x, y, p.index)  # the cell hit first (ties allowed)
    hit = o + p.t * d
    m = g.map_transform()
    assert np.allclose(p.world, [*(m[:2, :2] @ hit[:2] + m[:2, 2]), -hit[2]])
    assert p.depth == pytest.approx(hit[2]) and p.depth == pytest.approx(-p.world[2])
    i, j, k = p.index
    assert p.ijk_label == f"I={i + 1} J={j + 1} K={k + 1}"
    assert p.value == g.properties["CELLID"][i, j, k] and p.name == "CELLID"


@pytest.mark.parametrize("exaggeration, camera", [(1.0, {}),
                                                  (4.0, {"azimuth": 200, "elevation": 25})])
def test_grid_pick_is_the_numpy_ray_cell_intersection(ctx, exaggeration, camera):
    g = _grid()
    with geoshade.view(g, property="CELLID", size=SIZE, exaggeration=exaggeration, ctx=ctx,
                       **camera) as v:
        img, _ = v.draw(count=False)
        picks = pick_map(v)
        keys = key_map(picks, lambda p: p.index[0] + 10 * p.index[1] + 100 * p.index[2])
        pixels, edges = pixels_to_check(keys)
        assert edges > 40 and (keys >= 0).sum() > 0.2 * keys.size
        faces = oracle_faces(g, g.active)
        for x, y in pixels:
            check_grid_pick(v, faces, x, y, picks[y, x])
        assert silhouette_agrees(img, picks) == 0
        assert picks[0, 0] is None  # a corner of the picture misses


def _inner_pixel(keys):
    """A pixel whose 5×5 neighbourhood picks one cell, nearest the centre."""
    h, w = keys.shape
    best = None
    for y in range(2, h - 2):
        for x in range(2, w - 2):
            block = keys[y - 2:y + 3, x - 2:x + 3]
            if block[0, 0] >= 0 and (block == block[0, 0]).all():
                dist = (x - w / 2) ** 2 + (y - h / 2) ** 2
                if best is None or dist < best[0]:
                    best = (dist, x, y)
    assert best is not None
    return best[1], best[2]


def test_grid_pick_goes_through_a_filtered_out_cell(ctx):
    g = _grid()
    ids = g.properties["CELLID"]
    with geoshade.view(g, property="CELLID", size=SIZE, ctx=ctx) as v:
        img0, _ = v.draw(count=False)
        keys = key_map(pick_map(v), lambda p: int(p.value))
        x, y = _inner_pixel(keys)
        p0 = v.pick(x, y)
        v.update(filter=f"CELLID != {int(p0.value)}")
        img1, _ = v.draw(count=False)
        p1 = v.pick(x, y)
        check_grid_pick(v, oracle_faces(g, g.active & (ids != p0.value)), x, y, p1)
        assert p1 is None or (p1.index != p0.index and p1.t > p0.t)
        assert not np.array_equal(img0[y, x], img1[y, x])  # the front cell is gone there
        v.update(filter=f"CELLID == {int(p0.value)}")
        img2, _ = v.draw(count=False)
        assert not (img2[y, x, :3] == 255).all()  # the picked cell alone covers the pixel
        assert v.pick(x, y).index == p0.index


def test_grid_pick_respects_slice_plane_and_inactive_cells(ctx):
    g = _grid()
    with geoshade.view(g, property="CELLID", size=SIZE, slice="k=1:4", plane="1,0,0",
                       ctx=ctx) as v:
        img, _ = v.draw(count=False)
        picks = pick_map(v)
        shown = v.shown_mask()
        assert not shown[:, :, 0].any() and shown.sum() < g.active[:, :, 1:].sum()
        keys = key_map(picks, lambda p: int(p.value))
        faces = oracle_faces(g, shown)
        for x, y in pixels_to_check(keys)[0]:
            check_grid_pick(v, faces, x, y, picks[y, x])
        assert silhouette_agrees(img, picks) == 0


@pytest.mark.parametrize("count", [False, True])
def test_grid_pick_looks_through_the_fault_faces_the_view_hides(ctx, count):
    """The fault faces between shown cells are hidden: the rays go in through the gaps and meet
    the far side's faces from behind where the picture draws them (the counting frame draws
    every face) and nothing where it culls them (a frame without the counting pass)."""
    g = _grid()  # cells i >= 3 lie 6 m deeper: the fault's faces show between them
    camera = {"azimuth": 90, "elevation": 12, "zoom": 1.6}  # from the east, onto the fault
    with geoshade.view(g, property="CELLID", size=SIZE, faults="hide", ctx=ctx,
                       **camera) as v:
        img, _ = v.draw(count=count)
        picks = pick_map(v)
        keys = key_map(picks, lambda p: int(p.value))
        faces = oracle_faces(g, g.active, hide_faults=True)
        keep = None if count else oracle_front(v, faces)
        pixels = pixels_to_check(keys, step=3)[0]
        for x, y in pixels:
            check_grid_pick(v, faces, x, y, picks[y, x], keep)
        assert silhouette_agrees(img, picks) == 0
    with geoshade.view(g, property="CELLID", size=SIZE, faults="show", ctx=ctx, **camera) as v:
        v.draw(count=count)
        shown = {(x, y): v.pick(x, y) for x, y in pixels}
    # somewhere the hidden fault faces change what is picked
    assert any((a is None) != (b is None) or (a is not None and a.index != b.index)
               for a, b in ((picks[y, x], shown[x, y]) for x, y in pixels))


def test_grid_pick_reads_expressions_and_report_steps(ctx):
    g = make_grid(nx=5, ny=4, nz=3, steps=3)
    with geoshade.view(g, property="log10(PERMX)", size=SIZE, ctx=ctx) as v:
        v.draw(count=False)
        p = v.pick(*_inner_pixel(key_map(pick_map(v), lambda p: p.index[0] + 10 * p.index[1]
                                                                + 100 * p.index[2])))
        assert p.value == pytest.approx(np.log10(g.properties["PERMX"][p.index]))
        assert p.unit == "log10 mD" and "log10(PERMX)" in p.text()
        v.update(property="SWAT", step=1)
        v.draw(count=False)
        q = v.pick(*p.pixel)
        assert q.index == p.index and q.value == g.steps[1]["SWAT"][p.index]
        assert "step 1" in q.text()


def test_pick_outside_the_picture_and_after_release(ctx):
    g = _grid()
    v = geoshade.view(g, property="CELLID", size=SIZE, ctx=ctx)
    v.draw(count=False)
    for x, y in ((-1, 0), (SIZE[0], 0), (0, SIZE[1])):
        with pytest.raises(InputError, match="outside the 64x48 picture"):
            v.pick(x, y)
    v.release()
    with pytest.raises(InputError, match="after release"):
        v.pick(1, 1)


def test_pick_looks_through_the_camera_of_the_last_draw(ctx):
    g = _grid()
    with geoshade.view(g, property="CELLID", size=SIZE, ctx=ctx) as v:
        before = v.pick(32, 24)  # no draw yet: the options' camera
        v.draw(camera="top", count=False)
        top = v.pick(32, 24)
        assert top.index == v.pick(32, 24, camera="top").index
        assert before.index == v.pick(32, 24, camera="iso").index
        assert top.index[2] == 0 or not g.active[top.index[0], top.index[1], 0]


# --- core ----------------------------------------------------------------------------------------
def voxel_oracle(o, d, lo, hi):
    """(t_in per box, inf where missed): slab test of boxes (n, 3), t in [0, 1]."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (lo - o) / d, (hi - o) / d
    ta = np.where(d == 0, np.where((o >= lo) & (o <= hi), -np.inf, np.inf), ta)
    tb = np.where(d == 0, np.where((o >= lo) & (o <= hi), np.inf, -np.inf), tb)
    t0 = np.maximum(np.minimum(ta, tb).max(axis=1), 0.0)
    t1 = np.minimum(np.maximum(ta, tb).min(axis=1), 1.0)
    return np.where(t0 < t1, t0, np.inf)


def check_core(v, x, y, p, select, box=None):
    vol = v.volume
    a = np.asarray(vol.data)
    x0, y0, z0 = (0, 0, 0) if box is None else box[:3]
    nx, ny, nz = vol.shape_xyz if box is None else box[3:]
    sub = a[z0:z0 + nz, y0:y0 + ny, x0:x0 + nx]
    zz, yy, xx = np.nonzero((sub >= select[0]) & (sub <= select[1]))
    idx = np.stack([xx + x0, yy + y0, zz + z0], 1)
    exag = np.array([1.0, 1.0, v.options.exaggeration])
    sp, og = np.asarray(vol.spacing) * exag, np.asarray(vol.origin) * exag  # as drawn
    o, d = pixel_ray(v, x, y)
    t = voxel_oracle(o, d, og + idx * sp, og + (idx + 1) * sp)
    if not np.isfinite(t).any():
        assert p is None, (x, y)
        return
    assert p is not None, (x, y)
    assert p.t == pytest.approx(t.min(), abs=1e-9)
    hits = {tuple(c) for c in idx[t <= t.min() + 1e-9]}
    assert p.index in hits, (x, y)
    assert p.value == a[p.index[2], p.index[1], p.index[0]]
    assert np.allclose(p.world, (o + p.t * d) / exag)
    assert p.depth == pytest.approx(vol.bounds()[1, 2] - p.world[2])  # below the top face


@pytest.mark.parametrize("exaggeration", [1.0, 2.5])
def test_core_pick_is_the_first_selected_voxel(ctx, exaggeration):
    vol = geoshade.synthetic_core(16, seed=3)
    lo, hi = vol.meta["pore_range"]
    with geoshade.view(vol, select=(lo, hi), size=SIZE, exaggeration=exaggeration,
                       ctx=ctx) as v:
        img, _ = v.draw(count=False)
        picks = pick_map(v)
        keys = key_map(picks, lambda p: p.index[0] + 100 * p.index[1] + 10000 * p.index[2])
        pixels, edges = pixels_to_check(keys)
        assert edges > 40
        for x, y in pixels:
            check_core(v, x, y, picks[y, x], (lo, hi))
        assert silhouette_agrees(img, picks) == 0
        # a narrower selection: what is left is picked, the rays go on behind
        v.update(select=(lo, (lo + hi) / 2))
        v.draw(count=False)
        for x, y in pixels[::3]:
            check_core(v, x, y, v.pick(x, y), (lo, (lo + hi) / 2))
        box = [2, 3, 1, 9, 10, 12]
        v.update(box=box, select=(lo, hi))
        v.draw(count=False)
        for x, y in pixels[::3]:
            check_core(v, x, y, v.pick(x, y), (lo, hi), box)


# --- stacks --------------------------------------------------------------------------------------
def check_stacks(v, x, y, p, exag, hidden=()):
    from geoshade.compute.stacks import stacks_to_voxels
    from geoshade.models.stacks import EMPTY

    m = v.model
    vox = stacks_to_voxels(m)  # (nz, ny, nx) codes
    show = (vox != EMPTY) & ~np.isin(vox, list(hidden))
    zz, yy, xx = np.nonzero(show)
    idx = np.stack([xx, yy, zz], 1).astype(float)
    mm = np.diag([*m.spacing[:2], m.spacing[2] * exag])
    off = np.asarray(m.origin) * np.array([1, 1, exag])
    o, d = pixel_ray(v, x, y)
    t = voxel_oracle(o, d, idx @ mm + off, (idx + 1) @ mm + off)
    if not np.isfinite(t).any():
        assert p is None, (x, y)
        return
    assert p is not None, (x, y)
    assert p.t == pytest.approx(t.min(), abs=1e-7)
    first = t <= t.min() + 1e-7
    assert (p.index[0], p.index[1], p.value) in {(int(a), int(b), int(vox[c, b, a]))
                                                 for a, b, c in zip(xx[first], yy[first],
                                                                    zz[first], strict=True)}
    w = o + p.t * d
    assert np.allclose(p.world, [w[0], w[1], w[2] / exag])  # unexaggerated
    assert p.value not in hidden


def test_stacks_pick_is_the_first_voxel_of_a_shown_material(ctx):
    from geoshade.compute.stacks import synthetic_layers

    m = synthetic_layers(12, 10, 16, max_intervals=5, seed=4, spacing=(2.0, 3.0, 1.0))
    exag = 3.0
    with geoshade.view(m, size=SIZE, exaggeration=exag, ctx=ctx) as v:
        img, _ = v.draw(count=False)
        picks = pick_map(v)
        keys = key_map(picks, lambda p: p.index[0] + 100 * p.index[1] + 10000 * p.value)
        pixels, edges = pixels_to_check(keys)
        assert edges > 40
        for x, y in pixels:
            check_stacks(v, x, y, picks[y, x], exag)
        assert silhouette_agrees(img, picks) == 0
        top = int(np.bincount([p.value for p in picks.ravel() if p is not None]).argmax())
        v.update(hide=[top])
        v.draw(count=False)
        for x, y in pixels[::2]:
            check_stacks(v, x, y, v.pick(x, y), exag, hidden=(top,))
        p = next(p for p in picks.ravel() if p is not None)
        assert "material" in p.text() and p.label.startswith("column x=")


# --- iso -----------------------------------------------------------------------------------------
def check_iso(v, tri_world, x, y, p, exag):
    o, d = pixel_ray(v, x, y)
    t = oracle_ray_triangle(o, d, tri_world)
    if not np.isfinite(t).any():
        assert p is None, (x, y)
        return
    assert p is not None, (x, y)
    assert p.t == pytest.approx(t.min(), abs=1e-6)
    w = o + p.t * d
    assert np.allclose(p.world, [w[0], w[1], w[2] / exag], atol=1e-4)


def test_iso_pick_is_the_first_point_of_the_surface(ctx):
    from geoshade.compute.mesh.displacement import displacement_field
    from geoshade.compute.mesh.marching_cubes import marching_cubes, prepare_values

    f = displacement_field((24, 16, 16), steps=3, seed=0)
    exag = 2.0
    with geoshade.view(f, level=0.5, step=1, size=SIZE, exaggeration=exag, ctx=ctx) as v:
        img, _ = v.draw(count=False)
        tri = marching_cubes(prepare_values(f.step(1), f.active), 0.5).triangles
        m = np.diag([1.0, 1.0, exag, 1.0]) @ f.index_to_world()
        world = tri.astype(float) @ m[:3, :3].T + m[:3, 3]
        picks = pick_map(v)
        keys = key_map(picks, lambda p: p.index[0] + 100 * p.index[1] + 10000 * p.index[2])
        pixels, _ = pixels_to_check(keys, step=3)
        for x, y in pixels[::2]:
            check_iso(v, world, x, y, picks[y, x], exag)
        assert silhouette_agrees(img, picks) == 0
        p = next(p for p in picks.ravel() if p is not None)
        assert p.value == 0.5 and "step 1" in p.text()
        v.update(color_by="PRESSURE")
        v.draw(count=False)
        q = v.pick(*next((x, y) for x, y in pixels if picks[y, x] is not None))
        prop = f.property_step("PRESSURE", 1)
        assert q.name == "PRESSURE" and prop.min() <= q.value <= prop.max()


def test_iso_pick_on_a_corner_point_grid(ctx):
    from geoshade.compute.grid.geometry import cell_centres
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.compute.mesh.marching_cubes import marching_cubes, prepare_values

    g = synthetic_grid(10, 8, 5, steps=3, seed=1)
    exag = 5.0
    with geoshade.view(g, as_="iso", level=0.5, size=SIZE, exaggeration=exag, ctx=ctx) as v:
        img, _ = v.draw(count=False)
        f = v.field
        pos = np.asarray(cell_centres(g), float).transpose(2, 1, 0, 3)
        tri = marching_cubes(prepare_values(f.step(v.step), f.active), 0.5, pos).triangles
        world = tri * np.array([1.0, 1.0, -exag])
        picks = pick_map(v)
        keys = key_map(picks, lambda p: p.index[0] + 100 * p.index[1] + 10000 * p.index[2])
        pixels, _ = pixels_to_check(keys, step=3)
        for x, y in pixels[::2]:
            check_iso(v, world, x, y, picks[y, x], exag)
        assert silhouette_agrees(img, picks) == 0
        p = next(p for p in picks.ravel() if p is not None)
        i, j, k = p.index
        assert p.ijk_label == f"I={i + 1} J={j + 1} K={k + 1}" and p.depth == -p.world[2]


# --- the command line ----------------------------------------------------------------------------
def test_cli_render_pick_prints_and_writes_the_pick(ctx, tmp_path, capsys):
    from geoshade.cli.main import main

    a = np.zeros((8, 8, 8), np.uint8)
    a[2:6, 2:6, 2:6] = 7
    path = tmp_path / "v.npy"
    np.save(path, a)
    out, stats = tmp_path / "o.png", tmp_path / "s.json"
    rc = main(["core", "render", str(path), "--select", "5", "9", "--size", "64x48",
               "--frames", "1", "--view", "top", "--ortho", "-o", str(out), "--stats",
               str(stats), "--pick", "32,24", "--no-annotations"])
    text = capsys.readouterr().out
    assert rc == 0
    s = json.loads(stats.read_text())
    assert s["pick"]["index"][2] == 5 and s["pick"]["value"] == 7
    assert "pick 32,24: voxel x=" in text
    rc = main(["core", "render", str(path), "--size", "64x48", "-o", str(out), "--pick",
               "64,2"])
    assert rc != 0 and "--pick: pixel 64,2 is outside the 64x48 picture" in \
        capsys.readouterr().err


def test_core_pick_skips_the_air_around_a_detected_sample(ctx):
    """A core in air drawn with its detected sample (the default): a pick through the air at
    the picture's corner finds nothing, one through the centre lands inside the footprint."""
    from tests.compute.test_roi import core_in_air

    vol, _ = core_in_air(40, seed=4)
    lo, hi = int(np.asarray(vol.data).min()), int(np.asarray(vol.data).max())
    with geoshade.view(vol, select=(lo, hi), view="top", ortho=True, size=(80, 80),
                       annotations=False) as v:
        roi = v.options.roi
        assert roi is not None and roi.kind == "sample"
        v.draw(frames=1)
        assert v.pick(1, 1) is None                      # air only: nothing drawn there
        hit = v.pick(40, 40)
        assert hit is not None
        x, y, z = hit.index   # voxel (x, y, z) in the volume
        assert roi.contains(np.array([x]), np.array([y]), np.array([z]))[0]
