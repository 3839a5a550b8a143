"""A baseline of accepted findings: written once, then only new findings are reported.

A team adopting validate on 30-90 models accepts what is there today and fails CI only
on what a change adds. `validate --write-baseline FILE` records every finding of the run;
`--baseline FILE` (or `baseline = "FILE"` in the configuration) drops the findings it
records from later reports, each entry at most as many times as it was recorded.

An entry is keyed so that it survives edits elsewhere in the file: the model (its path
relative to the baseline file, and the variant or world model it is), the finding's file
(relative too), its code, its subject (link, joint, rotor or plugin name) and a
fingerprint of its message with line numbers taken out. The line itself is kept for the
reader and not matched, so adding a link above an accepted finding keeps it accepted;
a finding whose message changes (another mass, another rotor count) is new. The file
format (docs/ci.md):

    {"schema": "reedtool.baseline/1", "tool": "reedtool", "version": "...",
     "findings": [{"model": "urdf/mav.gazebo [mav_name=firefly]",
                   "file": "urdf/firefly.xacro", "line": 41, "code": "I204",
                   "subject": "rotor_0", "fingerprint": "0c5d2e...",
                   "message": "..."}, ...]}
"""

from __future__ import annotations

import os
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from reedtool.errors import ReedtoolError

SCHEMA = "reedtool.baseline/1"
# A line number inside a message ("line 12", "file.xacro:12") moves with every edit above it.
_LINE_REFERENCE = re.compile(r"(\bline\s+|:)\d+\b")


def fingerprint(code: str, subject: str | None, message: str) -> str:
    """16 hex digits of the finding's code, subject and message, line numbers taken out."""
    import hashlib

    text = _LINE_REFERENCE.sub(r"\1#", " ".join(message.split()))
    return hashlib.sha256(f"{code}\0{subject or ''}\0{text}".encode()).hexdigest()[:16]


def _relative(path: str | None, directory: Path) -> str | None:
    if path is None:
        return None
    try:
        return Path(os.path.relpath(os.path.abspath(path), directory)).as_posix()
    except ValueError:          # another drive: keep it absolute
        return Path(os.path.abspath(path)).as_posix()


def model_key(model_name: str, directory: Path) -> str:
    """A result's model name (display path, then ` [model X]` or ` [arg=value]`), with its
    path relative to the baseline's directory."""
    path, bracket, rest = model_name.partition(" [")
    return (_relative(path, directory) or path) + (bracket + rest if bracket else "")


def _key(model: str, file: str | None, code: str, subject: str | None, print_: str) -> tuple:
    return (model, file or "", code, subject or "", print_)


@dataclass
class Baseline:
    path: Path
    entries: Counter = field(default_factory=Counter)
    used: Counter = field(default_factory=Counter)

    @property
    def directory(self) -> Path:
        return Path(os.path.abspath(self.path)).parent

    def accepts(self, model_name: str, finding) -> bool:
        """Is this finding recorded (and not yet matched as often as it was recorded)?"""
        from reedtool.checks.runner import INTERNAL_ERROR

        if finding.message.startswith(INTERNAL_ERROR):
            return False     # a reedtool bug is never an accepted finding
        key = _key(model_key(model_name, self.directory),
                   _relative(finding.file, self.directory), finding.code, finding.subject,
                   fingerprint(finding.code, finding.subject, finding.message))
        if self.used[key] < self.entries[key]:
            self.used[key] += 1
            return True
        return False

    def stale(self) -> int:
        """Entries no finding matched this run (fixed since the baseline was written).
        Only meaningful when the run covered every model the baseline records."""
        return sum((self.entries - self.used).values())


