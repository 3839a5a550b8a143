"""JSON's numbers: it has no NaN or infinity, so every JSON report writes those as null.

One notion for every report (trim, hover, inertia, failures), so a non-finite figure reads
the same in all of them.
"""

from __future__ import annotations

import math


def finite_or_none(value) -> float | None:
    """`value` as a float, or None where it is None, NaN or infinite (JSON's null)."""
    return None if value is None or not math.isfinite(value) else float(value)


def finite_tree(value):
    """A JSON-ready tree (dicts, lists, tuples) with every non-finite float made None;
    anything else is kept as it is (e.g. the speeds of an invalid trim)."""
    if isinstance(value, dict):
        return {k: finite_tree(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_tree(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
