"""libsdformat, Gazebo's own SDFormat library, as the judge of every SDF reedtool writes.

Drake's parser (PyPI `drake`, in the `test` extra) reads SDFormat through libsdformat, so
a file libsdformat refuses (`::` in a name from SDF 1.8 on, a joint whose child is not a
link, a frame cycle, two siblings of one name, ...) raises here with libsdformat's own
message. Nothing is stripped from the file: what Drake cannot use but libsdformat accepts
(`<plugin>`, most `<sensor>` types) Drake only warns about and ignores, and a warning is
not a refusal. Drake refuses a few things Gazebo accepts, all of them outside what
reedtool writes; `DRAKE_ONLY_REFUSALS` names them, and a caller that meets one must say so.

`model://NAME` and `package://NAME` resolve through the directories given as
`model_dirs` (each a folder of model folders, as GZ_SIM_RESOURCE_PATH is): Drake looks
both up in its package map, where every model folder is added under its own name. Drake
resolves an include's URI to a file only, where libsdformat also takes a model folder and
reads its model.config; an `<include>` of a folder is pointed at the file its model.config
names before Drake reads it (`_includes_as_files`), the one change made to any file.

Importing this module imports Drake (about a second); import it inside the tests that
use it, not at collection.
"""

from __future__ import annotations

import logging
from pathlib import Path

from lxml import etree
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

# Drake-side refusals of files libsdformat itself accepts. None is expected in reedtool's
# output; a test that meets one is looking at Drake, not at libsdformat.
DRAKE_ONLY_REFUSALS = (
    "Drake does not support",
    "is not supported by Drake",
)


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


def _includes_as_files(path: Path | None, package_map, text: str | None = None) -> str:
    """The file's text (or `text`) with each `<include>` of a model folder pointed at its
    SDF file."""
    tree = etree.parse(str(path)) if text is None else etree.ElementTree(
        etree.fromstring(text.encode()))
    for uri in tree.iter("uri"):
        if uri.getparent() is None or uri.getparent().tag != "include":
            continue
        text = (uri.text or "").strip()
        scheme, sep, rest = text.partition("://")
        if not sep or scheme not in ("model", "package"):
            continue
        name, _, sub = rest.partition("/")
        if sub.strip("/") or not package_map.Contains(name):
            continue
        model_file = _model_file(Path(package_map.GetPath(name)))
        if model_file:
            uri.text = f"{scheme}://{name}/{model_file}"
    return etree.tostring(tree, encoding="unicode")


def _load(path: Path | str, model_dirs) -> tuple[str | None, MultibodyPlant]:
    path = Path(path)
    parser, plant = _parser(model_dirs)
    try:
        text = _includes_as_files(path, parser.package_map())
    except etree.XMLSyntaxError as exc:
        return f"{path}: not XML: {exc}", plant
    # Written beside the original, so relative mesh URIs resolve as they would there.
    staged = path.with_name(f".drake-{path.name}")
    staged.write_text(text)
    try:
        parser.AddModels(str(staged))
    except Exception as exc:  # noqa: BLE001 - pydrake raises RuntimeError for every refusal
        return str(exc).replace(str(staged), str(path)), plant
    finally:
        staged.unlink()
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
    try:
        text = _includes_as_files(None, parser.package_map(), text)
    except etree.XMLSyntaxError as exc:
        return f"not XML: {exc}"
    try:
        parser.AddModelsFromString(text, "sdf")
    except Exception as exc:  # noqa: BLE001
        return str(exc)
    return None


def body_count(path: Path | str, model_dirs=()) -> int:
    """How many bodies Drake built from the file (the world body included)."""
    error, plant = _load(path, model_dirs)
    if error:
        raise AssertionError(error)
    return plant.num_bodies()


# Drake logs every ignored <plugin>/<sensor> as a warning; the tests care about refusals.
logging.getLogger("drake").setLevel(logging.ERROR)
