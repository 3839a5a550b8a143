"""Safe reads and writes of the user's files.

Writes: atomic replace, no clobbering without --force, optional backup. Every file
reedtool writes into a user's tree goes through here, so the rules "nothing is lost" and
"no half-written file" live in one place.

Reads: a user's text file either decodes or gives one line saying which file and what to
do, whatever it is (missing, a directory, a device, binary, another encoding).
"""

from __future__ import annotations

import codecs
import errno
import math
import os
import re
import stat
from collections.abc import Sequence
from pathlib import Path

from reedtool.errors import ReedtoolError

# ------------------------------------------------------------------ reading


def open_regular_input(path: Path, *, what: str = "file", max_bytes: int | None = None):
    """A binary handle on a regular file, checked before a byte is read.

    Opened non-blocking, so a FIFO cannot hang the open, then fstat-ed (the file itself,
    not whatever the name pointed to a moment earlier): a FIFO, device, socket or
    directory is refused, and a file larger than `max_bytes` is refused without reading.
    The path is noted as an input of this run (no output may replace it).
    """
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError as exc:
        raise ReedtoolError(f"{what} not found", file=path, hint="check the path") from exc
    except IsADirectoryError as exc:
        raise ReedtoolError(f"is a directory, not a {what}", file=path,
                            hint="pass the file's path") from exc
    except OSError as exc:
        from reedtool.errors import os_error

        raise os_error(exc, path, action="read file") from exc
    try:
        info = os.fstat(fd)
        kind = _kind(info.st_mode)
        if kind == "a directory":
            raise ReedtoolError(f"is a directory, not a {what}", file=path,
                                hint="pass the file's path")
        if kind is not None:
            raise ReedtoolError(f"is {kind}, not a regular file; refusing to read it as a "
                                f"{what}", file=path, hint="pass the path of a file on disk")
        if max_bytes is not None and info.st_size > max_bytes:
            raise ReedtoolError(f"{what} is {info.st_size / 2**20:.1f} MB, more than the "
                                f"{max_bytes / 2**20:.0f} MB reedtool reads", file=path,
                                hint="is this the right file? simplify or split it")
        os.set_blocking(fd, True)
    except BaseException:
        os.close(fd)
        raise
    note_input(path)
    return os.fdopen(fd, "rb")


# Meshes: a robot part exports to well under a million triangles. Each triangle costs
# ~72 bytes as float64 and several times that in topology/hull/inertia work arrays, so
# 2 million (~1 GB of work) is the ceiling; a binary STL says its count in the header, so
# it is refused without reading the body. Any mesh file above 512 MB is refused by size
# (an ASCII STL at 2 M triangles is ~500 MB).
MAX_MESH_TRIANGLES = 2_000_000
MAX_MESH_BYTES = 512 * 1024 * 1024
# Coordinates beyond 1e9 file units (1000 km in mm) are a damaged file, not a part:
# 6e37 (a float32 bit pattern read as a coordinate) gives a 1e106 kg inertial.
MAX_MESH_COORDINATE = 1e9
# A model number beyond 1e100 in SI units (the observable universe is 1e27 m across and
# weighs 1e53 kg) is a typo or a broken expression, and squaring it (inertia, k*w^2)
# overflows: the readers report it as S102 and read it as infinite.
MAX_MAGNITUDE = 1e100


def magnitude_problem(values: list[float], *, unbounded_ok: bool = False,
                      infinity_ok: bool = False) -> tuple[list[float], str | None]:
    """The numbers as a reader keeps them (beyond MAX_MAGNITUDE: infinite) and what is
    wrong with them, for the reader's own finding; None when they are usable.

    `unbounded_ok`: a joint limit, where a huge finite number is the exporters' way of
    writing "no limit" (DBL_MAX, 1.79769e+308, which the loaders store as given).
    `infinity_ok`: such a limit in a format whose loader also parses `inf` (SDF:
    reedtool.io.limits). NaN is never usable."""
    if any(math.isnan(v) for v in values) or (
            not infinity_ok and not all(math.isfinite(v) for v in values)):
        return values, "is not finite"
    if all(abs(v) <= MAX_MAGNITUDE for v in values):
        return values, None
    kept = [v if abs(v) <= MAX_MAGNITUDE else math.copysign(math.inf, v) for v in values]
    if unbounded_ok:
        return kept, None
    return kept, (f"is beyond any physical quantity (|value| > {MAX_MAGNITUDE:g}): "
                  "effectively infinite")


def check_mesh_coordinates(triangles, source) -> None:
    """Refuse a mesh whose coordinates are astronomically large (a damaged export)."""
    import numpy as np

    finite = np.abs(np.where(np.isfinite(triangles), triangles, 0.0))
    largest = float(finite.max()) if finite.size else 0.0
    if largest > MAX_MESH_COORDINATE:
        raise ReedtoolError(f"mesh has a coordinate of {largest:.3g}, beyond the "
                            f"{MAX_MESH_COORDINATE:.0e} (file units) a robot part can span",
                            file=source, hint="the file is damaged or not a part; export it "
                                              "again")


