"""Where Gazebo finds a model: `model://NAME`, relative and absolute `<include>` URIs.

Lookup order (the including file's directory first, as libsdformat's findFile does, then
the search paths a Gazebo user sets):

1. the directory of the file that names the URI (and, for `model://NAME`, the directory
   holding that file's model directory, which is how a models/ folder is laid out);
2. every `--package-path` directory, used as a model root;
3. the colon-separated directories of GZ_SIM_RESOURCE_PATH, IGN_GAZEBO_RESOURCE_PATH,
   SDF_PATH and GAZEBO_MODEL_PATH, in that order.

A model directory is turned into its SDF file through `model.config`: the `<sdf>` entry
with the highest `version=` wins (libsdformat's choice); a directory without model.config
falls back to model.sdf.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

from lxml import etree

from reedtool.errors import ReedtoolError

RESOURCE_PATH_VARS = ("GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH", "SDF_PATH",
                      "GAZEBO_MODEL_PATH")


def env_roots() -> list[Path]:
    return [Path(p) for var in RESOURCE_PATH_VARS
            for p in os.environ.get(var, "").split(os.pathsep) if p]


def search_roots(including_file: Path, package_paths: Sequence[Path] = ()) -> list[Path]:
    """Directories a URI is looked up in, in order."""
    here = including_file.parent
    return [here, here.parent, *[Path(p) for p in package_paths], *env_roots()]


def _version_key(text: str) -> tuple[int, ...]:
    try:
        return tuple(int(part) for part in text.strip().split("."))
    except ValueError:
        return (-1,)


def model_sdf_in_dir(model_dir: Path) -> Path:
    """The SDF file a model directory stands for (model.config, else model.sdf)."""
    config = model_dir / "model.config"
    if config.is_file():
        try:
            root = etree.parse(str(config)).getroot()
        except (etree.XMLSyntaxError, OSError) as exc:
            raise ReedtoolError(f"{config}: cannot read model.config ({exc})") from None
        entries = [(el.get("version") or "", (el.text or "").strip())
                   for el in root.iter("sdf") if (el.text or "").strip()]
        if not entries:
            raise ReedtoolError(f"{config} names no <sdf> file")
        _version, name = max(entries, key=lambda entry: _version_key(entry[0]))
        path = model_dir / name
        if not path.is_file() and (model_dir / f"{name}.jinja").is_file():
            # PX4-SITL_gazebo-classic: model.config names iris.sdf, which its build renders
            # from iris.sdf.jinja (reedtool renders it too: io.sdf_jinja).
            return model_dir / f"{name}.jinja"
        if not path.is_file():
            raise ReedtoolError(f"{config} names '{name}', which does not exist")
        return path
    if (model_dir / "model.sdf").is_file():
        return model_dir / "model.sdf"
    raise ReedtoolError(f"model directory {model_dir} has neither model.config nor model.sdf")


def _as_sdf(candidate: Path) -> Path | None:
    if candidate.is_dir():
        return model_sdf_in_dir(candidate)
    if candidate.is_file():
        return candidate
    return None


REMOTE_SCHEMES = ("http://", "https://")


def is_remote_uri(uri: str) -> bool:
    """A Fuel or other web URI: Gazebo fetches it when the world loads (gz-sim through
    gz-fuel-tools, Classic through its model database); reedtool works offline."""
    return uri.strip().lower().startswith(REMOTE_SCHEMES)


REMOTE_NOT_CHECKED = ("is fetched by Gazebo from the web (Fuel) when the world loads; reedtool "
                      "works offline and could not check it")


def resolve_model_uri(uri: str, including_file: Path,
                      package_paths: Sequence[Path] = ()) -> Path:
    """The SDF file an `<include><uri>` names; ReedtoolError (no location) when not found."""
    if is_remote_uri(uri):
        raise ReedtoolError(f"'{uri}' {REMOTE_NOT_CHECKED}",
                            hint="to check it, download it (gz fuel download -u URI) and "
                                 "pass --package-path DIR with the folder holding it")
    if uri.startswith("file://"):
        uri = uri[len("file://"):]
    roots = search_roots(including_file, package_paths)
    if uri.startswith("model://"):
        rel = uri[len("model://"):].strip("/")
        candidates = [root / rel for root in roots]
    elif Path(uri).is_absolute():
        candidates = [Path(uri)]
    else:
        candidates = [root / uri for root in roots]
    for candidate in candidates:
        found = _as_sdf(candidate)
        if found is not None:
            return found
    where = "the including file's directory, --package-path, " + ", ".join(RESOURCE_PATH_VARS)
    raise ReedtoolError(f"included model '{uri}' not found (searched {where})")


def resolve_model_file_uri(uri: str, including_file: Path,
                           package_paths: Sequence[Path] = ()) -> Path:
    """A file inside a model (a mesh): `model://NAME/rest` -> the first root holding NAME."""
    name, _, rest = uri[len("model://"):].partition("/")
    for root in search_roots(including_file, package_paths):
        if root.name == name and root.is_dir():
            return root / rest
        if (root / name).is_dir():
            return root / name / rest
    raise ReedtoolError(f"model '{name}' not found in {', '.join(RESOURCE_PATH_VARS)} "
                        "or next to the model")
