"""Camera framing and the strict shader preprocessor."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.render.camera import VIEWS, Camera
from geoshade.render.shaders import ShaderError, load_program, preprocess

BOUNDS = np.array([[10.0, 20.0, -5.0], [30.0, 25.0, 5.0]])


def ndc(cam: Camera, pts):
    m = cam.projection_matrix() @ cam.view_matrix()
    h = np.c_[pts, np.ones(len(pts))] @ m.T
    return h[:, :3] / h[:, 3:]


def corners(b):
    return np.array([[b[i, 0], b[j, 1], b[k, 2]] for i in (0, 1) for j in (0, 1) for k in (0, 1)])


@pytest.mark.parametrize("view", sorted(VIEWS))
@pytest.mark.parametrize("ortho", [False, True])
def test_framing_shows_the_whole_box(view, ortho):
    cam = Camera.framed(BOUNDS, view=view, ortho=ortho, aspect=4 / 3)
    p = ndc(cam, corners(BOUNDS))
    assert np.all(np.abs(p) <= 1.0 + 1e-9)
    if ortho:  # tight: the box touches the frame on one axis
        assert np.abs(p[:, :2]).max() > 0.95


def test_named_view_directions():
    d = {v: Camera.framed(BOUNDS, view=v).direction for v in VIEWS}
    np.testing.assert_allclose(d["top"], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(d["bottom"], [0, 0, -1], atol=1e-12)
    np.testing.assert_allclose(d["front"], [0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(d["back"], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(d["left"], [-1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(d["right"], [1, 0, 0], atol=1e-12)
    # top view: +x to the right, +y up on screen
    cam = Camera.framed(BOUNDS, view="top", ortho=True)
    p = ndc(cam, np.array([[20.0, 22.5, 0], [21.0, 22.5, 0], [20.0, 23.5, 0]]))
    assert p[1, 0] > p[0, 0] and p[2, 1] > p[0, 1]


def test_orbit_zoom_pan():
    cam = Camera.framed(BOUNDS, view="iso")
    assert cam.orbit(10, 100).elevation == 90.0
    assert cam.zoomed(2).distance == pytest.approx(cam.distance / 2)
    moved = cam.panned(0.5, 0)
    assert np.linalg.norm(moved.target - cam.target) > 0
    assert moved.distance == cam.distance
    o = Camera.framed(BOUNDS, view="iso", ortho=True)
    assert o.zoomed(2).half_height == pytest.approx(o.half_height / 2)


def test_framing_depends_on_bounds_only():
    a = Camera.framed(BOUNDS, view="iso", ortho=True)
    b = Camera.framed(BOUNDS.copy(), view="iso", ortho=True)
    np.testing.assert_array_equal(a.view_matrix(), b.view_matrix())


def test_bad_camera_arguments():
    with pytest.raises(InputError, match="unknown view"):
        Camera.framed(BOUNDS, view="diagonal")
    with pytest.raises(InputError, match="zoom"):
        Camera.framed(BOUNDS, zoom=0)
    with pytest.raises(InputError, match="elevation"):
        Camera.framed(BOUNDS, elevation=120)


PKG = "geoshade.render.visuals.voxels"


def test_preprocessor_includes_defines_and_lines():
    src = preprocess(PKG, "trefoil.geom", {"TREFOIL_S": "int[80](0)", "TREFOIL_N": "int[80](0)",
                                           "BITS_PER_WORD": 32, "UNIT_BITS": 0, "UNIT_COLOR": 2,
                                           "UNIT_PALETTE": 3})
    lines = src.text.splitlines()
    assert lines[0].startswith("#version")
    assert "#define BITS_PER_WORD 32" in lines
    assert any(ln.startswith("#line 1 1") for ln in lines)  # the include is file 1
    assert src.files == ["trefoil.geom", "voxel_common.glsl"]


def test_unknown_or_missing_define_is_an_error():
    with pytest.raises(ShaderError, match="unknown define"):
        preprocess(PKG, "points.vert", {"NOT_DECLARED": 1})
    with pytest.raises(ShaderError, match="declared but not given"):
        preprocess(PKG, "trefoil.vert", {})
    with pytest.raises(ShaderError, match="not found"):
        preprocess(PKG, "nope.frag", {})


def test_compile_error_points_at_file_and_line(ctx, tmp_path, monkeypatch):
    from geoshade.render import shaders

    files = {"bad.frag": "#version 430 core\n#include \"phong.glsl\"\nout vec4 f;\n"
                         "void main() { f = undefined_thing; }\n"}
    real = shaders._read
    monkeypatch.setattr(shaders, "_read",
                        lambda pkg, name: files.get(name) if pkg == "x.y" and name in files
                        else real(pkg, name))
    with pytest.raises(ShaderError) as err:
        load_program(ctx, "x.y", {"vert": "bad.frag", "frag": "bad.frag"})
    assert "bad.frag:4" in str(err.value)
    _ = ctx.error
