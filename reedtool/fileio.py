"""Safe writes: atomic replace, no clobbering without --force, optional backup.

Every file reedtool writes into a user's tree goes through here, so the rules
"nothing is lost" and "no half-written file" live in one place.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from .errors import ReedtoolError


def check_writable(path: Path, force: bool) -> None:
    """Refuse to overwrite an existing file unless forced."""
    if path.exists() and not force:
        raise ReedtoolError("refusing to overwrite an existing file", file=path,
                            hint="pass --force to replace it")


def atomic_write_bytes(path: Path, data: bytes, *, force: bool = False,
                       backup: bool = False) -> Path | None:
    """Write `data` to `path` atomically; returns the backup path when one was made.

    The data goes to a temporary file in the same directory and is renamed over the
    target, so a crash leaves either the old file or the new one, never a mix.
    """
    path = Path(path)
    check_writable(path, force)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ReedtoolError(f"cannot create directory: {exc.strerror}", file=path.parent) from exc
    backup_path = None
    if backup and path.exists():
        backup_path = path.with_name(path.name + ".bak")
        shutil.copy2(path, backup_path)
    fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        if path.exists():
            shutil.copymode(path, tmp_name)
        os.replace(tmp_name, path)
    except OSError as exc:
        Path(tmp_name).unlink(missing_ok=True)
        raise ReedtoolError(f"cannot write file: {exc.strerror}", file=path) from exc
    except BaseException:
        Path(tmp_name).unlink(missing_ok=True)
        raise
    return backup_path


def atomic_write_text(path: Path, text: str, *, force: bool = False,
                      backup: bool = False) -> Path | None:
    return atomic_write_bytes(path, text.encode("utf-8"), force=force, backup=backup)
