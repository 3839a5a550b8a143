"""Suite-wide settings.

Hypothesis draws new examples on every run, which is how a property test finds what no
one wrote down; in CI (CI=true) it draws the same examples every time, so a submission
lands or fails on its own merits, never on a draw. Run `REEDTOOL_PROPERTY_EXAMPLES=1000
pytest tests/test_rules_property.py` locally to search wider.
"""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True)
if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
    settings.load_profile("ci")
