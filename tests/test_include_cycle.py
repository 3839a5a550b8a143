"""A file that includes itself is an error with the chain, whatever else it holds
(issue 19: a macro library that included itself was "skipped", exit 0)."""

from __future__ import annotations

import pytest
from cli_helpers import run_validate

HEAD = '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro"{name}>\n'
MACRO = '  <xacro:macro name="{m}"><link name="{m}"/></xacro:macro>\n'


def xacro(path, includes, body="", name=""):
    path.write_text(HEAD.format(name=f' name="{name}"' if name else "")
                    + "".join(f'  <xacro:include filename="{i}"/>\n' for i in includes)
                    + body + "</robot>\n")
    return path


@pytest.mark.parametrize("body, name", [
    (MACRO.format(m="m"), ""),                      # a macro library
    ("", ""),                                       # nothing but the include
    ('  <link name="base_link"/>\n', "r"),          # a robot
])
def test_a_file_including_itself_is_an_error_with_the_chain(tmp_path, capsys, body, name):
    model = xacro(tmp_path / "self.xacro", ["self.xacro"], body, name)
    code, out, err = run_validate([model], capsys)
    assert code == 2
    assert "include cycle: self.xacro -> self.xacro" in err
    assert "skipped" not in out + err


def test_a_cycle_through_another_library_names_both(tmp_path, capsys):
    a = xacro(tmp_path / "a.xacro", ["b.xacro"], MACRO.format(m="ma"))
    xacro(tmp_path / "b.xacro", ["a.xacro"], MACRO.format(m="mb"))
    code, out, err = run_validate([a], capsys)
    assert code == 2 and "include cycle: a.xacro -> b.xacro -> a.xacro" in err


def test_a_library_included_twice_without_a_cycle_is_still_skipped(tmp_path, capsys):
    # A diamond (a includes b and c, both include d) is no cycle.
    a = xacro(tmp_path / "a.xacro", ["b.xacro", "c.xacro"], MACRO.format(m="ma"))
    xacro(tmp_path / "b.xacro", ["d.xacro"], MACRO.format(m="mb"))
    xacro(tmp_path / "c.xacro", ["d.xacro"], MACRO.format(m="mc"))
    xacro(tmp_path / "d.xacro", [], MACRO.format(m="md"))
    code, out, _ = run_validate([a], capsys)
    assert code == 0 and "skipped: a xacro macro library" in out


def test_an_sdf_model_including_itself_is_an_error_with_the_chain(tmp_path, capsys):
    model = tmp_path / "m" / "model.sdf"
    model.parent.mkdir()
    model.write_text('<?xml version="1.0"?>\n<sdf version="1.9"><model name="m">'
                     '<link name="base_link"/><include><uri>model.sdf</uri></include>'
                     "</model></sdf>\n")
    code, _, err = run_validate([model], capsys)
    assert code == 2 and "cycle" in err and "model.sdf -> " in err
