"""Issue 14: never lose a byte, never hang.

One table of hostile inputs (special files, symlinks, backups, own sources as outputs,
huge or absurd inputs, implausible options), run against every subcommand it applies to.
Each row says: the command line, the exit code, a fragment of the one error line (or of
the warning), the files the command may create or change, and the special files that must
survive as they were. tests/test_bad_input.py covers malformed content (binary models,
NaN options, billion laughs, /dev/zero as a model, runaway ${} expressions); this table
covers the files and resources around it and does not repeat those rows.

Cases that could hang if the code regressed (a FIFO read as input, concurrent writers)
run in a subprocess with a generous timeout; the rest in-process. Huge files are sparse
(truncate), never written.
"""

from __future__ import annotations

import errno
import hashlib
import os
import stat
import struct
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from rotors_builder import multirotor_urdf

from reedtool.cli import main

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = Path(__file__).parent / "fixtures"
QUAD = FIXTURES / "core" / "quad_x_rotors.urdf"
SMARTCAR = FIXTURES / "smartcar" / "fixed" / "smartcar_description"
SMARTCAR_LEGACY = FIXTURES / "smartcar" / "legacy" / "smartcar_description"
TIMEOUT_S = 20   # a hang guard, not a speed assertion

# A single-link URDF whose collision geometry is a mesh, so inertia and validate read it.
MESH_URDF = """<?xml version="1.0"?>
<robot name="m">
  <link name="base_link">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
    <collision><geometry><mesh filename="part.stl"/></geometry></collision>
  </link>
</robot>
"""
TETRA = [((0, 0, 0), (0, 0.1, 0), (0.1, 0, 0)), ((0, 0, 0), (0.1, 0, 0), (0, 0, 0.1)),
         ((0, 0, 0), (0, 0, 0.1), (0, 0.1, 0)), ((0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1))]
XACRO_HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'


def binary_stl(triangles) -> bytes:
    body = b"".join(struct.pack("<12fH", 0, 0, 0, *(c for v in t for c in v), 0)
                    for t in triangles)
    return b"part".ljust(80) + struct.pack("<I", len(triangles)) + body


def sparse_stl(path: Path, facets: int, header_count: int | None = None) -> None:
    """A binary STL of `facets` facets without writing them (a sparse file)."""
    with open(path, "wb") as handle:
        handle.write(b"big".ljust(80) + struct.pack("<I", facets if header_count is None
                                                    else header_count))
        handle.truncate(84 + 50 * facets)


def many_rotor_urdf(n: int) -> str:
    """n RotorS rotors on a circle, alternating directions (a generated-wrongly model)."""
    return multirotor_urdf(n, name="many", arm_m=0.3, height_m=0.03, digits=6,
                           body_inertia=(0.03, 0.03, 0.06), rotor_kg=0.001,
                           rotor_inertia=(1e-7,) * 3, plugin_name="m{i}",
                           spins=[("cw", "ccw")[i % 2] for i in range(n)],
                           motor={"rotorVelocitySlowdownSim": None})


# ------------------------------------------------------------------ the scratch tree

def _copy_tree(src: Path, dst: Path) -> None:
    for path in src.rglob("*"):
        target = dst / path.relative_to(src)
        if path.is_dir():
            target.mkdir(parents=True, exist_ok=True)
        else:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(path.read_bytes())


