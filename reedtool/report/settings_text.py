"""`validate --show-settings`: the configuration file and settings each model of the run
gets, one block per model. Formats workflows.validate_run.ModelSettings; computes nothing."""

from __future__ import annotations


def settings_lines(s) -> list[str]:
    """One model's block: its name, then an indented line per setting."""
    lines = [f"{s.name}:"]
    if s.skipped is not None:
        return lines + [f"  skipped: {s.skipped}"]
    if s.error is not None:
        return lines + [f"  error: {s.error}"]
    if s.config is None:
        lines.append("  config: none found (defaults)")
    else:
        lines.append(f"  config: {s.config}")
        lines += [f"  also found (not used, the nearest wins): {other}" for other in s.also_found]
    lines.append(f"  select: {', '.join(x or 'ALL' for x in s.select)}")
    lines.append(f"  ignore: {', '.join(s.ignore) or '-'}")
    lines.append("  severity: " + (", ".join(f"{k} = {v}" for k, v in s.severity.items())
                                   or "-"))
    lines.append(f"  strict: {str(s.strict).lower()}")
    lines += [f"  arg {name}:={value}  ({origin})" for name, value, origin in s.arguments]
    if s.per_file_ignores:
        lines.append(f"  per-file-ignores: {', '.join(s.per_file_ignores)}")
    lines += [f"  variant:{label}" for label in s.variants]
    lines.append(f"  exclude: {', '.join(s.exclude) or '-'}"
                 + (" (forced)" if s.force_exclude else ""))
    if s.baseline is not None:
        lines.append(f"  baseline: {s.baseline}")
    return lines
