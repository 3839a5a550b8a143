"""The one catalogue of rules. Rules register themselves with the `@rule` decorator.

A rule's metadata (code, slug, default severity, one-line summary) is data; its docstring
is its documentation (`--explain`, docs/rules.md). Codes are a family letter and three
digits and are never reused: the code table (checks/codes.py) lists every code with its
stack and lifecycle, and the retired ones, which cannot register again.
"""

from __future__ import annotations

import importlib
import inspect
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Iterable

from reedtool.checks.codes import CODES, RETIRED
from reedtool.checks.finding import SEVERITIES, Issue

if TYPE_CHECKING:
    from reedtool.checks.context import CheckContext

CheckFn = Callable[["CheckContext"], Iterable[Issue]]

# Family letter -> (module that defines its rules, title).
FAMILIES: dict[str, tuple[str, str]] = {
    "S": ("reedtool.checks.structure", "Structure"),
    "I": ("reedtool.checks.inertia_rules", "Inertia"),
    "R": ("reedtool.checks.rotor_rules", "Rotors"),
    "C": ("reedtool.checks.controller_rules", "Controller cross-check"),
}
# Further rule modules of the families above (a family may span modules).
EXTRA_RULE_MODULES: tuple[str, ...] = (
    "reedtool.checks.argument_rules",
    "reedtool.checks.suppression_rules",
    "reedtool.checks.fault_rules",
    "reedtool.checks.flightstack_rules",
    "reedtool.checks.lee_rules",
    "reedtool.checks.plausibility_rules",
    "reedtool.checks.sdformat_rules",
)

# The severity policy (docs/validate.md, "Severity policy"): each rule names the clause that
# gives its default severity. clause -> (the severities it allows, its wording).
POLICY_CLAUSES: dict[str, tuple[tuple[str, ...], str]] = {
    "refused": (("error",), "Gazebo refuses the model: libsdformat, urdfdom, TinyXML2, a "
                            "mesh loader or a plugin rejects it, or Gazebo drops the element"),
    "cannot-fly": (("error",), "the model as written cannot do what it is for: it cannot "
                               "hover or be controlled, or a rotor spins against its "
                               "allocation"),
    "flight-stack": (("error",), "the flight stack or controller will command a motor the "
                                 "model does not have, spin it the other way, or saturate it"),
    "suspicious": (("warning",), "suspicious, but the model loads and can fly"),
    "ambiguous": (("warning", "info"), "reedtool cannot tell a convention from a mistake, "
                                       "so it says what it sees at a lower severity"),
    "explains": (("info",), "it explains; nothing is wrong"),
}

_CODE = re.compile(r"^[A-Z]\d{3}$")
_SLUG = re.compile(r"^[a-z0-9]+(-[a-z0-9]+)*$")


@dataclass(frozen=True)
class Rule:
    code: str
    slug: str
    severity: str          # default; a config may override it
    summary: str           # one line
    check: CheckFn
    clause: str = ""       # POLICY_CLAUSES key: why the default severity is what it is
    # Judged over a whole run, not one robot (S143: a suppression no model needed); the
    # runner skips it and `check` takes what the run gathered instead of a CheckContext.
    run_level: bool = False
    # From the code table (checks/codes.py): the flight stack whose contract the rule holds
    # the model to ("core" for any model), and "stable" or "preview".
    stack: str = "core"
    lifecycle: str = "stable"

    @property
    def policy(self) -> str:
        """The severity policy's sentence for this rule, as documented."""
        return f"{self.severity}: {POLICY_CLAUSES[self.clause][1]}"

    @property
    def family(self) -> str:
        return FAMILIES[self.code[0]][1]

    @property
    def explanation(self) -> str:
        return inspect.cleandoc(self.check.__doc__ or "").strip()


_RULES: dict[str, Rule] = {}


