"""Safe reads and writes of the user's files.

Writes: atomic replace, no clobbering without --force, optional backup. Every file
reedtool writes into a user's tree goes through here, so the rules "nothing is lost" and
"no half-written file" live in one place.

Reads: a user's text file either decodes or gives one line saying which file and what to
do, whatever it is (missing, a directory, a device, binary, another encoding).
"""

from __future__ import annotations

import codecs
import os
import re
import shutil
import stat
import tempfile
from pathlib import Path
from typing import Sequence

from reedtool.errors import ReedtoolError

# ------------------------------------------------------------------ reading


def read_bytes(path: Path, *, what: str = "file") -> bytes:
    """The bytes of a regular file; ReedtoolError for anything else.

    A FIFO or device (/dev/zero, /dev/stdin) is refused before reading: it may never end.
    """
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError as exc:
        raise ReedtoolError(f"{what} not found", file=path, hint="check the path") from exc
    except OSError as exc:
        raise ReedtoolError(f"cannot read {what}: {exc.strerror}", file=path) from exc
    if stat.S_ISDIR(mode):
        raise ReedtoolError(f"is a directory, not a {what}", file=path,
                            hint="pass the file's path")
    if not stat.S_ISREG(mode):
        raise ReedtoolError(f"is not a regular file (a device or pipe?), not a {what}",
                            file=path, hint="pass the path of a file on disk")
    try:
        return path.read_bytes()
    except OSError as exc:
        raise ReedtoolError(f"cannot read {what}: {exc.strerror}", file=path) from exc


def _decode(data: bytes, encoding: str, path: Path, what: str) -> str:
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        label = "UTF-8" if encoding in ("utf-8", "utf-8-sig") else encoding
        raise ReedtoolError(f"not a text {what}: byte 0x{data[exc.start]:02x} is not valid "
                            f"{label}", file=path, line=line,
                            hint="is this the right file? save it as UTF-8 text") from None


def read_text_file(path: Path, *, what: str = "file") -> str:
    """A UTF-8 text file (a BOM is allowed) as str."""
    return _decode(read_bytes(path, what=what), "utf-8-sig", Path(path), what)


_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
         (codecs.BOM_UTF8, "utf-8-sig"), (codecs.BOM_UTF16_LE, "utf-16"),
         (codecs.BOM_UTF16_BE, "utf-16"))
_XML_DECL_ENCODING = re.compile(rb"^<\?xml[^>]*?encoding\s*=\s*[\"']([A-Za-z][\w.:-]*)[\"']")


def xml_encoding(data: bytes) -> str:
    """The encoding an XML document is in, as the XML spec finds it: BOM, declaration, UTF-8."""
    for bom, name in _BOMS:
        if data.startswith(bom):
            return name
    match = _XML_DECL_ENCODING.match(data[:200])
    return match.group(1).decode("ascii").lower() if match else "utf-8"


def read_xml_file(path: Path, *, what: str = "file") -> tuple[str, str]:
    """(text, encoding) of an XML file, decoded as its BOM or XML declaration says.

    The text still carries its declaration; parse it with an XMLParser told the text is
    UTF-8 (reedtool.io.urdf does), and write it back with the returned encoding.
    """
    path = Path(path)
    data = read_bytes(path, what=what)
    encoding = xml_encoding(data)
    try:
        codecs.lookup(encoding)
    except LookupError:
        raise ReedtoolError(f"unknown encoding '{encoding}' in the XML declaration", file=path,
                            line=1, hint="save the file as UTF-8") from None
    text = _decode(data, encoding, path, what)
    return text.removeprefix("\ufeff"), encoding


# ------------------------------------------------------------------ writing


def check_writable(path: Path, force: bool) -> None:
    """Refuse to overwrite an existing file unless forced."""
    if path.exists() and not force:
        raise ReedtoolError("refusing to overwrite an existing file", file=path,
                            hint="pass --force to replace it")


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _make_parent(path: Path, created: list[Path]) -> None:
    """Create the missing directories above `path`, remembering them for a rollback."""
    missing = []
    for parent in path.parents:
        if parent.is_dir():
            break
        if parent.exists() or parent.is_symlink():
            raise ReedtoolError("is not a directory, so nothing can be written below it",
                                file=parent, hint=f"choose another path than {path}")
        missing.append(parent)
    for directory in reversed(missing):
        try:
            directory.mkdir()
        except FileExistsError:
            continue
        except OSError as exc:
            raise ReedtoolError(f"cannot create directory: {exc.strerror}",
                                file=directory) from exc
        created.append(directory)


def _stage(path: Path, data: bytes, created: list[Path]) -> str:
    """Write `data` to a temporary file beside `path`; returns its name."""
    _make_parent(path, created)
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise ReedtoolError(f"cannot write file: {exc.strerror}", file=path) from exc
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        if path.exists():
            shutil.copymode(path, tmp_name)
        else:
            # mkstemp makes the file 0600; a new file gets the mode any other tool gives it.
            os.chmod(tmp_name, 0o666 & ~_umask())
    except OSError as exc:
        Path(tmp_name).unlink(missing_ok=True)
        raise ReedtoolError(f"cannot write file: {exc.strerror}", file=path) from exc
    except BaseException:
        Path(tmp_name).unlink(missing_ok=True)
        raise
    return tmp_name


def atomic_write_many(items: Sequence[tuple[Path, bytes]], *, force: bool = False) -> None:
    """Write several files all or nothing: every one is staged before any is replaced.

    A failure while staging (a read-only or missing directory, a full disk) leaves the
    user's tree as it was, including directories that would have been created.
    """
    items = [(Path(path), data) for path, data in items]
    for path, _ in items:
        check_writable(path, force)
    created: list[Path] = []
    staged: list[tuple[str, Path]] = []
    try:
        for path, data in items:
            staged.append((_stage(path, data, created), path))
        for tmp_name, path in staged:
            os.replace(tmp_name, path)
    except OSError as exc:
        raise ReedtoolError(f"cannot write file: {exc.strerror}",
                            file=staged[-1][1] if staged else None) from exc
    finally:
        leftovers = [Path(tmp) for tmp, _ in staged if Path(tmp).exists()]
        for tmp in leftovers:
            tmp.unlink(missing_ok=True)
        if leftovers or len(staged) < len(items):
            for directory in reversed(created):
                try:
                    directory.rmdir()
                except OSError:
                    pass


def atomic_write_bytes(path: Path, data: bytes, *, force: bool = False,
                       backup: bool = False) -> Path | None:
    """Write `data` to `path` atomically; returns the backup path when one was made.

    The data goes to a temporary file in the same directory and is renamed over the
    target, so a crash leaves either the old file or the new one, never a mix.
    """
    path = Path(path)
    check_writable(path, force)
    created: list[Path] = []
    tmp_name = _stage(path, data, created)
    try:
        backup_path = None
        if backup and path.exists():
            backup_path = path.with_name(path.name + ".bak")
            shutil.copy2(path, backup_path)
        os.replace(tmp_name, path)
    except OSError as exc:
        raise ReedtoolError(f"cannot write file: {exc.strerror}", file=path) from exc
    finally:
        Path(tmp_name).unlink(missing_ok=True)
    return backup_path


def atomic_write_text(path: Path, text: str, *, force: bool = False,
                      backup: bool = False, encoding: str = "utf-8") -> Path | None:
    data = text.encode("utf-8" if encoding == "utf-8-sig" else encoding)
    return atomic_write_bytes(path, data, force=force, backup=backup)
