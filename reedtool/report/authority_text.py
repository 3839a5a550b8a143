"""`authority`'s text report: the intact ACAI and what it needs, the table of single
failures, each failure's flight, and the --require line. Formats the report of
workflows.authority; computes nothing."""

from __future__ import annotations

import json

SCHEMA = "reedtool.authority/1"


def render_json(result) -> str:
    """`result`: a workflows.authority.AuthorityReport (an analysis holds no NaN)."""
    from reedtool.report.json_format import envelope

    return json.dumps({**envelope(SCHEMA), **result.document}, indent=2,
                      allow_nan=result.refused)


def _ttw(value: float | None) -> str:
    return "never" if value is None else f"{value:.3g}"


def _intact_line(intact: dict) -> str:
    need = intact["min_thrust_to_weight"]
    if intact["controllable"]:
        return (f"intact: ACAI {intact['acai']:.4g} (controllable), needs thrust-to-weight > "
                f"{_ttw(need)}")
    if need is None:
        return (f"intact: ACAI {intact['acai']:.4g}: not controllable about hover at any "
                "thrust-to-weight")
    return (f"intact: ACAI {intact['acai']:.4g}: not controllable about hover; it would be "
            f"with thrust-to-weight > {need:.3g}")


def _verdict(report: dict, policy: str, policy_text: str) -> str:
    """The --require line: what was required and, when it failed, what is not so."""
    if report["passed"]:
        return f"PASSED --require {policy}: {policy_text}"
    causes = report["intact"].get("causes") or []
    because = f" ({', '.join(c['code'] for c in causes)})" if causes else ""
    if not report["intact"]["controllable"]:
        what = f"the intact vehicle is not controllable about hover{because}"
    else:
        key = "controllable" if policy == "any-single" else "controllable_without_yaw"
        lost = [f["rotor"] for f in report["failures"] if not f[key]]
        what = f"losing {', '.join(lost)} leaves " + (
            "less than full control" if policy == "any-single"
            else "no thrust, roll and pitch control")
    return f"FAILED --require {policy}: {what} (required: {policy_text})"


def _table(failures: list[dict]) -> list[str]:
    rows = [("#", "failed rotor", "dir", "ACAI", "full control", "ACAI no yaw",
             "no yaw", "min T/W", "min T/W no yaw")]
    for f in failures:
        number = "-" if f["motor_number"] is None else str(f["motor_number"])
        rows.append((number, f["rotor"], f["direction"], f"{f['acai']:.4g}",
                     "yes" if f["controllable"] else "no", f"{f['acai_without_yaw']:.4g}",
                     "yes" if f["controllable_without_yaw"] else "no",
                     _ttw(f["min_thrust_to_weight"]), _ttw(f["min_thrust_to_weight_without_yaw"])))
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    return ["  " + "  ".join(cell.ljust(w) if c < 3 else cell.rjust(w)
                             for c, (cell, w) in enumerate(zip(r, widths))).rstrip()
            for r in rows]


def render_text(result) -> str:
    """`result`: a workflows.authority.AuthorityReport of a model that was analysed."""
    report, policy = result.document, result.policy
    intact = report["intact"]
    lines = [(f"authority {result.name}: {len(report['failures'])} rotors, mass "
              f"{report['mass_kg']:.4g} kg, thrust-to-weight {report['thrust_to_weight']:.3g}"),
             _intact_line(intact)]
    for cause in intact.get("causes") or ():
        lines.append(f"  because {cause['code']} ({cause['slug']}): {cause['message']}")
    degraded = {k: v for k, v in report["efficiency"].items() if v != 1.0}
    if degraded:
        lines.append("efficiency: " + ", ".join(f"{k} {v:g}" for k, v in degraded.items()))
    if report["failed_rotor_efficiency"] > 0:
        lines.append(f"each case below: that rotor keeps {report['failed_rotor_efficiency']:g} "
                     "of its thrust (--degrade) instead of stopping")
    lines += _table(report["failures"])
    for f in report["failures"]:
        if "flight" in f:
            mode = "" if f["flight"]["yaw_controlled"] else " (yaw dropped)"
            lines.append(f"  flight{mode}: {f['flight']['status'].upper()}: {f['flight']['message']}")
    full = sum(f["controllable"] for f in report["failures"])
    no_yaw = sum(f["controllable_without_yaw"] for f in report["failures"])
    lines.append(f"single failures: {full}/{len(report['failures'])} keep full control, "
                 f"{no_yaw}/{len(report['failures'])} keep thrust, roll and pitch "
                 f"(ACAI in mixed units: N and N*m)")
    lines.append(_verdict(report, policy, result.policy_text))
    return "\n".join(lines)
