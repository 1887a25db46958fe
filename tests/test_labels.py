"""Label placement (styles/labels.py): the boxes it reserves are the boxes annotate draws, so
no two drawn labels overlap; crowded labels are moved near their point or hidden and counted."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from geoshade.styles.annotate import Annotations, Label, annotate
from geoshade.styles.labels import first_inside, place_labels, text_sizes


def _overlapping(boxes) -> int:
    return sum(ax < bx + bw and bx < ax + aw and ay < by + bh and by < ay + ah
               for (ax, ay, aw, ah), (bx, by, bw, bh) in combinations(boxes, 2))


@pytest.mark.parametrize("size", [(640, 480), (1920, 1080)])
def test_reserved_boxes_are_the_drawn_ones(size):
    w, h = size
    rng = np.random.default_rng(1)
    names = [f"WELL_{n:02d}" if n % 3 else f"P{n}" for n in range(40)]
    labels = [Label(t, float(x), float(y)) for t, x, y in
              zip(names, rng.uniform(0.4, 0.5, 40) * w, rng.uniform(0.4, 0.5, 40) * h,
                  strict=True)]
    p = place_labels(labels, size)
    _, layout = annotate(np.zeros((h, w, 4), np.uint8), Annotations(labels=p.labels))
    drawn = layout["labels"]
    assert [d["text"] for d in drawn] == [lab.text for lab in p.labels]
    np.testing.assert_allclose([d["bbox"] for d in drawn], p.boxes, atol=0.11)
    assert _overlapping([d["bbox"] for d in drawn]) == 0
    assert len(p.labels) + len(p.hidden) == 40 and p.hidden and p.moved
    assert set(p.hidden).isdisjoint(lab.text for lab in p.labels)


def test_free_labels_stay_and_crowded_ones_stay_near():
    lone = [Label("A", 100, 100), Label("B", 400, 300)]
    p = place_labels(lone, (640, 480))
    assert p.labels == tuple(lone) and p.moved == 0 and p.note() == ""
    pair = [Label("OP_1", 200, 200), Label("OP_2", 203, 201)]
    q = place_labels(pair, (640, 480))
    assert q.labels[0] == pair[0] and q.moved == 1 and not q.hidden
    bw, bh = text_sizes(["OP_2"], 480)[0]
    moved = q.labels[1]
    assert abs(moved.x - 203) <= bw + 10 and abs(moved.y - 201) <= 3 * bh


def test_outside_points_are_dropped_not_hidden():
    p = place_labels([Label("OUT", -5, 10), Label("IN", 50, 50)], (100, 100))
    assert [lab.text for lab in p.labels] == ["IN"] and p.hidden == ()


def test_first_inside_clips_segments():
    rect = (0, 20, 100, 100)
    assert first_inside(np.array([[10.0, 50]]), rect) == (10.0, 50.0)
    assert first_inside(np.array([[-50.0, 50], [50, 50]]), rect) == (0.0, 50.0)
    assert first_inside(np.array([[np.nan, np.nan], [150.0, 0], [50, 60]]), rect) == \
        pytest.approx((100.0, 30.0))
    nan_gap = np.array([[50.0, -10], [np.nan, np.nan], [50, 30]])
    assert first_inside(nan_gap, rect) == (50.0, 30.0)
    assert first_inside(np.array([[200.0, 50], [300, 60]]), rect) is None