def read_baseline(path: Path) -> Baseline:
    import json  # imported here: a run without a baseline file never parses JSON

    from reedtool.io.fileio import read_bytes

    try:
        document = json.loads(read_bytes(Path(path), what="baseline file",
                                         max_bytes=64 << 20).decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ReedtoolError(f"not a reedtool baseline: {exc}", file=path,
                            hint="write it with `reedtool validate --write-baseline FILE`"
                            ) from None
    if not isinstance(document, dict) or document.get("schema") != SCHEMA \
            or not isinstance(document.get("findings"), list):
        raise ReedtoolError(f"not a reedtool baseline (schema '{SCHEMA}' expected)", file=path,
                            hint="write it with `reedtool validate --write-baseline FILE`")
    baseline = Baseline(Path(path))
    for n, entry in enumerate(document["findings"]):
        try:
            baseline.entries[_key(str(entry["model"]), entry.get("file"), str(entry["code"]),
                                  entry.get("subject"), str(entry["fingerprint"]))] += 1
        except (KeyError, TypeError):
            raise ReedtoolError(f"baseline entry {n + 1} lacks model, code or fingerprint",
                                file=path, hint="write it again with --write-baseline"
                                ) from None
    return baseline


def baseline_text(results, path: Path) -> tuple[str, int]:
    """The baseline document recording every finding of `results` (ModelResults), keyed
    relative to `path`'s directory; and how many findings it records."""
    import json

    from reedtool import __version__
    from reedtool.checks.runner import INTERNAL_ERROR

    directory = Path(os.path.abspath(path)).parent
    entries = []
    for result in results:
        for f in result.findings:
            if f.message.startswith(INTERNAL_ERROR):
                continue
            entries.append({"model": model_key(result.name, directory),
                            "file": _relative(f.file, directory), "line": f.line,
                            "code": f.code, "subject": f.subject,
                            "fingerprint": fingerprint(f.code, f.subject, f.message),
                            "message": f.message})
    entries.sort(key=lambda e: (e["model"], e["file"] or "", e["line"] or 0, e["code"],
                                e["subject"] or "", e["fingerprint"]))
    document = {"schema": SCHEMA, "tool": "reedtool", "version": __version__,
                "findings": entries}
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n", len(entries)


def apply_baselines(results, baseline_for) -> list[Baseline]:
    """Drop from each ModelResult the findings its baseline accepts (counted in
    `result.baselined`). `baseline_for(result) -> Baseline | None`. Returns the baselines
    used, for their stale counts."""
    used: dict[int, Baseline] = {}
    for result in results:
        baseline = baseline_for(result)
        if baseline is None:
            continue
        used[id(baseline)] = baseline
        kept = [f for f in result.findings if not baseline.accepts(result.name, f)]
        result.baselined += len(result.findings) - len(kept)
        result.findings = kept
    return list(used.values())


def apply_run_baselines(results, models, baseline_file: Path | None
                        ) -> tuple[list[Baseline], list[Path]]:
    """A run's baselines applied: `--baseline FILE` for every model, else each model's
    configuration's `baseline` (`models`: (display name, path) of the run's targets; a
    result belongs to its target by name, variants and world models included). Returns
    the baselines used and the configured ones that do not exist yet (nothing accepted:
    every finding is reported, the safe side)."""
    from reedtool.config import load_config

    loaded: dict[Path, Baseline] = {}

    def load(path: Path) -> Baseline:
        key = Path(os.path.abspath(path))
        if key not in loaded:
            loaded[key] = read_baseline(path)
        return loaded[key]

    if baseline_file is not None:
        baseline = load(baseline_file)
        return apply_baselines(results, lambda result: baseline), []
    configured = {name: load_config(path).baseline for name, path in models}
    configured = {name: path for name, path in configured.items() if path is not None}
    missing: list[Path] = []

    def baseline_for(result) -> Baseline | None:
        path = next((p for name, p in configured.items()
                     if result.name == name or result.name.startswith(name + " [")), None)
        if path is None:
            return None
        if not path.is_file():
            if path not in missing:
                missing.append(path)
            return None
        return load(path)

    return (apply_baselines(results, baseline_for) if configured else []), missing
