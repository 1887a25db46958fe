"""StackModel, Legend and BoreholeLogs: the layout's contracts and their one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.models import BoreholeLogs, Legend, StackModel
from geoshade.models.stacks import EMPTY


def small() -> StackModel:
    # column 0: [0,2) code 1, [2,5) code 2, air above; column 1 empty; column 2: [3,6) code 1
    return StackModel(offsets=[0, 3, 3, 4], starts=[0, 2, 5, 3], codes=[1, 2, EMPTY, 1],
                      shape=(3, 1), nlevels=6)


def test_sizes_ends_tops_and_bounds():
    m = small()
    assert (m.ncols, m.nintervals, m.max_intervals) == (3, 4, 3)
    assert m.counts().tolist() == [3, 0, 1]
    assert m.ends().tolist() == [2, 5, 6, 6]
    assert m.column_tops().tolist() == [5, 0, 6]
    assert m.occupied_levels() == (0.0, 6.0)
    assert m.column_ids().tolist() == [0, 0, 0, 2]
    assert m.bounds().tolist() == [[0, 0, 0], [3, 1, 6]]
    assert m.legend.codes.tolist() == [1, 2]


@pytest.mark.parametrize("starts, what", [
    ([0, 2, 2, 3], "non-monotonic or overlapping"),      # equal starts in column 0
    ([0, 4, 3, 3], "non-monotonic or overlapping"),      # decreasing
    ([0, 2, 6, 3], "outside [0, 6)"),                    # at the top
    ([-1, 2, 5, 3], "outside [0, 6)"),
])
def test_bad_starts_are_one_line_errors_naming_the_column(starts, what):
    with pytest.raises(InputError) as e:
        StackModel([0, 3, 3, 4], starts, [1, 2, EMPTY, 1], (3, 1), 6, name="m.stacks.npz")
    msg = str(e.value)
    assert what in msg and "column 0 (x 0, y 0)" in msg and msg.startswith("m.stacks.npz: ")
    assert "\n" not in msg


@pytest.mark.parametrize("kw, what", [
    ({"offsets": [0, 3, 3]}, "offsets: expected (4,)"),
    ({"offsets": [0, 3, 2, 4]}, "offsets: expected 0 ="),
    ({"codes": [1, 2, EMPTY]}, "starts, codes"),
    ({"codes": [1.5, 2, EMPTY, 1]}, "integer material codes"),
    ({"shape": (0, 1)}, "shape"),
    ({"nlevels": 0}, "nlevels"),
    ({"borehole": [True]}, "borehole"),
    ({"spacing": (1, 0, 1)}, "spacing"),
    ({"legend": Legend.from_codes([1])}, "not in the legend"),
])
def test_contract_errors(kw, what):
    args = {"offsets": [0, 3, 3, 4], "starts": [0, 2, 5, 3], "codes": [1, 2, EMPTY, 1],
            "shape": (3, 1), "nlevels": 6, **kw}
    with pytest.raises(InputError, match=None) as e:
        StackModel(**args)
    assert what in str(e.value)


def test_from_layers_gaps_air_and_order():
    m = StackModel.from_layers((2, 2), 10, column=[3, 3, 0], bottom=[5, 1, 0], top=[7, 4, 10],
                               code=[2, 1, 3])
    assert m.offsets.tolist() == [0, 1, 1, 1, 5]
    assert m.starts.tolist() == [0, 1, 4, 5, 7]
    assert m.codes.tolist() == [3, 1, EMPTY, 2, EMPTY]


@pytest.mark.parametrize("bottom, top, what", [
    ([0, 3], [4, 6], "overlapping"),
    ([0, 5], [4, 5], "non-monotonic"),
    ([0, 5], [4, 11], "outside [0, 10]"),
])
def test_from_layers_rejects_overlap_and_inversion(bottom, top, what):
    with pytest.raises(InputError) as e:
        StackModel.from_layers((1, 1), 10, [0, 0], bottom, top, [1, 2])
    assert what in str(e.value)


def test_canonical_merges_equal_neighbours_only_inside_a_column():
    m = StackModel([0, 3, 4], [0, 2, 4, 0], [5, 5, 6, 6], (2, 1), 8).canonical()
    assert m.codes.tolist() == [5, 6, 6] and m.starts.tolist() == [0, 4, 0]
    assert m.offsets.tolist() == [0, 2, 3]


def test_replace_columns_flags_boreholes_and_merges_legends():
    a = small()
    b = StackModel.from_layers((3, 1), 6, [1], [1], [3], [9], legend=Legend.from_codes([9]))
    m = a.replace_columns([1], b, flag_boreholes=True, log_base=[1.0])
    assert m.borehole.tolist() == [False, True, False]
    assert m.codes[m.offsets[1]:m.offsets[2]].tolist() == [9, EMPTY]
    assert m.legend.codes.tolist() == [1, 2, 9]
    assert m.log_intervals().tolist() == [False, False, False, True, True, False]
    assert m.log_base.tolist() == [0.0, 1.0, 0.0]


def test_legend_checks_and_lookup():
    lg = Legend([5, 1], ("five", "one"), [[5, 5, 5, 255], [1, 1, 1, 255]])
    assert lg.codes.tolist() == [1, 5] and lg.names == ("one", "five")
    assert lg.index_of(np.array([5, EMPTY, 1])).tolist() == [2, 0, 1]
    assert lg.name_of(5) == "five"
    with pytest.raises(InputError, match="appears twice"):
        Legend([1, 1], ("a", "b"), np.zeros((2, 4)))
    with pytest.raises(InputError, match="reserved"):
        Legend([EMPTY], ("a",), np.zeros((1, 4)))
    with pytest.raises(InputError, match="not in the legend"):
        lg.index_of(np.array([7]))
    auto = Legend.from_codes([3, 3, 8, EMPTY])
    assert auto.codes.tolist() == [3, 8] and len({tuple(c) for c in auto.rgba}) == 2


def test_borehole_logs_contract():
    logs = BoreholeLogs(["a", "a", "b"], [0, 0, 1], [0, 0, 1], [0, -1, 0], [-1, -2, -3],
                        [1, 2, 1])
    assert (logs.nboreholes, len(logs)) == (2, 3)
    with pytest.raises(InputError, match="NaN"):
        BoreholeLogs(["a"], [np.nan], [0], [0], [-1], [1])
    with pytest.raises(InputError, match="expected 1 values"):
        BoreholeLogs(["a"], [0, 1], [0], [0], [-1], [1])
