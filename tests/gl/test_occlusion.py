"""Ambient occlusion and depth cue over a core picture (``render/visuals/ambient``): on by
default for one solid colour, off for a colour map; flat faces and the background untouched,
creases darker, far surfaces dimmer; the same for every method; checked before GL; released."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.errors import InputError
from geoshade.models import VoxelVolume
from geoshade.testing.views import RecordingContext

SIZE = (160, 160)


def trench_volume() -> VoxelVolume:
    """A 24 × 24 × 8 slab of value 1 with a 4-voxel-wide, 4-deep trench along y in the middle."""
    v = np.ones((8, 24, 24), np.uint8)   # (z, y, x)
    v[4:, :, 10:14] = 0
    return VoxelVolume(v)


def stairs_volume() -> VoxelVolume:
    """Four 6-voxel-wide steps along x, 2, 4, 6, 8 voxels high."""
    v = np.zeros((8, 8, 24), np.uint8)   # (z, y, x)
    for s in range(4):
        v[: 2 * (s + 1), :, 6 * s:6 * s + 6] = 1
    return VoxelVolume(v)


def top(vol, ctx, **kw):
    with geoshade.view(vol, select=(1, 1), size=SIZE, ctx=ctx, view="top", ortho=True,
                       **kw) as v:
        cam = v.camera()
        return v.draw(cam), cam


def test_one_solid_colour_gets_occlusion_and_a_colour_map_does_not(ctx):
    vol = trench_volume()
    (_, st_solid), _ = top(vol, ctx)
    assert st_solid["occlusion"] == {"strength": 0.7, "radius": 3.0, "depth_cue": 0.3}
    with geoshade.view(vol, select=(0, 1), size=SIZE, ctx=ctx) as v:
        _, st_map = v.draw()
    assert "occlusion" not in st_map
    with geoshade.view(vol, select=(0, 1), size=SIZE, ctx=ctx, occlusion=True) as v:
        _, st_on = v.draw()
    assert st_on["occlusion"]["strength"] == 0.7   # asked for: on for a colour map too


def test_flat_faces_and_background_are_untouched_and_the_trench_darkens(ctx):
    vol = trench_volume()
    (bare, _), _ = top(vol, ctx, occlusion=False)
    (ao, st), _ = top(vol, ctx, occlusion={"depth_cue": 0.0})
    assert st["occlusion"]["depth_cue"] == 0.0
    lum0, lum1 = bare[..., :3].astype(int).sum(-1), ao[..., :3].astype(int).sum(-1)
    background = (bare[..., :3] == 255).all(-1)
    np.testing.assert_array_equal(ao[background], bare[background])
    # columns of the picture: x of the model runs left to right in a top view
    cols = np.flatnonzero((~background).any(0))
    x0, x1 = cols[0], cols[-1] + 1
    px = (x1 - x0) / 24                     # pixels per voxel
    rows = slice(int(np.flatnonzero((~background).any(1))[0] + 2 * px),
                 int(np.flatnonzero((~background).any(1))[-1] - 2 * px))
    far_left = slice(int(x0 + 1 * px), int(x0 + 5 * px))     # the top face, 5+ voxels away
    floor_edge = slice(int(x0 + 10 * px + 1), int(x0 + 11 * px))   # trench floor by its wall
    np.testing.assert_array_equal(ao[rows, far_left], bare[rows, far_left])
    assert (lum1[rows, floor_edge] < lum0[rows, floor_edge] - 30).all()


def test_the_depth_cue_dims_the_lower_steps(ctx):
    vol = stairs_volume()
    (bare, _), _ = top(vol, ctx, occlusion=False)
    (cue, _), _ = top(vol, ctx, occlusion={"strength": 0.0, "depth_cue": 0.5})
    background = (bare[..., :3] == 255).all(-1)
    cols = np.flatnonzero((~background).any(0))
    x0, px = cols[0], (cols[-1] + 1 - cols[0]) / 24
    row = int(np.flatnonzero((~background).any(1)).mean())
    ratio = [cue[row, int(x0 + (6 * s + 3) * px), :3].astype(float).sum()
             / bare[row, int(x0 + (6 * s + 3) * px), :3].astype(float).sum() for s in range(4)]
    # step s is 8 - 2(s + 1) voxels below the model's top (the nearest point) of 8 in all,
    # the model's bottom being the farthest: it dims by 0.5 of that fraction
    want = [1 - 0.5 * (8 - 2 * (s + 1)) / 8 for s in range(4)]
    assert ratio == pytest.approx(want, abs=0.02)


def test_the_pass_is_the_same_for_every_method(ctx):
    """Raycast and instanced cubes draw the same voxels and depths, so they agree with
    occlusion as they do without it."""
    vol = trench_volume()
    diff = {}
    for occ in (False, True):
        imgs = []
        for method in ("raycast", "cubes"):
            with geoshade.view(vol, select=(1, 1), size=SIZE, ctx=ctx, method=method,
                               occlusion=occ) as v:
                imgs.append(v.draw(v.camera())[0].astype(int))
        diff[occ] = float((np.abs(imgs[0] - imgs[1]).max(-1) > 12).mean())
    assert diff[True] <= diff[False] + 0.01


@pytest.mark.parametrize(("value", "msg"), [
    ({"strength": 2}, r"occlusion strength: expected a number in 0\.\.1, got 2"),
    ({"radius": -1}, r"occlusion radius: expected a positive length, got -1"),
    ({"blur": 1}, r"occlusion: unknown field\(s\) \['blur'\]"),
    ("maybe", r"occlusion: expected"),
])
def test_bad_occlusion_is_one_line_before_gl(value, msg):
    with pytest.raises(InputError, match=msg):
        geoshade.view(trench_volume(), select=(1, 1), occlusion=value, ctx=object())


def test_the_pass_is_released(ctx):
    rec = RecordingContext(ctx)
    v = geoshade.view(trench_volume(), select=(1, 1), size=SIZE, ctx=rec)
    v.draw()
    v.update(select=(0, 1))
    v.draw()
    v.release()
    assert rec.alive() == []


def test_cli_colour_and_occlusion_flags(ctx, capsys, tmp_path):
    import json

    from geoshade.cli.main import main

    path = tmp_path / "trench.npy"
    np.save(path, np.asarray(trench_volume().data))
    runs = {"auto": [], "off": ["--no-occlusion"], "solid": ["--solid-color", "0.2,0.4,0.8"],
            "reverse": ["--select", "0", "1", "--colormap", "magma", "--reverse"]}
    stats = {}
    for name, flags in runs.items():
        out, js = tmp_path / f"{name}.png", tmp_path / f"{name}.json"
        args = ["core", "render", str(path), "--size", "160x160", "-o", str(out),
                "--stats", str(js)]
        if name != "reverse":
            args += ["--select", "1", "1"]
        assert main([*args, *flags]) == 0, capsys.readouterr().err
        stats[name] = json.loads(js.read_text())
    assert "occlusion" in stats["auto"] and "occlusion" not in stats["off"]
    assert "occlusion" in stats["solid"] and "occlusion" not in stats["reverse"]
    from geoshade.styles.options import ColorStyle

    fwd = ColorStyle(colormap="magma").palette_rgba()
    rev = ColorStyle(colormap="magma", reverse=True).palette_rgba()
    np.testing.assert_array_equal(rev, fwd[::-1])
