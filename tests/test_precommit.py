"""The pre-commit hook, run as pre-commit runs it: `pre-commit try-repo` on a sample
repository holding two broken models. pre-commit installs reedtool from this repository
into its own environment, which needs the package index (CI has it; offline, skip)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
FIXTURES = Path(__file__).parent / "fixtures" / "validate"


def _pre_commit() -> str | None:
    found = shutil.which("pre-commit")
    if found:
        return found
    candidate = Path(sys.executable).parent / "pre-commit"
    return str(candidate) if candidate.exists() else None


def _index_reachable() -> bool:
    index = os.environ.get("PIP_INDEX_URL", "https://pypi.org/simple/").rstrip("/")
    try:
        with urllib.request.urlopen(f"{index}/hatchling/", timeout=5):
            return True
    except OSError:
        return False


def _git(cwd: Path, *args: str) -> None:
    subprocess.run(["git", "-c", "user.email=test@example.com", "-c", "user.name=test",
                    "-c", "commit.gpgsign=false", *args], cwd=cwd, check=True,
                   capture_output=True)


@pytest.mark.slow
def test_pre_commit_try_repo_reports_both_models_and_fails(tmp_path):
    pre_commit = _pre_commit()
    if pre_commit is None:
        pytest.skip("pre-commit is not installed")
    if not (REPO / ".git").exists() or not (REPO / ".pre-commit-hooks.yaml").is_file():
        pytest.skip("not a git checkout of reedtool (pre-commit needs the repository)")
    if not _index_reachable():
        pytest.skip("the package index cannot be reached: pre-commit cannot install the hook")
    sample = tmp_path / "sample"
    (sample / "urdf").mkdir(parents=True)
    shutil.copy(FIXTURES / "S105_bad_child_missing.urdf", sample / "urdf" / "arm.urdf")
    shutil.copy(FIXTURES / "I203_bad_triangle.urdf", sample / "urdf" / "quad.urdf")
    (sample / "README.md").write_text("not a model: the hook's files pattern skips it\n")
    _git(sample, "init", "-q")
    _git(sample, "add", "-A")
    _git(sample, "commit", "-q", "-m", "two broken models")
    env = {**os.environ, "PRE_COMMIT_HOME": str(tmp_path / "pre-commit-home"),
           "NO_COLOR": "1"}
    result = subprocess.run([pre_commit, "try-repo", str(REPO), "reedtool-validate",
                             "--all-files", "--color", "never"], cwd=sample, env=env,
                            capture_output=True, text=True, timeout=600)
    out = result.stdout + result.stderr
    assert result.returncode == 1, out
    assert "reedtool validate" in out and "Failed" in out
    # Both models reported, each with its own rule codes, in one run.
    assert "urdf/arm.urdf: 2 errors" in out and "urdf/quad.urdf: 1 error" in out
    assert "S105" in out and "S104" in out and "I203" in out
    assert "2 models: 3 errors" in out
