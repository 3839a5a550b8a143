"""PX4's Gazebo Classic `.sdf.jinja` templates: rendered as PX4's jinja_gen.py renders them.

The fixture (tests/fixtures/px4_classic_jinja) is in the shape of PX4-SITL_gazebo-classic:
models/quad_jinja/quad_jinja.sdf.jinja with `{% set %}`, a macro and `{% for %}` loops,
model.config naming the rendered quad_jinja.sdf, resources/px4_gazebo_jinja_parameters.json
overriding one argument. Expected values come from jinja_gen.py's argument defaults
(mavlink_tcp_port 4560) and the JSON file (mavlink_udp_port 14570), and from the template's
own text (the lines findings must point at).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from cli_helpers import run_cli

from reedtool.io.loader import load_robot

FIXTURE = Path(__file__).parent / "fixtures" / "px4_classic_jinja"
MODEL_DIR = FIXTURE / "models" / "quad_jinja"
TEMPLATE = MODEL_DIR / "quad_jinja.sdf.jinja"


def template_line(text: str, start: int = 1) -> int:
    """The 1-based line of the template holding `text`, from line `start` on."""
    lines = TEMPLATE.read_text().splitlines()
    return next(n for n, line in enumerate(lines, 1) if n >= start and text in line)


def test_rendered_with_jinja_gen_defaults_and_the_repository_overrides():
    from reedtool.io.sdf_jinja import render

    text = render(TEMPLATE).text
    assert "<mavlink_tcp_port>4560</mavlink_tcp_port>" in text      # jinja_gen.py default
    assert "<mavlink_udp_port>14570</mavlink_udp_port>" in text     # the JSON override
    assert "{{" not in text and "{%" not in text
    robot = load_robot(TEMPLATE)
    assert sorted(link.name for link in robot.links) == \
        ["base_link", "rotor_0", "rotor_1", "rotor_2", "rotor_3"]
    # The macro's box inertia, m/12 (y² + z²) for the body: 1.5/12 (0.47² + 0.11²).
    base = robot.link_map["base_link"].inertial.inertia_kg_m2
    assert base[0, 0] == pytest.approx(1.5 / 12 * (0.47 ** 2 + 0.11 ** 2), rel=1e-12)


def test_locations_point_into_the_template():
    from reedtool.physics.rotors import discover_rotors

    robot = load_robot(TEMPLATE)
    assert robot.link_map["base_link"].loc.file == str(TEMPLATE)
    assert robot.link_map["base_link"].loc.line == template_line("<link name='base_link'>")
    loop_start = template_line("{%- for x, y, spin in rotors %}")
    loop_end = template_line("{%- endfor %}")
    rotors = discover_rotors(robot)
    assert len(rotors) == 4
    for rotor in rotors:
        # Each rotor's plugin is written by the loop body: its line is in that body.
        assert rotor.loc.file == str(TEMPLATE)
        assert loop_start < rotor.loc.line < loop_end, rotor.loc
    first = next(r for r in rotors if r.motor_number == 0)
    assert first.loc.line == template_line("<plugin name='motor_model_")


def test_a_directory_and_model_config_find_the_template(tmp_path):
    for target in (MODEL_DIR, FIXTURE):
        code, text = run_cli("validate", target, "--format", "json")
        assert code == 0, text
        assert "quad_jinja" in text and "no model file" not in text
    # A build renders quad_jinja.sdf beside the template: the template is the model.
    copy = tmp_path / "quad_jinja"
    shutil.copytree(MODEL_DIR, copy)
    from reedtool.io.sdf_jinja import render

    (copy / "quad_jinja.sdf").write_text(render(TEMPLATE).text)
    from reedtool.workflows.targets import expand_targets

    targets = [t for t in expand_targets([str(tmp_path)], lambda p: [p]) if t.path is not None]
    assert [t.path.name for t in targets] == ["quad_jinja.sdf.jinja"]
    assert load_robot(MODEL_DIR).links[0].loc.file == str(TEMPLATE)


def test_a_template_error_is_one_line_with_its_place(tmp_path):
    bad = tmp_path / "broken.sdf.jinja"
    bad.write_text("<sdf version='1.6'>\n  <model name='m'>\n  {% if x %}\n  </model>\n</sdf>\n")
    code, text = run_cli("validate", bad)
    assert code == 2
    assert f"{bad}:" in text and "Jinja template error" in text and "Traceback" not in text


def test_the_template_ports_to_a_model_libsdformat_loads(tmp_path):
    import json

    import sdformat_oracle

    code, text = run_cli("migrate", TEMPLATE, "--to", "gz", "-o", tmp_path, "--format", "json")
    assert code == 0, text
    target = Path(json.loads(text)["target"])
    assert sdformat_oracle.libsdformat_error(target / "model.sdf") is None


def test_an_sdf_including_a_template_reads_it_rendered(tmp_path):
    """PX4's iris_opt_flow.sdf includes model://px4flow, a template: the include is
    rendered too, and its elements keep the template's lines."""
    outer = tmp_path / "outer.sdf"
    outer.write_text("<?xml version='1.0'?>\n<sdf version='1.6'>\n  <model name='outer'>\n"
                     "    <include>\n      <uri>model://quad_jinja</uri>\n    </include>\n"
                     "  </model>\n</sdf>\n")
    robot = load_robot(outer, {}, [MODEL_DIR.parent])
    rotor = next(link for link in robot.links if link.name.endswith("rotor_1"))
    assert rotor.loc.file == str(TEMPLATE)
    loop_start = template_line("{%- for x, y, spin in rotors %}")
    assert loop_start < rotor.loc.line < template_line("{%- endfor %}")


def test_rendered_xml_errors_point_at_the_template_line(tmp_path):
    bad = tmp_path / "m.sdf.jinja"
    bad.write_text("<sdf version='1.6'>\n{%- set n = 2 -%}\n  <model name='m'>\n"
                   "    <link name='a'></linc>\n  </model>\n</sdf>\n")
    code, text = run_cli("validate", bad)
    assert code == 2
    assert f"{bad}:4:" in text                      # the template's line, not the rendered 3


def test_every_model_of_a_world_keeps_template_lines(tmp_path):
    """A world that includes the template twice: both models point into the template."""
    from reedtool.io.loader import load_robots

    world = tmp_path / "two.sdf"
    include = ("    <include>\n      <name>{}</name>\n      <uri>model://quad_jinja</uri>\n"
               "    </include>\n")
    world.write_text("<?xml version='1.0'?>\n<sdf version='1.6'>\n  <world name='w'>\n"
                     + include.format("a") + include.format("b") + "  </world>\n</sdf>\n")
    robots = load_robots(world, {}, [MODEL_DIR.parent])
    assert len(robots) == 2
    loop = (template_line("{%- for x, y, spin in rotors %}"), template_line("{%- endfor %}"))
    for robot in robots:
        rotor = next(link for link in robot.links if link.name.endswith("rotor_2"))
        assert rotor.loc.file == str(TEMPLATE) and loop[0] < rotor.loc.line < loop[1]
