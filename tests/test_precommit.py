"""The pre-commit hook, run as pre-commit runs it: `pre-commit try-repo` on a sample
repository holding three broken models, one a RotorS-style `.gazebo` top file whose mass
comes from the xacro arguments of the repository's pyproject.toml. pre-commit installs reedtool from this repository
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
    """Whether pip, as pre-commit will run it, can reach its index. PIP_INDEX_URL set but
    empty (a way to say "no index") is no index, never a crash of the check itself."""
    index = os.environ.get("PIP_INDEX_URL")
    if index is None:
        index = "https://pypi.org/simple/"
    index = index.strip().rstrip("/")
    if not index or os.environ.get("PIP_NO_INDEX", "").lower() in ("1", "true", "yes"):
        return False
    try:
        with urllib.request.urlopen(f"{index}/hatchling/", timeout=5):
            return True
    except (OSError, ValueError):       # unreachable, or not a URL urllib can open
        return False


def _git(cwd: Path, *args: str) -> None:
    subprocess.run(["git", "-c", "user.email=test@example.com", "-c", "user.name=test",
                    "-c", "commit.gpgsign=false", *args], cwd=cwd, check=True,
                   capture_output=True)


@pytest.mark.slow
def test_pre_commit_try_repo_reports_every_model_and_fails(tmp_path):
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
    # A .gazebo top file (issue 19: the hook matched only .urdf/.xacro/.sdf and printed
    # "(no files to check) Skipped"); its mass -1 arrives through the config's arguments,
    # so the run also shows the hook passing pyproject.toml without reading it as a model.
    (sample / "urdf" / "vehicle.gazebo").write_text(
        '<?xml version="1.0"?>\n<robot name="vehicle" xmlns:xacro="http://ros.org/wiki/xacro">\n'
        '  <link name="base_link">\n    <inertial>\n      <mass value="$(arg body_mass)"/>\n'
        '      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/>\n'
        '    </inertial>\n  </link>\n</robot>\n')
    (sample / "pyproject.toml").write_text('[tool.reedtool]\nargs = {body_mass = "-1"}\n')
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
    # Every model reported, each with its own rule codes, in one run.
    assert "urdf/arm.urdf: 2 errors" in out and "urdf/quad.urdf: 1 error" in out
    assert "S105" in out and "S104" in out and "I203" in out
    assert "urdf/vehicle.gazebo: 2 errors" in out and "has mass -1 kg" in out
    assert "pyproject.toml" not in out   # passed to the hook, never read as a model
    assert "3 models: 5 errors" in out