def rule(code: str, slug: str, severity: str, summary: str, *, clause: str,
         run_level: bool = False) -> Callable[[CheckFn], CheckFn]:
    """Register a check function under a stable code; `clause` names the severity
    policy's clause (POLICY_CLAUSES) that gives `severity`."""

    def register(fn: CheckFn) -> CheckFn:
        # Programming errors in a rule module, caught at import time by the test suite.
        if not _CODE.match(code) or code[0] not in FAMILIES:
            raise ValueError(f"bad rule code {code!r}")
        if code in RETIRED:
            raise ValueError(f"rule code {code} is retired ({RETIRED[code][1]}); take a new one")
        if not _SLUG.match(slug):
            raise ValueError(f"bad rule slug {slug!r}")
        if severity not in SEVERITIES:
            raise ValueError(f"bad severity {severity!r} for {code}")
        if clause not in POLICY_CLAUSES or severity not in POLICY_CLAUSES[clause][0]:
            raise ValueError(f"rule {code}: clause {clause!r} does not give severity {severity}")
        if not fn.__doc__:
            raise ValueError(f"rule {code} has no docstring (its documentation)")
        if code in _RULES and _RULES[code].check is not fn:
            raise ValueError(f"rule code {code} registered twice")
        if any(r.slug == slug and r.code != code for r in _RULES.values()):
            raise ValueError(f"rule slug {slug!r} registered twice")
        # A code not yet in the table is a preview of any stack until it is entered there
        # (tests/test_code_table.py fails until it is).
        _slug, stack, lifecycle = CODES.get(code, (slug, "core", "preview"))
        _RULES[code] = Rule(code, slug, severity, summary, fn, clause, run_level,
                            stack=stack, lifecycle=lifecycle)
        return fn

    return register


_families_loaded = False
# The sorted catalogue, kept while the registered rules stay the same ones: every model of
# a run asks for it several times (selection, runner, severities).
_sorted: tuple[tuple, list[Rule]] = ((), [])


def _load_families() -> None:
    global _families_loaded
    if _families_loaded:
        return
    for module_name, _title in FAMILIES.values():
        importlib.import_module(module_name)
    for module_name in EXTRA_RULE_MODULES:
        importlib.import_module(module_name)
    _families_loaded = True


def all_rules() -> list[Rule]:
    """Every registered rule, by family (S, I, R) and then by code."""
    global _sorted
    _load_families()
    key = tuple(map(id, _RULES.values()))
    if _sorted[0] != key:
        order = list(FAMILIES)
        _sorted = (key, sorted(_RULES.values(),
                                       key=lambda r: (order.index(r.code[0]), r.code)))
    return list(_sorted[1])


def get_rule(code_or_slug: str) -> Rule | None:
    """Look a rule up by code (case-insensitive) or slug."""
    _load_families()
    key = code_or_slug.strip()
    found = _RULES.get(key.upper())
    if found is not None:
        return found
    return next((r for r in _RULES.values() if r.slug == key.lower()), None)


def suggest_selector(word: str) -> str | None:
    """The rule code, code prefix or rule name closest to a selector that matches none
    (`R3O4` -> `R304`: a letter O typed for a zero), for a did-you-mean."""
    import difflib

    rules = all_rules()
    key = word.strip()
    # A code typed with O for 0 or I/l for 1 is the commonest slip; try it first.
    digits = key[:1].upper() + key[1:].upper().replace("O", "0").replace("I", "1") \
        .replace("L", "1")
    codes = {r.code for r in rules}
    if any(code.startswith(digits) for code in codes) and len(digits) > 1:
        return digits
    # Otherwise the nearest code prefix of the same length, or the nearest rule name.
    prefixes = sorted({r.code[:len(key)] for r in rules if 1 < len(key) <= len(r.code)})
    close = difflib.get_close_matches(key.upper(), prefixes, n=1, cutoff=0.6)
    if close:
        return close[0]
    close = difflib.get_close_matches(key.lower(), [r.slug for r in rules], n=1, cutoff=0.6)
    return close[0] if close else None
