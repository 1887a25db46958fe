"""Hidden-voxel culling references and the trefoil tables."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from geoshade.compute.voxels.visibility import (
    CUBE_CORNERS,
    FACE_NORMALS,
    exposed_mask,
    paper_normal_tables,
    strip_triangles,
    trefoil_tables,
    trefoil_variant,
    view_signs_from_modelview,
    visible_faces,
    visible_mask,
)
from geoshade.errors import InputError


def _brute_visible(sel, eye=None, signs=None):
    nz, ny, nx = sel.shape
    out = np.zeros_like(sel)

    def on(x, y, z):
        return 0 <= x < nx and 0 <= y < ny and 0 <= z < nz and bool(sel[z, y, x])

    for z, y, x in itertools.product(range(nz), range(ny), range(nx)):
        if not sel[z, y, x]:
            continue
        if eye is not None:
            d = [1 if eye[p] >= c + 0.5 else -1 for p, c in enumerate((x, y, z))]
        else:
            d = [1 if s else -1 for s in signs]
        hidden = on(x + d[0], y, z) and on(x, y + d[1], z) and on(x, y, z + d[2])
        out[z, y, x] = not hidden
    return out


def _brute_exposed(sel):
    nz, ny, nx = sel.shape
    out = np.zeros_like(sel)
    for z, y, x in itertools.product(range(nz), range(ny), range(nx)):
        if not sel[z, y, x]:
            continue
        nb = [
            (x + 1, y, z),
            (x - 1, y, z),
            (x, y + 1, z),
            (x, y - 1, z),
            (x, y, z + 1),
            (x, y, z - 1),
        ]
        out[z, y, x] = not all(
            0 <= a < nx and 0 <= b < ny and 0 <= c < nz and sel[c, b, a] for a, b, c in nb
        )
    return out


@pytest.mark.parametrize("density", [0.5, 0.8, 1.0])
def test_visible_mask_vs_brute_force(density):
    rng = np.random.default_rng(int(density * 10))
    sel = rng.random((5, 6, 7)) < density  # (nz, ny, nx): x 0..7, y 0..6, z 0..5
    eyes = [
        (30.0, 40.0, 50.0),
        (-10.0, -3.0, -8.0),
        (3.5, 2.0, 2.5),  # inside the box, on voxel centres and on faces
        (3.2, 2.9, -1.0),
        (0.5, 6.0, 5.0),
        (7.0, 0.0, 2.49),
        (np.inf, -np.inf, 1.5),
    ]
    for eye in eyes:
        np.testing.assert_array_equal(
            visible_mask(sel, eye_ijk=eye), _brute_visible(sel, eye=eye), err_msg=str(eye)
        )
    for signs in itertools.product([False, True], repeat=3):
        np.testing.assert_array_equal(
            visible_mask(sel, view_signs=signs), _brute_visible(sel, signs=signs)
        )


def test_visible_mask_arguments():
    sel = np.ones((2, 2, 2), bool)
    with pytest.raises(InputError, match="exactly one"):
        visible_mask(sel)
    with pytest.raises(InputError, match="exactly one"):
        visible_mask(sel, eye_ijk=(0, 0, 0), view_signs=(1, 1, 1))
    with pytest.raises(InputError, match="eye_ijk"):
        visible_mask(sel, eye_ijk=(0, 0))
    with pytest.raises(InputError, match="3D"):
        visible_mask(np.ones((2, 2)), view_signs=(1, 1, 1))
    # a visible voxel is always selected; a single voxel is never hidden
    one = np.zeros((3, 3, 3), bool)
    one[1, 1, 1] = True
    assert visible_mask(one, eye_ijk=(1.5, 1.5, 1.5)).sum() == 1


def test_exposed_mask_vs_brute_force():
    rng = np.random.default_rng(5)
    for shape in [(5, 6, 7), (1, 4, 4), (2, 2, 2), (3, 1, 5)]:
        sel = rng.random(shape) < 0.7
        np.testing.assert_array_equal(exposed_mask(sel), _brute_exposed(sel))
    full = np.ones((4, 5, 6), bool)
    assert exposed_mask(full).sum() == 4 * 5 * 6 - 2 * 3 * 4


def test_exposed_contains_visible():
    sel = np.random.default_rng(8).random((6, 6, 6)) < 0.6
    ex = exposed_mask(sel)
    for signs in itertools.product([False, True], repeat=3):
        vis = visible_mask(sel, view_signs=signs)
        assert not (vis & ~ex).any()


def test_strips_are_printed_ones():
    S, N = trefoil_tables()
    assert S.shape == N.shape == (8, 10)
    assert S.tolist() == [
        [5, 4, 1, 0, 3, 2, 2, 0, 6, 4],
        [4, 0, 5, 1, 7, 3, 3, 1, 2, 0],
        [1, 0, 3, 2, 7, 6, 6, 2, 4, 0],
        [5, 1, 7, 3, 6, 2, 2, 3, 0, 1],
        [1, 5, 0, 4, 2, 6, 6, 4, 7, 5],
        [0, 1, 4, 5, 6, 7, 7, 5, 3, 1],
        [0, 4, 2, 6, 3, 7, 7, 6, 5, 4],
        [4, 5, 6, 7, 2, 3, 3, 7, 1, 5],
    ]
    assert (N[:, :2] == -1).all()


@pytest.mark.parametrize("t", range(8))
def test_each_strip_covers_the_visible_faces_ccw(t):
    S, N = trefoil_tables()
    tris = strip_triangles(S[t])
    faces_seen = {}
    degenerate = 0
    for g, tri in enumerate(tris):
        if len(set(tri.tolist())) < 3:
            degenerate += 1
            assert N[t, g + 2] == -1
            continue
        face = int(N[t, g + 2])
        assert face >= 0
        a, b, c = CUBE_CORNERS[tri].astype(float)
        normal = np.cross(b - a, c - a)
        # counter-clockwise seen from outside: the right-hand normal is the outward normal
        np.testing.assert_array_equal(normal, FACE_NORMALS[face])
        faces_seen.setdefault(face, set()).update(tri.tolist())
    assert degenerate == 2
    assert set(faces_seen) == set(visible_faces(t))
    for face, verts in faces_seen.items():  # two triangles covering all four corners
        p, sign = face % 3, 1 if face < 3 else 0
        assert verts == {v for v in range(8) if CUBE_CORNERS[v, p] == sign}
        assert sum(1 for g in range(8) if N[t, g + 2] == face) == 2


def test_derived_normals_differ_from_paper_except_t7():
    _, N = trefoil_tables()
    P = paper_normal_tables()
    assert P.shape == (8, 10)
    assert P[0].tolist() == [-1, -1, 4, 4, 0, 0, 0, 0, 5, 5]
    for t in range(8):
        real = N[t] >= 0  # entries of non-degenerate triangles
        agree = bool((N[t][real] == P[t][real]).all())
        assert agree == (t == 7), t


def test_variant_helpers():
    assert trefoil_variant((True, True, False)) == 3
    assert visible_faces(5) == (0, 4, 2)
    with pytest.raises(InputError):
        visible_faces(8)
    # an iso view from (+x, +y, +z): all positive faces face the eye
    eye = np.array([1.0, 1.0, 1.0]) / np.sqrt(3)
    f = eye
    r = np.cross([0.0, 0.0, 1.0], f)
    r /= np.linalg.norm(r)
    u = np.cross(f, r)
    view = np.stack([r, u, f])  # rows: view-space axes; camera looks down -f
    assert view_signs_from_modelview(view) == (True, True, True)
    assert view_signs_from_modelview(-view) == (False, False, False)