# Text inputs (models, configs, specs) larger than this are not hand-written robot files.
MAX_TEXT_BYTES = 256 * 1024 * 1024


def read_bytes(path: Path, *, what: str = "file", max_bytes: int | None = MAX_TEXT_BYTES) -> bytes:
    """The bytes of a regular file; ReedtoolError for anything else.

    A FIFO or device (/dev/zero, /dev/stdin) is refused before reading: it may never end.
    """
    path = Path(path)
    with open_regular_input(path, what=what, max_bytes=max_bytes) as handle:
        try:
            return handle.read()
        except OSError as exc:
            from reedtool.errors import os_error

            raise os_error(exc, path, action="read file") from exc
        except MemoryError:
            raise ReedtoolError(f"out of memory reading {what}", file=path,
                                hint="is this the right file?") from None


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
#
# The rules every output obeys (issue 14):
# - only a regular file is ever replaced: a device, FIFO, socket or directory is refused,
#   even with --force (replacing /dev/full with a CSV is never what the user meant);
# - never a file this run read (the model, an included xacro): `-o robot.urdf.xacro`
#   would destroy the source; only the in-place fixers (--fix, --fix-legacy) may;
# - a symlink is followed: the real file gets the new content, the link stays a link;
# - without --force, creation is race-free: the data is staged in a temporary file and
#   published with os.link, which fails if the name exists (two concurrent runs: one wins);
# - with --force, os.replace swaps the new file in atomically; a backup is a hard link to
#   the old file under the first free name of NAME.bak, NAME.bak.1, ... (never clobbered);
# - data is fsynced before it is published, and the directory after.

STDOUT = "-"
_run_inputs: set[str] = set()


def note_input(path: Path | str) -> None:
    """Remember that this run read `path`, so that no output may replace it."""
    try:
        _run_inputs.add(os.path.realpath(path))
    except (OSError, ValueError):
        pass


def reset_inputs() -> None:
    """Forget the inputs noted so far (a new run in the same process)."""
    _run_inputs.clear()


def is_stdout(path: Path | str | None) -> bool:
    return path is not None and str(path) == STDOUT


def real_target(path: Path) -> Path:
    """The file a write to `path` lands in: symlinks followed, the link itself kept."""
    return Path(os.path.realpath(path)) if os.path.islink(path) else Path(path)


def _kind(mode: int) -> str | None:
    """What a non-regular file is, or None for a regular file."""
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return None if stat.S_ISREG(mode) else "not a regular file"


def check_writable(path: Path, force: bool, *, in_place: bool = False,
                   stdout_ok: bool = False) -> None:
    """Refuse an output we must not write, before any work is done.

    Called again at write time (the run's inputs are only known then).
    """
    if is_stdout(path):
        if stdout_ok:
            return
        raise ReedtoolError("'-' (standard output) is not supported for this output",
                            hint="pass a file name; write ./- for a file named '-'")
    path = Path(path)
    target = real_target(path)
    try:
        mode = target.stat().st_mode
    except FileNotFoundError:
        if os.path.islink(path):   # a dangling link: its target would be created
            return
        return
    except OSError as exc:
        raise ReedtoolError(f"cannot write file: {exc.strerror}", file=path) from exc
    kind = _kind(mode)
    if kind is not None:
        raise ReedtoolError(f"is {kind}, not a regular file; reedtool writes regular files only",
                            file=path, hint="choose a file path for the output")
    if not in_place and os.path.realpath(target) in _run_inputs:
        raise ReedtoolError("refusing to overwrite a file this run reads (an input of the model)",
                            file=path, hint="choose another output path")
    if not force:
        raise ReedtoolError("refusing to overwrite an existing file", file=path,
                            hint="pass --force to replace it")


def current_umask() -> int:
    """The process's umask (os.umask can only be read by setting it, so it is set back)."""
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


def _fsync_dir(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass   # some filesystems cannot sync a directory; the data itself is synced
    finally:
        os.close(fd)


def _stage(path: Path, data: bytes, created: list[Path]) -> str:
    """Write `data` to a temporary file beside `path` (the real file); returns its name."""
    import shutil
    import tempfile  # imported here: only a write needs them, and validate writes nothing

    _make_parent(path, created)
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name[:64]}.", suffix=".tmp",
                                        dir=path.parent)
    except OSError as exc:
        raise write_error(exc, path) from exc
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        if path.exists():
            shutil.copymode(path, tmp_name)
        else:
            # mkstemp makes the file 0600; a new file gets the mode any other tool gives it.
            os.chmod(tmp_name, 0o666 & ~current_umask())
    except OSError as exc:
        Path(tmp_name).unlink(missing_ok=True)
        raise write_error(exc, path) from exc
    except BaseException:
        Path(tmp_name).unlink(missing_ok=True)
        raise
    return tmp_name


