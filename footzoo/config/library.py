"""The configs shipped with footzoo, by name: ``Pipeline.from_yaml("recommended")`` from anywhere.

The YAML files live in the repository's top-level ``configs/`` folder; a wheel installs them as
``footzoo/configs/`` (``setup.py`` maps the folder into the package), so they are found by name in
an installed footzoo and in a source checkout alike. A name
is a file stem (``yun2012``), with or without ``.yaml``; a path to an existing file always
wins over a name, so a user's edited copy next to their data is read instead.
"""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

from ..core.errors import ConfigError, did_you_mean


def _shipped_folder() -> Path:
    """``footzoo/configs`` of an installed footzoo, else ``configs/`` beside the package in a source checkout."""
    package = Path(__file__).resolve().parents[1]
    installed = package / "configs"
    return installed if installed.is_dir() else package.parent / "configs"


#: Folder of the shipped YAML files.
BUILTIN = _shipped_folder()


def names(kind: str | None = None) -> list[str]:
    """Names of the shipped configs: ``kind`` ``"pipeline"``, ``"study"`` or None for both."""
    out = []
    for p in sorted(BUILTIN.glob("*.yaml")):
        study = p.stem.startswith("study_")
        if kind is None or (kind == "study") == study:
            out.append(p.stem)
    if kind not in (None, "pipeline", "study"):
        raise ConfigError(f"kind must be 'pipeline', 'study' or None, got {kind!r}")
    return out


def is_name(spec: str | Path) -> bool:
    """Whether ``spec`` names a shipped config rather than a file path."""
    s = str(spec)
    stem = s[:-5] if s.endswith(".yaml") else s
    return "/" not in s and "\\" not in s and (BUILTIN / f"{stem}.yaml").is_file()


def path(name: str) -> Path:
    """The file of the shipped config ``name`` (``recommended`` or ``recommended.yaml``)."""
    stem = name[:-5] if name.endswith(".yaml") else name
    p = BUILTIN / f"{stem}.yaml"
    if not p.is_file():
        known = names()
        raise ConfigError(f"no shipped config named {name!r}{did_you_mean(stem, known)}; shipped configs: {known} "
                          "(or give the path of a YAML file)")
    return p


def resolve(spec: str | Path) -> Path:
    """A config's file: ``spec`` itself when it exists, else the shipped config of that name.

    Raises
    ------
    ConfigError
        When ``spec`` is neither an existing file nor a shipped config's name.
    """
    if not isinstance(spec, (str, os.PathLike)):
        raise ConfigError(f"a config is a shipped config's name or the path of a YAML file, got {type(spec).__name__} "
                          f"{spec!r:.80}; a mapping goes to Pipeline.from_dict")
    if not str(spec).strip():
        raise ConfigError("the config is an empty name; give a shipped config's name (footzoo configs lists them) "
                          "or the path of a YAML file")
    p = Path(spec)
    if isinstance(spec, str) and not p.exists() and ("\n" in spec or re.match(r"\s*[\w.-]+\s*:\s", spec)):
        raise ConfigError(f"{spec[:60]!r} looks like the text of a YAML config, not a file name nor a shipped "
                          "config's name; write it to a .yaml file and give its path, or pass the mapping itself "
                          "(Pipeline.from_dict({...}))")
    if p.is_symlink() and not p.exists():
        return p  # a link in a loop or to nothing: the file's reader names why
    if not p.exists() and p.suffix in ("", ".yaml", ".yml") and p.parent != Path(".") and is_name(p.name):
        # e.g. configs/study_quick.yaml from a source checkout, run where footzoo is installed
        raise ConfigError(f"{str(spec)!r}: no such file; footzoo ships a config named {p.stem!r}: give its name "
                          f"alone ('{p.stem}'), which works from any folder, or the path of your own copy")
    if p.exists() or not is_name(spec):
        if not p.exists() and "/" not in str(spec) and "\\" not in str(spec) and p.suffix in ("", ".yaml", ".yml"):
            if p.suffix:  # a file name: say that the file is missing, then which names are shipped
                known = names()
                raise ConfigError(f"{str(spec)!r}: no such file in {str(Path.cwd())!r}, and no shipped config has that "
                                  f"name{did_you_mean(p.stem, known)}; check the path, or use a shipped config by "
                                  f"name: {known}")
            path(str(spec))  # a name that is not shipped: the error lists the shipped ones
        return p
    return path(str(spec))


def copy(name: str, dest: str | Path = ".", overwrite: bool = False) -> Path:
    """Copy the shipped config ``name`` to ``dest`` (a folder, or a file name) to edit it; returns the new file.

    ``dest`` is a folder when it is one, ends in ``/`` or has no extension (created when missing), else a
    ``.yaml``/``.yml`` file name.

    Raises
    ------
    ConfigError
        When the target exists (unless ``overwrite``) or ``name`` is not shipped.
    """
    src = path(name)
    d = Path(dest)
    folder = d.is_dir() or str(dest).endswith(("/", os.sep)) or (not d.exists() and not d.suffix)
    if not folder and d.suffix not in (".yaml", ".yml"):
        raise ConfigError(f"{str(dest)!r}: a config is a YAML file; name the copy '{d.stem}.yaml', or give a folder "
                          f"(ending in '/') to copy {src.name} into")
    target = d / src.name if folder else d
    if target.exists() and not overwrite:
        raise ConfigError(f"{target} exists; choose another destination, or overwrite it (--force; overwrite=True)")
    if target.resolve() == src.resolve():
        raise ConfigError(f"{target} is the shipped file itself; copy it elsewhere")
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.tmp")
    shutil.copyfile(src, tmp)
    tmp.replace(target)
    return target
