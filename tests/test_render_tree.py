"""Template rendering and the all-or-nothing writer."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path, PurePosixPath

import pytest

from reedtool.errors import ReedtoolError
from reedtool.generate import render as scaffold
from reedtool.generate.render import RenderedFile, render_tree, templates_root, write_tree


def digest(root: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(root.rglob("*")):
        h.update(str(p.relative_to(root)).encode())
        if p.is_file():
            h.update(p.read_bytes())
    return h.hexdigest()


@pytest.fixture
def tset(tmp_path) -> Path:
    """A tiny template root: one set 'demo' and a partial."""
    root = tmp_path / "templates"
    (root / "ros1").mkdir(parents=True)              # what templates_root() looks for
    demo = root / "demo"
    (demo / "{{ name }}_dir").mkdir(parents=True)
    (demo / "{{ name }}_dir" / "{{ name }}.txt.j2").write_text(
        "hello {{ name }}\n{% include '_parts/line.j2' %}")
    (root / "_parts").mkdir()
    (root / "_parts" / "line.j2").write_text("n={{ n }}\n")
    (demo / "blob.bin").write_bytes(b"\x00\xff{{ name }}\x80")
    (demo / "_private.j2").write_text("{{ never }}")
    return root


def test_templates_root_is_the_checkout_templates():
    root = templates_root()
    assert (root / "ros1").is_dir() and (root / "common").is_dir()


def test_render_names_contents_and_binary(tset):
    files = {f.path: f.data for f in render_tree(["demo"], {"name": "pkg", "n": 3}, root=tset)}
    assert files == {
        PurePosixPath("pkg_dir/pkg.txt"): b"hello pkg\nn=3\n",
        PurePosixPath("blob.bin"): b"\x00\xff{{ name }}\x80",   # copied, not rendered
    }


def test_undefined_variable_is_an_error(tset):
    with pytest.raises(RuntimeError, match="n"):
        render_tree(["demo"], {"name": "pkg"}, root=tset)


def test_write_creates_target_atomically(tmp_path):
    files = [RenderedFile(PurePosixPath("a/b.txt"), b"x", 0o644),
             RenderedFile(PurePosixPath("run.py"), b"#!", 0o755)]
    assert write_tree(tmp_path / "pkg", files) is None
    assert (tmp_path / "pkg" / "a" / "b.txt").read_bytes() == b"x"
    assert os.stat(tmp_path / "pkg" / "run.py").st_mode & 0o777 == 0o755
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pkg"]


def test_empty_existing_directory_is_used(tmp_path):
    (tmp_path / "pkg").mkdir()
    write_tree(tmp_path / "pkg", [RenderedFile(PurePosixPath("f"), b"1", 0o644)])
    assert (tmp_path / "pkg" / "f").read_bytes() == b"1"


def test_non_empty_target_refused_unchanged(tmp_path):
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "mine.txt").write_text("keep")
    before = digest(tmp_path)
    with pytest.raises(ReedtoolError, match="not empty"):
        write_tree(tmp_path / "pkg", [RenderedFile(PurePosixPath("f"), b"1", 0o644)])
    assert digest(tmp_path) == before


def test_target_that_is_a_file_is_refused_even_with_force(tmp_path):
    (tmp_path / "pkg").write_text("a file")
    with pytest.raises(ReedtoolError, match="not a directory"):
        write_tree(tmp_path / "pkg", [], force=True)


def test_failure_mid_write_leaves_nothing(tmp_path, monkeypatch):
    calls = []
    real = Path.write_bytes

    def flaky(self, data):
        calls.append(self)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", flaky)
    files = [RenderedFile(PurePosixPath(f"f{i}"), b"1", 0o644) for i in range(3)]
    with pytest.raises(ReedtoolError) as info:
        write_tree(tmp_path / "pkg", files)
    assert "nothing was changed" in info.value.one_line()
    assert list(tmp_path.iterdir()) == []


def test_force_overlays_and_keeps_a_backup(tmp_path):
    pkg = tmp_path / "pkg"
    write_tree(pkg, [RenderedFile(PurePosixPath("gen.txt"), b"old", 0o644)])
    (pkg / "user.txt").write_text("mine")
    backup = write_tree(pkg, [RenderedFile(PurePosixPath("gen.txt"), b"new", 0o644)], force=True)
    assert backup == tmp_path / "pkg.bak"
    assert (pkg / "gen.txt").read_bytes() == b"new"
    assert (pkg / "user.txt").read_text() == "mine"
    assert (backup / "gen.txt").read_bytes() == b"old"
    # A second --force does not overwrite the first backup.
    assert write_tree(pkg, [], force=True) == tmp_path / "pkg.bak.1"
    assert (tmp_path / "pkg.bak" / "gen.txt").read_bytes() == b"old"


def test_wheel_layout_is_found(tmp_path, monkeypatch):
    """Installed from a wheel, templates live in reedtool/_data/templates."""
    fake_pkg = tmp_path / "site" / "reedtool"
    (fake_pkg / "_data" / "templates" / "ros1").mkdir(parents=True)
    monkeypatch.setattr(scaffold, "__file__", str(fake_pkg / "generate" / "render.py"))
    assert templates_root() == fake_pkg / "_data" / "templates"