def write_error(exc: OSError, path: Path | str | None) -> ReedtoolError:
    """An OSError while writing as one line naming the file and what to do."""
    from reedtool.errors import os_error

    return os_error(exc, path, action="write file")


def free_backup_name(path: Path) -> Path:
    """The first of NAME.bak, NAME.bak.1, ... that does not exist (an older one is kept)."""
    candidate = path.with_name(path.name + ".bak")
    n = 1
    while candidate.exists() or candidate.is_symlink():
        candidate = path.with_name(f"{path.name}.bak.{n}")
        n += 1
    return candidate


def _make_backup(path: Path) -> Path:
    """Keep the current `path` under a free backup name, never replacing an older backup."""
    import shutil

    for _ in range(1000):
        backup = free_backup_name(path)
        try:
            os.link(path, backup)        # fails if the name was taken meanwhile
            return backup
        except FileExistsError:
            continue
        except OSError:
            try:                         # no hard links here (e.g. a FAT stick): copy, O_EXCL
                with open(path, "rb") as src, open(backup, "xb") as dst:
                    shutil.copyfileobj(src, dst)
                    dst.flush()
                    os.fsync(dst.fileno())
                shutil.copystat(path, backup)
                return backup
            except FileExistsError:
                continue
    raise ReedtoolError("no free backup name (NAME.bak.N up to 1000 taken)", file=path,
                        hint="remove old backups")


def _publish(tmp_name: str, path: Path, force: bool) -> None:
    """Move the staged file to `path`: atomically replacing it with force, else create-or-fail."""
    if force:
        os.replace(tmp_name, path)
        return
    try:
        os.link(tmp_name, path)          # atomic create-or-fail: no check-then-rename race
    except FileExistsError:
        raise ReedtoolError("refusing to overwrite an existing file (created meanwhile)",
                            file=path, hint="pass --force to replace it") from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV):
            raise
        # No hard links on this filesystem: O_EXCL creation is the race-free fallback.
        with open(tmp_name, "rb") as src:
            data = src.read()
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            raise ReedtoolError("refusing to overwrite an existing file (created meanwhile)",
                                file=path, hint="pass --force to replace it") from None
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
    os.unlink(tmp_name)


def atomic_write_many(items: Sequence[tuple[Path, bytes]], *, force: bool = False) -> None:
    """Write several files all or nothing: every one is staged before any is published.

    A failure while staging (a read-only or missing directory, a full disk) leaves the
    user's tree as it was, including directories that would have been created; a failure
    while publishing without --force removes the files this call created.
    """
    items = [(Path(path), data) for path, data in items]
    for path, _ in items:
        check_writable(path, force)
    targets = [(real_target(path), data) for path, data in items]
    created: list[Path] = []
    staged: list[tuple[str, Path]] = []
    published: list[Path] = []
    try:
        for path, data in targets:
            staged.append((_stage(path, data, created), path))
        for tmp_name, path in staged:
            _publish(tmp_name, path, force)
            published.append(path)
        for directory in {path.parent for _, path in staged}:
            _fsync_dir(directory)
    except OSError as exc:
        raise write_error(exc, staged[-1][1] if staged else None) from exc
    finally:
        leftovers = [Path(tmp) for tmp, _ in staged if Path(tmp).exists()]
        for tmp in leftovers:
            tmp.unlink(missing_ok=True)
        if not force and len(published) < len(items):
            for path in published:
                path.unlink(missing_ok=True)
        if leftovers or len(staged) < len(items):
            for directory in reversed(created):
                try:
                    directory.rmdir()
                except OSError:
                    pass


def atomic_write_bytes(path: Path, data: bytes, *, force: bool = False,
                       backup: bool = False, in_place: bool = False) -> Path | None:
    """Write `data` to `path` atomically; returns the backup path when one was made.

    The data goes to a temporary file in the same directory and is renamed over the
    target, so a crash leaves either the old file or the new one, never a mix. `in_place`
    allows replacing a file this run read (the fixers that edit the user's model).
    """
    path = Path(path)
    check_writable(path, force, in_place=in_place)
    target = real_target(path)
    created: list[Path] = []
    tmp_name = _stage(target, data, created)
    try:
        backup_path = None
        if backup and target.exists():
            backup_path = _make_backup(target)
        _publish(tmp_name, target, force)
        _fsync_dir(target.parent)
    except OSError as exc:
        raise write_error(exc, path) from exc
    finally:
        Path(tmp_name).unlink(missing_ok=True)
    return backup_path


def atomic_write_text(path: Path, text: str, *, force: bool = False,
                      backup: bool = False, encoding: str = "utf-8",
                      in_place: bool = False) -> Path | None:
    data = text.encode("utf-8" if encoding == "utf-8-sig" else encoding)
    return atomic_write_bytes(path, data, force=force, backup=backup, in_place=in_place)


def write_stdout(text: str) -> None:
    """Text to standard output, as `-o -` asks."""
    import click

    click.echo(text, nl=False)
