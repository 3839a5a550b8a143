"""Running the CLI in-process for tests, the way the console script would."""

from click.testing import CliRunner

from reedtool.cli import cli
from reedtool.errors import ReedtoolError


def run_cli(*args) -> tuple[int, str]:
    """The CLI in-process; returns (exit code, output). Reedtool errors count as exit 2."""
    result = CliRunner().invoke(cli, [str(a) for a in args], standalone_mode=False)
    if result.exception is not None:
        if isinstance(result.exception, ReedtoolError):
            return 2, result.output + result.exception.one_line()
        raise result.exception
    return result.return_value, result.output


def run_validate(argv, capsys) -> tuple[int, str, str]:
    """`reedtool validate ARGV` through the console entry (exit code, stdout, stderr)."""
    import pytest

    from reedtool.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["validate", *map(str, argv)])
    out, err = capsys.readouterr()
    return exc.value.code, out, err
