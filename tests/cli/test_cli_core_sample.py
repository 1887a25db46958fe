"""The command line never decides a porosity silently: a label image's --select auto is refused in
one line, info names its labels, a sample in air is counted without its air (one warning line),
and what was decided is printed, written to the JSON and drawn on the plot and the picture."""

from __future__ import annotations

import json

import numpy as np
import pytest

from geoshade.cli.main import main
from tests.compute.test_sample import sample_in_air

pytest.importorskip("skimage.filters")


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture
def label_raw(tmp_path):
    a = np.zeros((20, 20, 20), np.uint8)
    a.reshape(-1)[: int(0.136 * a.size)] = 255  # 13.6 % pore label 255
    np.random.default_rng(2).shuffle(a.reshape(-1))
    f = tmp_path / "IMG.raw"
    a.tofile(f)
    return f, a


@pytest.fixture
def air_raw(tmp_path):
    vol, sample, pores = sample_in_air()
    f = tmp_path / "air.raw"
    np.asarray(vol.data).tofile(f)
    return f, ("--shape", 64, 60, 40, "--dtype", "uint16"), sample, pores


def test_label_image_auto_is_refused_in_one_line(capsys, tmp_path, label_raw):
    f, a = label_raw
    frac = np.count_nonzero(a == 255) / a.size
    rc, _, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--select", "auto",
                     "-o", tmp_path / "p.png")
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert err.strip() == (f"geoshade: error: IMG.raw: select auto: a label image "
                           f"(0: {100 * (1 - frac):.1f} %, 255: {100 * frac:.1f} %) — which "
                           "value is pore? use --select 255 255 or --select 0 0")
    assert not (tmp_path / "p.png").exists()
    # the answer the user gives: the pore label's fraction
    js = tmp_path / "p.json"
    rc, text, err = run(capsys, "core", "porosity", f, "--dtype", "uint8", "--select", 255, 255,
                        "-o", tmp_path / "p.png", "--json", js)
    assert rc == 0, err
    d = json.loads(js.read_text())
    assert d["porosity"] == frac and d["sample"]["status"] == "label image"
    assert "a label image: no air detected, every voxel of the box counts" in text
    # info names the labels and never calls one of them the pore space
    rc, text, err = run(capsys, "info", f, "--dtype", "uint8")
    assert rc == 0, err
    assert (f"labels   0: {100 * (1 - frac):.1f} %, 255: {100 * frac:.1f} % (a label image: "
            "which value is pore? --select 255 255 or --select 0 0)") in text
    assert "pore space" not in text and "pores    --select" not in text
    rc, text, _ = run(capsys, "info", f, "--dtype", "uint8", "--json")
    th = json.loads(text)["threshold"]
    assert th["pore_select"] is None and [e["value"] for e in th["labels"]] == [0.0, 255.0]
    # core render refuses it the same way
    rc, _, err = run(capsys, "core", "render", f, "--dtype", "uint8", "--select", "auto",
                     "-o", tmp_path / "r.png")
    assert rc == 2 and "which value is pore?" in err and len(err.strip().splitlines()) == 1


def test_sample_in_air_counted_without_its_air(capsys, tmp_path, air_raw, monkeypatch):
    from matplotlib.figure import Figure

    titles = []
    save = Figure.savefig
    monkeypatch.setattr(Figure, "savefig", lambda self, *a, **k: (
        titles.append(self.axes[0].get_title()), save(self, *a, **k))[1])
    f, hints, sample, pores = air_raw
    js = tmp_path / "p.json"
    rc, text, err = run(capsys, "core", "porosity", f, *hints, "--select", "auto",
                        "-o", tmp_path / "p.png", "--json", js)
    assert rc == 0, err
    d = json.loads(js.read_text())
    assert d["porosity"] == pores.sum() / sample.sum() and d["total"] == sample.sum()
    lines = text.strip().splitlines()
    assert lines[0].startswith(f"porosity {d['porosity']:.4f} ({d['count']:,} of "
                               f"{d['total']:,} voxels of the sample in [")
    assert lines[1:] == ["  " + n for n in d["notes"]]
    assert d["notes"][0] == d["select_auto"]["text"]
    assert d["notes"][0].startswith(f"dark phase ≤ Otsu {d['select_auto']['threshold']:,.6g} "
                                    "taken as pore (pores hold air")
    # one warning line with the fraction, the same number in the JSON
    warn = [w for w in err.splitlines() if w.startswith("geoshade: warning:")]
    assert warn == [f"geoshade: warning: air.raw: {100 * d['outside_fraction']:.1f} % of the "
                    "selected voxels lie outside the detected sample (air); they are not "
                    "counted (--sample none counts them)"]
    # the plot's title carries the same notes
    for n in d["notes"]:
        assert n.split(" (")[0] in titles[-1].replace("\n", " ")
    # --sample none: every voxel of the box, the air too
    rc, _, err = run(capsys, "core", "porosity", f, *hints, "--select", "auto", "--sample",
                     "none", "-o", tmp_path / "p.png", "--json", js)
    assert rc == 0 and "warning" not in err
    d2 = json.loads(js.read_text())
    assert d2["total"] == 64 * 60 * 40 and d2["porosity"] > 10 * d["porosity"]
    # --roi sample: the detected sample as an ROI, the same count
    rc, _, err = run(capsys, "core", "porosity", f, *hints, "--select", "auto", "--roi",
                     "sample", "-o", tmp_path / "p.png", "--json", js)
    assert rc == 0 and "warning" not in err
    d3 = json.loads(js.read_text())
    assert (d3["count"], d3["total"]) == (d["count"], d["total"])
    assert d3["roi"]["kind"] == "sample" and d3["select"] == d["select"]


@pytest.mark.gl
def test_the_picture_repeats_what_the_cli_says(capsys, tmp_path, air_raw):
    import textwrap

    f, hints, _, _ = air_raw
    js, st = tmp_path / "p.json", tmp_path / "s.json"
    rc, _, err = run(capsys, "core", "porosity", f, *hints, "--select", "auto", "-o",
                     tmp_path / "p.png", "--json", js)
    assert rc == 0, err
    d = json.loads(js.read_text())
    import geoshade

    vol = geoshade.load(f, shape=(64, 60, 40), dtype="uint16")
    with geoshade.view(vol, select="auto", porosity="z", size=(1024, 768)) as view:
        _, stats = view.draw(frames=1)
        _, subtitle = view._title(stats)
    lines = subtitle.splitlines()
    # the View draws the detected sample by default (drawn = counted): the same number
    assert f"porosity {d['porosity']:.4f}" in lines[0] and "sample" in lines[0]
    assert lines[1:] == [textwrap.shorten(n, 110, placeholder="…") for n in d["notes"]]
    rc, _, err = run(capsys, "core", "render", f, *hints, "--select", "auto", "--roi", "sample",
                     "-o", tmp_path / "r.png", "--size", "320x240", "--stats", st)
    assert rc == 0, err
    assert json.loads(st.read_text())["voxels_selected"] == d["count"]  # drawn = counted
