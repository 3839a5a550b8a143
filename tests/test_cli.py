"""The CLI shell: every listed subcommand is real, and errors never show a traceback."""

import subprocess
import sys

import pytest

import reedtool
from reedtool.cli import SUBCOMMANDS, cli, main


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", "from reedtool.cli import main; main()", *args],
                          capture_output=True, text=True, timeout=120)


def test_version_is_the_package_version():
    result = run("--version")
    assert result.returncode == 0
    assert result.stdout.strip().endswith(reedtool.__version__)


def test_help_lists_every_subcommand_with_its_summary():
    result = run("--help")
    assert result.returncode == 0
    listed = [line.split()[0] for line in result.stdout.split("Commands:")[1].splitlines()
              if line.startswith("  ") and not line.startswith("    ")]
    assert sorted(listed) == sorted(SUBCOMMANDS)
    flat = " ".join(result.stdout.split())
    for _module, summary in SUBCOMMANDS.values():
        assert summary[:25] in flat


@pytest.mark.parametrize("name", sorted(SUBCOMMANDS))
def test_each_subcommand_is_a_real_click_command(name):
    # Not a placeholder: it has options or arguments of its own and a help text.
    command = cli.get_command(None, name)
    assert command is not None and command.callback is not None
    assert command.params, f"{name} takes no arguments or options"
    assert (command.help or "").strip()


def test_missing_model_file_is_one_line_exit_2(tmp_path, capsys):
    missing = tmp_path / "nope.urdf"
    with pytest.raises(SystemExit) as info:
        main(["expand", str(missing)])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert str(missing) in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_unknown_subcommand_exit_2():
    result = run("fly-to-the-moon")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