def make_tree(root: Path) -> None:
    """Everything any row needs, made once per test in tmp_path."""
    (root / "quad.urdf").write_bytes(QUAD.read_bytes())
    _copy_tree(SMARTCAR, root / "ws" / "smartcar_description")
    _copy_tree(SMARTCAR_LEGACY, root / "legacy" / "smartcar_description")
    os.mkfifo(root / "fifo")
    (root / "adir").mkdir()
    (root / "mesh.urdf").write_text(MESH_URDF)
    (root / "part.stl").write_bytes(binary_stl(TETRA))
    # a FIFO mesh referenced by a model
    (root / "fifomesh").mkdir()
    (root / "fifomesh" / "m.urdf").write_text(MESH_URDF)
    os.mkfifo(root / "fifomesh" / "part.stl")
    # huge meshes, sparse
    sparse_stl(root / "huge_count.stl", 3_000_000)             # 150 MB, header says 3 M
    with open(root / "huge_zero.stl", "wb") as handle:        # 2 GB of nothing
        handle.truncate(2 * 1024 ** 3)
    (root / "hugemesh").mkdir()
    (root / "hugemesh" / "m.urdf").write_text(MESH_URDF)
    os.link(root / "huge_zero.stl", root / "hugemesh" / "part.stl")
    absurd = [tuple(tuple(6e37 if c else 0.0 for c in v) for v in t) for t in TETRA]
    (root / "absurd.stl").write_bytes(binary_stl(absurd))
    # a package to import into; one whose mesh target is a FIFO
    for name in ("pkg", "fifopkg"):
        (root / name / "meshes").mkdir(parents=True)
        (root / name / "package.xml").write_text(
            f'<package format="3"><name>{name}</name><version>0.0.1</version></package>\n')
    os.mkfifo(root / "fifopkg" / "meshes" / "part.stl")
    # xacro bombs that bypassed the ${} guard or the depth handling
    (root / "eval_bomb.xacro").write_text(
        XACRO_HEAD + "  <link name=\"$(eval 'x'*10**9)\"/>\n</robot>\n")
    depth = 100_000
    (root / "deep.xacro").write_text(XACRO_HEAD + "<a>" * depth + "</a>" * depth
                                     + '\n  <link name="b"/>\n</robot>\n')
    # two packages with one name under one --package-path
    for side in ("a", "b"):
        _copy_tree(SMARTCAR, root / "dup" / side / "smartcar_description")
    # a binary config next to a model
    (root / "cfg").mkdir()
    (root / "cfg" / "quad.urdf").write_bytes(QUAD.read_bytes())
    (root / "cfg" / "reedtool.toml").write_bytes(bytes(range(256)) * 4)
    (root / "many.urdf").write_text(many_rotor_urdf(2000))
    long_name = "L" * 1_000_000
    (root / "longname.urdf").write_text(
        f'<robot name="r"><link name="{long_name}"/><link name="b"/></robot>\n')
    (root / "spec_arm.yaml").write_text("arm_length: 1e9\n")


def snapshot(root: Path) -> dict[str, tuple]:
    """Every path under root: its type, and for regular files a digest of the content.

    Sparse giants are identified by size and mtime (hashing 2 GB of zeros is slow).
    """
    state = {}
    for path in sorted(root.rglob("*")):
        info = path.lstat()
        kind = stat.S_IFMT(info.st_mode)
        if stat.S_ISREG(info.st_mode) and info.st_size < 8 * 1024 * 1024:
            state[str(path.relative_to(root))] = (kind, hashlib.sha1(path.read_bytes()).hexdigest())
        elif stat.S_ISLNK(info.st_mode):
            state[str(path.relative_to(root))] = (kind, os.readlink(path))
        else:
            state[str(path.relative_to(root))] = (kind, info.st_size, info.st_mtime_ns)
    return state


def run_inprocess(args, capsys) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as exit_info:
        main([str(a) for a in args])
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


def run_subprocess(args, cwd: Path, **kwargs) -> tuple[int, str, str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, "-c", "from reedtool.cli import main; main()",
                           *map(str, args)], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=TIMEOUT_S, check=False, **kwargs)
    return proc.returncode, proc.stdout, proc.stderr


# ------------------------------------------------------------------ the table

@dataclass
class Case:
    id: str
    args: list[str]
    code: int
    fragment: str                      # in the error line (or in stderr for code 0/1)
    may_change: tuple[str, ...] = ()   # paths (relative) the command may create or change
    subprocess: bool = False           # could hang if regressed
    error_line: bool = True            # exit 2 with exactly one `reedtool: error:` line
    check: Callable[[Path], None] | None = field(default=None, repr=False)


SMARTCAR_XACRO = "ws/smartcar_description/urdf/smartcar.urdf.xacro"
SMARTCAR_BODY = "ws/smartcar_description/urdf/smartcar_body.urdf.xacro"
LEGACY_XACRO = "legacy/smartcar_description/urdf/smartcar.urdf.xacro"


