"""JSON has no NaN or infinity: every report writes them as null through one helper."""

import json
import math

import numpy as np

from reedtool.io.json_values import finite_or_none, finite_tree


def test_non_finite_and_missing_become_none():
    for value in (math.nan, math.inf, -math.inf, np.float64("nan"), None):
        assert finite_or_none(value) is None


def test_finite_values_come_back_as_plain_floats():
    got = finite_or_none(np.float64(2.5))
    assert got == 2.5 and type(got) is float      # exact: 2.5 is a binary float
    assert finite_or_none(3) == 3.0


def test_tree_nulls_only_non_finite_floats():
    tree = {"a": [1.0, math.nan, ("x", math.inf)], "b": {"c": -math.inf, "d": 7}}
    out = finite_tree(tree)
    assert out == {"a": [1.0, None, ["x", None]], "b": {"c": None, "d": 7}}
    json.dumps(out, allow_nan=False)              # raises if any non-finite survived
