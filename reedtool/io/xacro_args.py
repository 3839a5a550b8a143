"""Which xacro arguments a model declares, and where the arguments given to it came from.

xacro silently ignores a `name:=value` the model never reads, so a misspelt argument
(`mav_nmae:=...`) leaves the default in place without a word. A model "knows" an argument
when a file of its include tree declares it (`<xacro:arg name=...>`) or reads it
(`$(arg name)`); the include tree is followed statically, as the legacy scan does.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

from reedtool.model import SourceLoc

_DECLARED = re.compile(r"<(?:[\w.-]+:)?arg\b[^>]*?\bname\s*=\s*[\"']([^\"']+)[\"']")
_READ = re.compile(r"\$\(arg\s+([^)\s]+)\s*\)")


@dataclass(frozen=True)
class ArgumentUse:
    """The arguments given to one model and the names its xacro files know."""

    declared: frozenset[str]
    given: Mapping[str, SourceLoc | None] = field(default_factory=dict)  # name -> where
    origins: Mapping[str, str] = field(default_factory=dict)     # name -> "--launch X" etc.
    complete: bool = True    # False: an include could not be followed, names may be missing


def known_arguments(path: Path, mappings: Mapping[str, str] | None = None,
                    package_paths: Sequence[Path] = ()) -> tuple[frozenset[str], bool]:
    """Argument names declared or read in the include tree of `path`; and whether every
    include of the tree could be followed (when not, a name may be missing)."""
    from reedtool.io.legacy_xacro import include_specs
    from reedtool.resolve.packages import PackageResolver
    from reedtool.io.xacro_expand import include_texts, static_include_resolver

    mappings = dict(mappings or {})
    texts = include_texts(Path(path), mappings, package_paths)
    resolve = static_include_resolver(PackageResolver(package_paths, model_path=Path(path)),
                                       mappings)
    names: set[str] = set()
    complete = bool(texts)
    for file, text in texts.items():
        names.update(_DECLARED.findall(text))
        names.update(_READ.findall(text))
        for spec in include_specs(text):
            target = resolve(spec, file)
            if target is None or not target.is_file():
                complete = False
    return frozenset(names), complete