def _is_fifo(rel: str):
    def check(root: Path) -> None:
        assert stat.S_ISFIFO((root / rel).lstat().st_mode)
    return check


CASES = [
    # --- outputs that are not regular files: refused even with --force, node untouched
    Case("expand-o-fifo", ["expand", SMARTCAR_XACRO, "-o", "fifo", "--force"], 2, "FIFO",
         check=_is_fifo("fifo")),
    Case("expand-o-directory", ["expand", SMARTCAR_XACRO, "-o", "adir", "--force"], 2, "adir"),
    Case("hover-csv-fifo", ["hover-test", "quad.urdf", "--csv", "fifo", "--force"], 2, "FIFO",
         check=_is_fifo("fifo")),
    Case("hover-plot-fifo", ["hover-test", "quad.urdf", "--plot", "fifo", "--force"], 2,
         "FIFO", check=_is_fifo("fifo")),
    Case("import-stl-into-fifo", ["import-stl", "part.stl", "--package", "fifopkg", "--force"],
         2, "FIFO", check=_is_fifo("fifopkg/meshes/part.stl")),
    # --- outputs that are inputs of the same run
    Case("expand-o-own-source", ["expand", SMARTCAR_XACRO, "-o", SMARTCAR_BODY, "--force"],
         2, "reads"),
    Case("expand-o-model", ["expand", SMARTCAR_XACRO, "-o", SMARTCAR_XACRO, "--force"],
         2, "reads"),
    Case("hover-csv-model", ["hover-test", "quad.urdf", "--csv", "quad.urdf", "--force"],
         2, "reads"),
    # --- '-': stdout where the format allows it, refused elsewhere, never a file named '-'
    Case("expand-o-stdout", ["expand", SMARTCAR_XACRO, "-o", "-"], 0, "", error_line=False),
    Case("hover-plot-stdout", ["hover-test", "quad.urdf", "--plot", "-"], 2,
         "standard output"),
    # --- inputs that are not regular files: refused, never read (a FIFO read blocks forever)
    Case("validate-fifo-model", ["validate", "fifo"], 2, "fifo", subprocess=True),
    Case("validate-fifo-mesh", ["validate", "fifomesh/m.urdf"], 1, "S115", subprocess=True,
         error_line=False),
    # inertia reports an unreadable mesh on its link and carries on with the others
    Case("inertia-fifo-mesh", ["inertia", "fifomesh/m.urdf"], 0, "FIFO", subprocess=True,
         error_line=False),
    Case("import-stl-fifo", ["import-stl", "fifo", "--package", "pkg"], 2, "FIFO",
         subprocess=True),
    # --- sizes checked before reading
    Case("import-stl-2gb-sparse", ["import-stl", "huge_zero.stl", "--package", "pkg"], 2,
         "MB reedtool reads"),
    Case("import-stl-3m-facets", ["import-stl", "huge_count.stl", "--package", "pkg"], 2,
         "3,000,000 triangles"),
    Case("inertia-2gb-mesh", ["inertia", "hugemesh/m.urdf"], 0, "MB reedtool reads",
         error_line=False),
    Case("validate-2gb-mesh", ["validate", "hugemesh/m.urdf"], 1, "S115", error_line=False),
    Case("import-stl-absurd-coordinates", ["import-stl", "absurd.stl", "--package", "pkg"], 2,
         "6e+37"),
    # --- xacro: $(eval) under the expression guard; depth with its own message
    Case("expand-eval-bomb", ["expand", "eval_bomb.xacro"], 2, "would run away"),
    Case("validate-eval-bomb", ["validate", "eval_bomb.xacro"], 2, "would run away"),
    Case("expand-deep-xml", ["expand", "deep.xacro"], 2, "XML nested 100001 deep (limit 500)"),
    # --- package search
    Case("expand-missing-package-path",
         ["expand", SMARTCAR_XACRO, "--package-path", "nowhere"], 2, "nowhere"),
    Case("hover-missing-package-path",
         ["hover-test", "quad.urdf", "--package-path", "nowhere"], 2, "nowhere"),
    Case("expand-duplicate-packages",
         ["expand", SMARTCAR_XACRO, "--package-path", "dup"], 0,
         "two packages named 'smartcar_description'", error_line=False),
    # --- environment errors named, not "internal error"
    Case("validate-binary-config", ["validate", "cfg/quad.urdf"], 2, "reedtool.toml"),
    Case("new-package-long-name", ["new-package", "a" * 300, "-o", "out"], 2,
         "too long", may_change=("out",)),
    # --- resources estimated before allocating
    Case("hover-samples-memory", ["hover-test", "quad.urdf", "--samples", "10000000"], 2,
         "--max-memory"),
    Case("hover-2000-rotors", ["hover-test", "many.urdf"], 2, "2000 rotors"),
    # --- implausible values: exit 2 with the allowed range, before any work
    Case("hover-rate-tiny", ["hover-test", "quad.urdf", "--rate", "1e-3"], 2, "50 .. 100000 Hz"),
    Case("hover-offset-huge", ["hover-test", "quad.urdf", "--offset", "1e300", "0", "0"], 2,
         "0 .. 1000 m"),
    Case("hover-duration-huge", ["hover-test", "quad.urdf", "--duration", "1e7"], 2,
         "--duration"),
    Case("import-stl-mass-huge", ["import-stl", "part.stl", "--package", "pkg", "--mass", "1e30"],
         2, "1e-06 .. 10000 kg"),
    Case("import-stl-density-tiny",
         ["import-stl", "part.stl", "--package", "pkg", "--density", "1e-9"], 2, "kg/m^3"),
    Case("new-package-arm-length", ["new-package", "n5", "--arm-length", "1e9", "-o", "out"],
         2, "arm_length", may_change=("out",)),
    Case("new-package-spec-arm-length",
         ["new-package", "n5", "--spec", "spec_arm.yaml", "-o", "out"], 2, "spec_arm.yaml",
         may_change=("out",)),
    Case("new-package-shadows-bundled", ["new-package", "rotors_description", "-o", "out"], 2,
         "bundles", may_change=("out",)),
]


