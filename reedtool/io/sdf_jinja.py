"""PX4's Gazebo Classic templates (`*.sdf.jinja`), rendered as PX4 renders them.

PX4-SITL_gazebo-classic keeps its models as Jinja templates and renders them at build
time with scripts/jinja_gen.py: a jinja2 FileSystemLoader over the repository, default
Undefined (an unknown name renders empty), and the context of jinja_gen's argument
defaults (mavlink_tcp_port 4560, mavlink_udp_port 14560, serial_enabled 0, hil_mode 0,
...), `np` (numpy), `rospack` None without ROS, `ros_version` 0, overridden by the
repository's resources/px4_gazebo_jinja_parameters.json when there is one. reedtool does
the same, and then reads the text as SDF.

Findings point into the template: each line of the rendered text is matched to a
template line (difflib: the lines a block of template text renders to, line by line;
the lines a macro or expression expands to, to the template lines they replace), and
every SourceLoc of the model in the template is moved to that line (the rendered line
kept as `urdf_line`, the line of the expansion).
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from pathlib import Path

from reedtool.errors import ReedtoolError

SUFFIX = ".sdf.jinja"
# scripts/jinja_gen.py argparse defaults (PX4-SITL_gazebo-classic).
JINJA_GEN_DEFAULTS = {
    "mavlink_tcp_port": 4560, "mavlink_udp_port": 14560, "serial_enabled": 0,
    "serial_device": "/dev/ttyACM0", "serial_baudrate": 921600, "hil_mode": 0,
    "mavlink_id": 1, "cam_component_id": 100, "gst_udp_host": "127.0.0.1",
    "gst_udp_port": 5600, "external_render_ip": "", "video_uri": "udp://127.0.0.1:5600",
    "mavlink_cam_udp_port": 14530, "udp_onboard_gimbal_host_ip": 13030,
    "udp_onboard_gimbal_port_remote": 13030,
}
OVERRIDES = Path("resources") / "px4_gazebo_jinja_parameters.json"
_MAX_ROOT_DEPTH = 4        # a template sits at <repo>/models/<model>/<model>.sdf.jinja


# Templates rendered since the last relocate_rendered(): path -> template line per rendered
# line (an SDF model may include one: PX4's iris_opt_flow includes px4flow).
_RENDERED: dict[str, list[int]] = {}


def is_sdf_jinja(path: Path | str) -> bool:
    return str(path).lower().endswith(SUFFIX)


@dataclass
class Rendered:
    text: str
    template_line: list[int]           # rendered line n (1-based) -> template_line[n - 1]


def _env_dir(path: Path) -> Path:
    """The repository jinja_gen.py is run with (the ancestor holding resources/ or
    scripts/jinja_gen.py), else the template's own directory."""
    for parent in list(path.parents)[:_MAX_ROOT_DEPTH]:
        if (parent / OVERRIDES).is_file() or (parent / "scripts" / "jinja_gen.py").is_file():
            return parent
    return path.parent


def _context(env_dir: Path) -> dict:
    import numpy as np

    context = {"np": np, "rospack": None, "ros_version": 0, **JINJA_GEN_DEFAULTS}
    overrides = env_dir / OVERRIDES
    if overrides.is_file():
        import json

        from reedtool.io.fileio import read_text_file

        try:
            context.update(json.loads(read_text_file(overrides, what="jinja parameters")))
        except json.JSONDecodeError as exc:
            raise ReedtoolError(f"not JSON ({exc.msg})", file=overrides, line=exc.lineno,
                                hint="jinja_gen.py reads it as a JSON object") from None
    return context


def render(path: Path) -> Rendered:
    """The template's text as jinja_gen.py renders it, with the template line of each
    rendered line."""
    import jinja2

    from reedtool.io.fileio import read_text_file

    path = Path(path)
    source = read_text_file(path, what="SDF template")
    env_dir = _env_dir(path.resolve())
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(env_dir)))
    try:
        template = env.from_string(source)
        text = template.render(_context(env_dir))
    except jinja2.TemplateSyntaxError as exc:
        raise ReedtoolError(f"Jinja template error: {exc.message}", file=path, line=exc.lineno,
                            hint="PX4's jinja_gen.py would refuse it too") from None
    except jinja2.TemplateError as exc:
        raise ReedtoolError(f"Jinja template error: {exc}", file=path,
                            hint="reedtool renders it with jinja_gen.py's default "
                                 "arguments") from None
    except Exception as exc:        # an expression of the template failed (np, arithmetic)
        raise ReedtoolError(f"rendering the template failed: {type(exc).__name__}: {exc}",
                            file=path, hint="reedtool renders it with jinja_gen.py's "
                                            "default arguments") from None
    rendered = Rendered(text, _line_map(source.splitlines(), text.splitlines()))
    _RENDERED[str(path)] = rendered.template_line
    return rendered


