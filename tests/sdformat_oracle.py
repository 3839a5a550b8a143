"""libsdformat, Gazebo's own SDFormat library, as the judge of every SDF reedtool writes.

Drake's parser (PyPI `drake`, in the `test` extra) reads SDFormat through libsdformat, so
a file libsdformat refuses (`::` in a name from SDF 1.8 on, a joint whose child is not a
link, a frame cycle, two siblings of one name, ...) raises here with libsdformat's own
message. Nothing is stripped from the file: what Drake cannot use but libsdformat accepts
(`<plugin>`, most `<sensor>` types) Drake only warns about and ignores, and a warning is
not a refusal. Drake refuses a few things Gazebo accepts, all of them outside what
reedtool writes; `drake_only_reason` tells them apart by message and declared version
(`DRAKE_ONLY_REFUSALS`), and a caller that meets one must say so.

`model://NAME` and `package://NAME` resolve through the directories given as
`model_dirs` (each a folder of model folders, as GZ_SIM_RESOURCE_PATH is): Drake looks
both up in its package map, where every model folder is added under its own name. Drake
resolves an include's URI to a file only, where libsdformat also takes a model folder and
reads its model.config; an `<include>` of a folder is pointed at the file its model.config
names before Drake reads it (`_includes_as_files`; an included file that includes folders
is staged beside itself with its includes pointed so), the one change made to any file.

Importing this module imports Drake (about a second); import it inside the tests that
use it, not at collection.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from lxml import etree
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

# Staged copies carry the process id: pytest-xdist workers loading the same fixture at once
# must never write, read or delete each other's copy.
_STAGED = f".drake-{os.getpid()}-"

# Drake-side refusals of files libsdformat itself accepts, each with why it is Drake's.
# Drake runs libsdformat with its warnings and unrecognized-element policies set to
# ERR (Gazebo's default is WARN) and adds a few limits of its own.
DRAKE_ONLY_REFUSALS = (
    (r"Drake does not support|is not supported by Drake", None,
     "a feature Drake's multibody plant does not model"),
    (r"not defined in SDF\. Copying|XML Attribute\[[^\]]*\] in element\[[^\]]*\] not "
     r"defined in SDF", None,
     "an element or attribute the file's SDF version does not define: libsdformat copies "
     "or drops it with a warning (PX4's <gz_frame_id>, 1.6's <use_parent_model_frame> "
     "or <pose frame=''> in a newer file)"),
    (r"LinkJointGraph already has joint", None,
     "Drake builds one joint between two links; libsdformat allows several"),
    (r"Drake must never use ParserConfig::GlobalConfig\(\)", None,
     "a Drake assertion met by elements libsdformat loads with its global configuration "
     "(particle emitters)"),
    (r"Non-unique name\[[^\]]*\] detected", (1, 7),
     "below SDF 1.7 libsdformat renames a link, joint or frame that takes a sibling's "
     "name, with a warning (Model.cc)"),
    (r"Get(Frame|ModelInstance|Body)ByName\(\): There is no", (1, 8),
     "below SDF 1.8 '::' may appear in a name; Drake's own lookup reads it as a scope"),
)


def drake_only_reason(error: str, version: str | None) -> str | None:
    """Why `error` is Drake's refusal of a file libsdformat (as Gazebo runs it) accepts,
    or None when it is libsdformat's own. `version`: the file's declared SDF version."""
    import re

    try:
        declared = tuple(int(part) for part in (version or "").split("."))
    except ValueError:
        declared = ()
    for pattern, below, reason in DRAKE_ONLY_REFUSALS:
        if re.search(pattern, error) and (below is None or (declared and declared < below)):
            return reason
    return None


def _parser(model_dirs) -> tuple[Parser, MultibodyPlant]:
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    package_map = parser.package_map()
    for root in model_dirs:
        root = Path(root)
        candidates = [root] if (root / "model.config").is_file() else sorted(root.iterdir())
        for model_dir in candidates:
            if model_dir.is_dir() and not package_map.Contains(model_dir.name):
                package_map.Add(model_dir.name, str(model_dir))
    return parser, plant


def _model_file(model_dir: Path) -> str | None:
    """The SDF file model.config names for its highest version, as libsdformat picks it."""
    config = model_dir / "model.config"
    if not config.is_file():
        return None
    sdf_nodes = etree.parse(str(config)).getroot().findall("sdf")
    if not sdf_nodes:
        return None
    best = max(sdf_nodes, key=lambda node: tuple(int(part) for part in
                                                 (node.get("version") or "0").split(".")))
    return (best.text or "").strip() or None


def _include_target(text: str, package_map) -> tuple[str, Path] | None:
    """(URI prefix, model folder) of an include naming a model folder of the package map:
    `model://NAME`, `package://NAME`, or a bare `NAME`, which gz-sim looks up in
    GZ_SIM_RESOURCE_PATH (PX4's x500_depth includes `<uri>x500</uri>`)."""
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "model", text
        if "/" in text.strip("/"):
            return None
    elif scheme not in ("model", "package"):
        return None
    name, _, sub = rest.partition("/")
    if sub.strip("/") or not package_map.Contains(name):
        return None
    return f"{scheme}://{name}", Path(package_map.GetPath(name))


def _includes_as_files(path: Path | None, package_map, text: str | None = None,
                       staged: list | None = None, pointed: list | None = None) -> str:
    """The file's text (or `text`) with each `<include>` of a model folder pointed at its
    SDF file. An included file that includes folders itself is staged beside itself
    (`.drake-PID-model.sdf`, listed in `staged` for the caller to remove) with its own
    includes pointed so; each `<uri>` pointed is listed in `pointed`. Text strict XML cannot
    read (TinyXML2 takes `--` in a comment) is handed to Drake as it is."""
    raw = path.read_bytes() if text is None else text.encode()
    try:
        tree = etree.ElementTree(etree.fromstring(raw))
    except etree.XMLSyntaxError:
        return raw.decode()
    for uri in tree.iter("uri"):
        if uri.getparent() is None or uri.getparent().tag != "include":
            continue
        target = _include_target((uri.text or "").strip(), package_map)
        model_file = _model_file(target[1]) if target else None
        if not model_file:
            continue
        prefix, folder = target
        inner = folder / model_file
        inner_text = _includes_as_files(inner, package_map, staged=staged)
        if staged is not None and inner_text != inner.read_text():
            copy = inner.with_name(f"{_STAGED}{inner.name}")
            copy.write_text(inner_text)
            staged.append(copy)
            model_file = copy.name
        uri.text = f"{prefix}/{model_file}"
        if pointed is not None:
            pointed.append(uri.text)
    return etree.tostring(tree, encoding="unicode")


def _load(path: Path | str, model_dirs) -> tuple[str | None, MultibodyPlant]:
    path = Path(path)
    parser, plant = _parser(model_dirs)
    staged: list[Path] = []
    try:
        pointed: list[str] = []
        text = _includes_as_files(path, parser.package_map(), staged=staged, pointed=pointed)
        if pointed:
            # Written beside the original, so relative mesh URIs resolve as they would there.
            staged.append(path.with_name(f"{_STAGED}{path.name}"))
            staged[-1].write_text(text)
        # No include pointed elsewhere: Drake reads the file itself, nothing is written.
        parser.AddModels(str(staged[-1] if pointed else path))
    except Exception as exc:  # noqa: BLE001 - pydrake raises RuntimeError for every refusal
        message = str(exc)
        for copy in staged:
            message = message.replace(str(copy), str(copy.with_name(copy.name[len(_STAGED):])))
        return message, plant
    finally:
        for copy in staged:
            copy.unlink(missing_ok=True)
    return None, plant


def libsdformat_error(path: Path | str, model_dirs=()) -> str | None:
    """libsdformat's refusal of the file at `path`, through Drake; None when it loads.

    `model_dirs`: folders holding model folders (or model folders themselves) that
    `model://` and `package://` URIs in the file name.
    """
    return _load(path, model_dirs)[0]


def libsdformat_error_text(text: str, model_dirs=()) -> str | None:
    """As `libsdformat_error`, for SDF given as a string (relative mesh URIs have no
    directory to resolve in). Loading a string skips what Drake does around a file and
    takes a few milliseconds where a file takes about a tenth of a second."""
    parser, _ = _parser(model_dirs)
    staged: list[Path] = []
    try:
        parser.AddModelsFromString(
            _includes_as_files(None, parser.package_map(), text, staged), "sdf")
    except Exception as exc:  # noqa: BLE001
        return str(exc)
    finally:
        for copy in staged:
            copy.unlink(missing_ok=True)
    return None


def body_count(path: Path | str, model_dirs=()) -> int:
    """How many bodies Drake built from the file (the world body included)."""
    error, plant = _load(path, model_dirs)
    if error:
        raise AssertionError(error)
    return plant.num_bodies()


# Drake logs every ignored <plugin>/<sensor> as a warning; the tests care about refusals.
logging.getLogger("drake").setLevel(logging.ERROR)


def mass_properties_text(text: str) -> dict[str, tuple[float, object, object]]:
    """{link name: (mass, COM in the link frame, 3x3 inertia about the COM in link axes)}
    as Drake builds its plant from SDF text through libsdformat (the world body left out)."""
    import numpy as np

    parser, plant = _parser(())
    parser.AddModelsFromString(text, "sdf")
    plant.Finalize()
    out = {}
    for index in range(1, plant.num_bodies()):
        body = plant.get_body(type(plant.world_body().index())(index))
        M = body.default_spatial_inertia()
        c = np.asarray(M.get_com())
        mass = M.get_mass()
        I_Bo = M.CalcRotationalInertia().CopyToFullMatrix3()
        out[body.name()] = (mass, c, I_Bo - mass * (c @ c * np.eye(3) - np.outer(c, c)))
    return out
