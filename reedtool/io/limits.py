"""The one notion of a joint-limit number the loader reads as "no limit".

Three spellings of it reach reedtool, and each loader decides which it accepts:

- DBL_MAX (1.79769e+308) and anything beyond NO_LIMIT_BEYOND: exporters write it, urdfdom
  and libsdformat store it as given, and sdformat itself writes +-1e16 for none;
- +-inf: libsdformat parses `inf` as a number (a limit of infinity is no limit), where
  urdfdom refuses it ("lower value (-inf) is not a valid float"): in a URDF it stays an
  error (S102), in an SDF it is no limit;
- -1: SDF's (and Gazebo Classic's) "no effort / velocity limit".

A NaN is never a limit: it stays the reader's finding in every format.
"""

from __future__ import annotations

import math

# sdformat writes "no limit" as +-1e16; anything beyond this is unbounded.
NO_LIMIT_BEYOND = 1e15
# The loader accepts "inf" in a number it reads (libsdformat: yes; urdfdom: no).
INFINITY_PARSED = {"sdf": True, "urdf": False}
# Fields where a negative number means "no limit" (SDF, Gazebo Classic).
NEGATIVE_IS_NONE = {"sdf": ("effort", "velocity"), "urdf": ()}


def infinity_accepted(source_format: str) -> bool:
    """Does this format's loader read `inf` in a joint limit as a number?"""
    return INFINITY_PARSED.get(source_format, False)


def as_limit(value: float | None, field: str, source_format: str) -> float | None:
    """A joint-limit number as the simulator uses it: +-inf for every "no limit"
    spelling the loader of `source_format` reads (see the module docstring), else the
    value. None (absent) and NaN pass through unchanged."""
    if value is None or math.isnan(value):
        return value
    if field in NEGATIVE_IS_NONE.get(source_format, ()) and value < 0:
        return math.inf
    if abs(value) >= NO_LIMIT_BEYOND:
        return math.copysign(math.inf, value)
    return value


def unbounded(lower: float | None, upper: float | None) -> bool:
    """A revolute joint with no position limit on either side (a continuous one)."""
    return (lower is not None and upper is not None
            and lower <= -NO_LIMIT_BEYOND and upper >= NO_LIMIT_BEYOND)


# What sdformat's joint.sdf writes for "no limit": lower/upper default to -+1e16, and an
# effort or velocity limit is "not enforced if negative" (default -1).
SDF_NO_POSITION_LIMIT = 1e16


def is_no_limit(value: float | None) -> bool:
    """A limit the readers left as "none": absent (None) or infinite (as_limit's)."""
    return value is None or not math.isfinite(value)


def sdf_limit_text(tag: str, value: float | None) -> str | None:
    """The text SDF writes for a joint limit `tag` (lower, upper, effort, velocity), or
    None to leave the element out. "No limit" is never written as `inf` (libsdformat reads
    it, but the spec's own spelling is the one every reader takes): lower/upper become
    sdformat's -+1e16, effort/velocity are left out (sdformat's default -1, not enforced)."""
    if tag in ("effort", "velocity"):
        return None if is_no_limit(value) or value < 0 else repr(float(value))
    if is_no_limit(value) or abs(value) >= NO_LIMIT_BEYOND:
        sign = -1.0 if (value is not None and value < 0) or (value is None and tag == "lower") \
            else 1.0
        return f"{sign * SDF_NO_POSITION_LIMIT:g}"
    return "0" if value == 0 else repr(float(value))


def urdf_limit_text(tag: str, value: float | None, number=repr) -> str | None:
    """The text URDF writes for a joint limit attribute, or None to leave it out (absent in
    the source: urdfdom reads 0 for lower/upper, as it did there). urdfdom refuses `inf`, so
    "no limit" is written as sdformat's -+1e16, which both readers take as none."""
    if value is None or math.isnan(value):
        return None
    if abs(value) >= NO_LIMIT_BEYOND:
        return f"{math.copysign(SDF_NO_POSITION_LIMIT, value):g}"
    return number(value)