def _allowed(rel: str, may_change: tuple[str, ...]) -> bool:
    return any(rel == m or rel.startswith(m + "/") for m in may_change)


@pytest.fixture(scope="module")
def scratch(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("hostile")
    make_tree(root)
    return root


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_input(case: Case, scratch: Path, monkeypatch, capsys):
    before = snapshot(scratch)
    if case.subprocess:
        code, out, err = run_subprocess(case.args, scratch)
    else:
        monkeypatch.chdir(scratch)
        code, out, err = run_inprocess(case.args, capsys)
    after = snapshot(scratch)
    changed = sorted(k for k in set(before) | set(after)
                     if before.get(k) != after.get(k) and not _allowed(k, case.may_change))
    for rel in sorted(set(after) - set(before), reverse=True):   # keep the shared tree clean
        path = scratch / rel
        path.rmdir() if path.is_dir() and not path.is_symlink() else path.unlink()
    assert code == case.code, err
    assert "Traceback" not in err and "internal error" not in err, err
    if case.error_line:
        assert err.count("\n") == 1 and err.startswith("reedtool: error: "), err
    assert case.fragment in (err if case.error_line else out + err), out + err
    assert len(err) < 2000, "a message echoes a huge input back"
    assert changed == [], f"files changed outside the named output: {changed}"
    assert not (scratch / "-").exists()
    if case.check:
        case.check(scratch)


# ------------------------------------------------------------------ writers, one by one

def test_expand_stdout_dash_writes_the_urdf(scratch, monkeypatch, capsys):
    monkeypatch.chdir(scratch)
    code, out, _ = run_inprocess(["expand", SMARTCAR_XACRO, "-o", "-"], capsys)
    assert code == 0 and out.lstrip().startswith("<?xml") and "<robot" in out


def test_concurrent_creates_exactly_one_wins(tmp_path):
    _copy_tree(SMARTCAR, tmp_path / "smartcar_description")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    args = [sys.executable, "-c", "from reedtool.cli import main; main()", "expand",
            "smartcar_description/urdf/smartcar.urdf.xacro", "-o", "same.urdf"]
    procs = [subprocess.Popen(args, cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(4)]
    results = [(p.wait(timeout=TIMEOUT_S * 3), p.stderr.read()) for p in procs]
    for p in procs:
        p.stdout.close()
        p.stderr.close()
    wins = [err for code, err in results if code == 0]
    assert len(wins) == 1 and "wrote same.urdf" in wins[0], results
    assert all(code == 2 and "refusing to overwrite" in err for code, err in results
               if code != 0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["same.urdf", "smartcar_description"]


def test_fix_legacy_keeps_an_older_backup(tmp_path, capsys, monkeypatch):
    _copy_tree(SMARTCAR_LEGACY, tmp_path / "smartcar_description")
    model = tmp_path / "smartcar_description" / "urdf" / "smartcar.urdf.xacro"
    original = model.read_bytes()
    (model.parent / (model.name + ".bak")).write_text("older backup")
    monkeypatch.chdir(tmp_path)
    code, _, err = run_inprocess(["expand", model, "--fix-legacy", "-o", "out.urdf"], capsys)
    assert code == 0, err
    assert (model.parent / (model.name + ".bak")).read_text() == "older backup"
    assert (model.parent / (model.name + ".bak.1")).read_bytes() == original
    assert model.read_bytes() != original


def test_inertia_fix_through_a_symlink_keeps_the_link(tmp_path, capsys):
    # The model's rotors declare the wrong inertia for their cylinders, so --fix rewrites.
    real = tmp_path / "src" / "quad.urdf"
    real.parent.mkdir()
    real.write_bytes(QUAD.read_bytes())
    link = tmp_path / "install" / "quad.urdf"
    link.parent.mkdir()
    link.symlink_to(real)
    code, _out, err = run_inprocess(["inertia", link, "--fix"], capsys)
    assert code == 0, err
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert real.read_bytes() != QUAD.read_bytes()                  # the real file was fixed
    assert (tmp_path / "src" / "quad.urdf.bak").read_bytes() == QUAD.read_bytes()
    assert not (tmp_path / "install" / "quad.urdf.bak").exists()


def test_stdout_on_a_full_disk_is_one_line(tmp_path):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full")
    _copy_tree(SMARTCAR, tmp_path / "smartcar_description")
    with open("/dev/full", "w") as full:     # opened for writing, never replaced or chmod-ed
        code, _, err = _run_to(full, tmp_path)
    assert code == 2 and err.count("\n") == 1 and "No space left" in err, err
    assert "internal error" not in err and "Traceback" not in err


def _run_to(stdout, cwd: Path) -> tuple[int, str, str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, "-c", "from reedtool.cli import main; main()",
                           "expand", "smartcar_description/urdf/smartcar.urdf.xacro"],
                          cwd=cwd, env=env, stdout=stdout, stderr=subprocess.PIPE, text=True,
                          timeout=TIMEOUT_S, check=False)
    return proc.returncode, "", proc.stderr


def test_long_link_name_is_shortened_in_findings(scratch, monkeypatch, capsys):
    monkeypatch.chdir(scratch)
    code, out, _err = run_inprocess(["validate", "longname.urdf"], capsys)
    assert code == 1 and "S104" in out               # the second root is reported ...
    assert max(len(line) for line in out.splitlines()) < 400   # ... without 1 MB of 'L'
    assert "\u2026" in out


@pytest.mark.parametrize("exc, fragment", [
    (OSError(errno.ENOSPC, "No space left on device", "out.urdf"), "disk is full"),
    (OSError(errno.EROFS, "Read-only file system", "out.urdf"), "read-only"),
    (OSError(errno.EACCES, "Permission denied", "out.urdf"), "permissions"),
    (MemoryError(), "out of memory"),
    (UnicodeDecodeError("utf-8", b"\xff", 0, 1, "invalid start byte"), "UTF-8"),
])
def test_environment_errors_are_one_line_not_internal(exc, fragment, monkeypatch, capsys):
    import reedtool.io.loader

    def explode(*_args, **_kwargs):
        raise exc

    monkeypatch.setattr(reedtool.io.loader, "load_robot", explode)
    code, _, err = run_inprocess(["validate", QUAD], capsys)
    assert code == 2 and err.count("\n") == 1 and fragment in err, err
    assert "internal error" not in err


def test_package_scan_is_bounded(tmp_path, monkeypatch, capsys):
    from reedtool.resolve import packages

    monkeypatch.setattr(packages, "MAX_CRAWL_DIRS", 30)
    for i in range(40):
        (tmp_path / "tree" / f"d{i}").mkdir(parents=True)
    model = tmp_path / "m.xacro"
    model.write_text(XACRO_HEAD + '  <xacro:include filename="$(find nothing_here)/x.xacro"/>\n'
                     '  <link name="a"/>\n</robot>\n')
    code, _, err = run_inprocess(["expand", model, "--package-path", tmp_path / "tree"], capsys)
    assert code == 2 and "more than 30 directories" in err, err


def test_backups_are_numbered_and_never_replaced(tmp_path):
    from reedtool.io.fileio import atomic_write_text

    target = tmp_path / "f.txt"
    target.write_text("v0")
    for i in range(1, 4):
        atomic_write_text(target, f"v{i}", force=True, backup=True)
    assert target.read_text() == "v3"
    assert [(tmp_path / n).read_text() for n in ("f.txt.bak", "f.txt.bak.1", "f.txt.bak.2")] \
        == ["v0", "v1", "v2"]
    assert sorted(p.name for p in tmp_path.iterdir()) == \
        ["f.txt", "f.txt.bak", "f.txt.bak.1", "f.txt.bak.2"]   # no temporary left


# ------------------------------------------------------------------ the building blocks

def test_shorten_keeps_both_ends_within_the_limit():
    from reedtool.errors import MAX_SHOWN_NAME, shorten, shorten_names

    name = "head_" + "x" * 1000 + "_tail"
    short = shorten(name)
    assert len(short) == MAX_SHOWN_NAME and short.startswith("head_") and short.endswith("_tail")
    assert shorten("base_link") == "base_link"
    message = shorten_names(f"link '{name}' has no inertia")
    assert message == f"link '{short}' has no inertia"


@pytest.mark.parametrize("quantity, value, ok", [
    ("rate", 1000.0, True), ("rate", 1e-3, False), ("rate", float("nan"), False),
    ("length", 0.18738, True), ("length", 1e9, False), ("mass", 1.5, True),
    ("mass", 0.0, False), ("offset", -5.0, True), ("offset", 1e300, False),
])
def test_plausible_ranges(quantity, value, ok):
    from reedtool.errors import ReedtoolError, check_plausible

    magnitude = quantity == "offset"
    if ok:
        assert check_plausible(quantity, value, "x", magnitude=magnitude) == value
    else:
        with pytest.raises(ReedtoolError, match="the plausible range"):
            check_plausible(quantity, value, "x", magnitude=magnitude)


def test_create_without_force_fails_if_the_name_appears_meanwhile(tmp_path, monkeypatch):
    """The check-then-publish race: the name is taken between the check and the write."""
    from reedtool.errors import ReedtoolError
    from reedtool.io import fileio

    target = tmp_path / "out.urdf"
    real_stage = fileio._stage

    def stage_then_competitor_writes(path, data, created):
        name = real_stage(path, data, created)
        target.write_text("the other writer's file")
        return name

    monkeypatch.setattr(fileio, "_stage", stage_then_competitor_writes)
    with pytest.raises(ReedtoolError, match="created meanwhile"):
        fileio.atomic_write_text(target, "mine")
    assert target.read_text() == "the other writer's file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.urdf"]


def test_open_regular_input_refuses_without_blocking(tmp_path):
    from reedtool.errors import ReedtoolError
    from reedtool.io.fileio import open_regular_input

    os.mkfifo(tmp_path / "pipe")       # no writer: a blocking open would never return
    with pytest.raises(ReedtoolError, match="FIFO"):
        open_regular_input(tmp_path / "pipe")
    (tmp_path / "big").write_bytes(b"x" * 2000)
    with pytest.raises(ReedtoolError, match="more than"):
        open_regular_input(tmp_path / "big", max_bytes=1000)
    with open_regular_input(tmp_path / "big", max_bytes=2000) as handle:
        assert len(handle.read()) == 2000
