"""validate's errors as a computing command shows them before (or instead of) its result:
the findings in validate's text form, then one line saying what the command did with them.
"""

from __future__ import annotations

from typing import Sequence


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'s' if n != 1 else ''}"


def why_line(refusing: Sequence, reported: Sequence, refused: bool, action: str,
             ignore_validation: bool = False) -> str:
    """One line: how many errors, which make the result meaningless, what was done.

    `action` is the command's verb phrase ("flying it", "computing it", "drawing it").
    """
    total = len(refusing) + len(reported)
    codes = sorted({f.code for f in refusing})
    line = f"validate reports {_plural(total, 'error')} for this model"
    if refusing:
        verb = "makes" if len(refusing) == 1 else "make"
        line += f"; {len(refusing)} of them {verb} the result meaningless ({', '.join(codes)})"
    if refused:
        return (f"FAILED: {line}; not {action} (--ignore {','.join(codes)} or "
                "--ignore-validation goes ahead)")
    if refusing and ignore_validation:
        return f"{line}; {action} anyway (--ignore-validation)"
    return f"{line}; none of them makes the result meaningless: {action}"


def validation_text(model: str, refusing: Sequence, reported: Sequence, refused: bool,
                    action: str, ignore_validation: bool = False) -> str:
    """The errors in validate's text form, then the why line ("" when there are none)."""
    from reedtool.report import ModelResult, render

    errors = [*refusing, *reported]
    if not errors:
        return ""
    return (render([ModelResult(model, errors)], "text")
            + why_line(refusing, reported, refused, action, ignore_validation) + "\n")


def validation_json(refusing: Sequence, reported: Sequence, refused: bool) -> dict:
    """The `validation` member of a command's JSON report."""
    return {"errors": [f.to_dict() for f in [*refusing, *reported]],
            "refusing": sorted({f.code for f in refusing}), "refused": refused}