def _normal(line: str) -> str:
    """A line with its expressions and numbers blanked: a template line and what it
    renders to compare equal (`rotor_{{ loop.index0 }}` and `rotor_2`)."""
    line = re.sub(r"\{\{.*?\}\}", "#", line.strip())
    return re.sub(r"#+", "#", re.sub(r"[-+]?\d[\d.eE+-]*", "#", line))


def _template_keys(template: list[str]) -> list[str]:
    """What each template line can match: its normal form; nothing for a macro's body (it
    renders where the macro is called, and a finding there points at the call) or a
    statement-only line (it renders nothing)."""
    keys, depth = [], 0
    for n, line in enumerate(template):
        if re.search(r"\{%-?\s*macro\b", line):
            depth += 1
        silent = depth > 0 or re.fullmatch(r"\s*\{%.*?%\}\s*", line) is not None
        if re.search(r"\{%-?\s*endmacro\b", line):
            depth = max(depth - 1, 0)
        keys.append(f"\0{n}" if silent else _normal(line))
    return keys


def _line_map(template: list[str], rendered: list[str]) -> list[int]:
    """Rendered line -> template line. Lines a loop repeats are matched again against the
    template before them (the loop's body); a macro's lines map to its call."""
    import difflib  # imported here: only a rendered template needs it, not every validate

    t_norm = _template_keys(template)
    r_norm = [_normal(line) for line in rendered]
    matcher = difflib.SequenceMatcher(None, t_norm, r_norm, autojunk=False)
    out = [1] * len(rendered)
    for tag, i1, i2, j1, j2 in matcher.get_opcodes():
        for j in range(j1, j2):
            if tag == "equal":
                out[j] = i1 + (j - j1) + 1
            elif i2 > i1:
                out[j] = i1 + min(j - j1, i2 - i1 - 1) + 1
            else:
                out[j] = max(i1, 1)    # inserted: the template line before it
        if tag in ("insert", "replace") and j2 - j1 > i2 - i1:
            _repeats(t_norm[:i2], r_norm, j1, j2, out)
    return out


def _repeats(t_norm: list[str], r_norm: list[str], j1: int, j2: int, out: list[int]) -> None:
    """Rendered lines j1..j2 that repeat template text (a loop's later passes), matched
    pass by pass: each round aligns what is left with the template once."""
    import difflib

    start = j1
    while start < j2:
        again = difflib.SequenceMatcher(None, t_norm, r_norm[start:j2], autojunk=False)
        blocks = [b for b in again.get_matching_blocks() if b.size]
        if not blocks:
            return
        for block in blocks:
            for n in range(block.size):
                out[start + block.b + n] = block.a + n + 1
        start += blocks[-1].b + blocks[-1].size


def _relocate(obj, file: str, line_map: list[int], seen: dict[int, object]):
    """obj with every SourceLoc of `file` in it moved to the template line (SourceLoc is
    frozen: a moved one is a new SourceLoc, put where the old one was)."""
    from reedtool.model import SourceLoc

    if obj is None or isinstance(obj, (str, bytes, int, float, bool)):
        return obj
    if id(obj) in seen:
        return seen[id(obj)]
    seen[id(obj)] = obj
    if isinstance(obj, SourceLoc):
        if obj.file == file and obj.line is not None and 1 <= obj.line <= len(line_map):
            moved = dataclasses.replace(obj, line=line_map[obj.line - 1], urdf_line=obj.line)
            seen[id(obj)] = moved
            return moved
        return obj
    if isinstance(obj, list):
        obj[:] = [_relocate(value, file, line_map, seen) for value in obj]
    elif isinstance(obj, tuple) and not hasattr(obj, "_fields"):
        moved = tuple(_relocate(value, file, line_map, seen) for value in obj)
        seen[id(obj)] = moved
        return moved
    elif isinstance(obj, dict):
        for key, value in obj.items():
            obj[key] = _relocate(value, file, line_map, seen)
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        for item in dataclasses.fields(obj):
            value = getattr(obj, item.name, None)
            moved = _relocate(value, file, line_map, seen)
            if moved is not value:
                object.__setattr__(obj, item.name, moved)
    return obj


def take_rendered() -> dict[str, list[int]]:
    """The line maps of the templates rendered since the last call (and forget them)."""
    maps = dict(_RENDERED)
    _RENDERED.clear()
    return maps


def relocate_rendered(robot, maps: dict[str, list[int]] | None = None):
    """Move the robot's locations in every template rendered while loading it (its own
    file, or a template it includes) to the template's lines; `maps` from take_rendered()
    when several robots come from one load (a world)."""
    for file, line_map in (take_rendered() if maps is None else maps).items():
        robot = _relocate(robot, file, line_map, {})
    return robot
