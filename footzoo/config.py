"""YAML pipeline configurations: parsing and validation with did-you-mean errors.

A configuration::

    name: yun2012
    gravity: 9.81                 # m/s²
    init: {duration: 0.5}         # still period at the start used for alignment (s)
    orientation: {type: fqa_complementary, static_gain: 1.05, dynamic_gain: 0.0}
    detector:    {type: angular_rate_fsm, threshold: 0.6, min_duration: 0.1}
    corrections:
      - {type: zvu_dedrift}
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from .errors import ConfigError
from .registry import did_you_mean

TOP_LEVEL_KEYS: dict[str, str] = {
    "name": "pipeline name (text)",
    "description": "free text",
    "gravity": "gravity magnitude g (m/s²), default 9.81",
    "init": "initial alignment: {duration: s of stillness at the start (default 0.5)}",
    "orientation": "orientation plug-in {type: ..., params}",
    "detector": "stance detector plug-in {type: ..., params}",
    "corrections": "list of correction plug-ins [{type: ..., params}, ...]",
    "analysis": "list of analysis plug-ins [{type: huang_fpa, ...}] run on the result",
    "plugins": "external plug-ins to load first: module names or .py paths (relative to the YAML file)",
}
INIT_KEYS: dict[str, Any] = {"duration": 0.5, "max_gyr": 0.6}
REQUIRED = ("orientation", "detector")


def load_yaml(path: str | Path) -> dict[str, Any]:
    """Read a YAML file into a dict, with clear errors for missing or empty files."""
    p = Path(path)
    if not p.exists():
        raise ConfigError(f"config file {str(p)!r} does not exist; check the path (footzoo ships configs/*.yaml)")
    try:
        data = yaml.safe_load(p.read_text())
    except yaml.YAMLError as err:
        raise ConfigError(f"{p}: not valid YAML: {err}") from None
    if data is None:
        raise ConfigError(f"{p}: the file is empty; a config needs at least 'orientation' and 'detector'")
    if not isinstance(data, dict):
        raise ConfigError(f"{p}: the top level must be a mapping, got {type(data).__name__}")
    data.setdefault("name", p.stem)
    return data


def check_top_level(d: dict[str, Any]) -> None:
    """Reject unknown or missing top-level keys, listing the valid ones."""
    if not isinstance(d, dict):
        raise ConfigError(f"a config must be a mapping, got {type(d).__name__}")
    valid = list(TOP_LEVEL_KEYS)
    for key in d:
        if key not in TOP_LEVEL_KEYS:
            raise ConfigError(f"unknown config key {key!r}{did_you_mean(key, valid)}; valid keys: {valid}")
    for key in REQUIRED:
        if key not in d:
            raise ConfigError(f"config is missing {key!r} ({TOP_LEVEL_KEYS[key]})")
    init = d.get("init", {}) or {}
    if not isinstance(init, dict):
        raise ConfigError(f"init must be a mapping like {{duration: 0.5}}, got {init!r}")
    for key in init:
        if key not in INIT_KEYS:
            raise ConfigError(f"unknown init key {key!r}{did_you_mean(key, list(INIT_KEYS))}; valid: {list(INIT_KEYS)}")
    for key, example in (("corrections", "[{type: zvu_dedrift}]"), ("analysis", "[{type: huang_fpa}]")):
        if not isinstance(d.get(key, []) or [], list):
            raise ConfigError(f"{key} must be a list, e.g. {example}")
