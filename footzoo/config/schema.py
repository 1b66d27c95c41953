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

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..core.checks import GRAVITY_RANGE, Settings
from ..core.conventions import GRAVITY as GRAVITY_DEFAULT
from ..core.errors import ConfigError, did_you_mean
from ..core.params import Declared, Real
from ..core.yamlsafe import load_file
from .library import resolve

TOP_LEVEL_KEYS: dict[str, str] = {
    "name": "pipeline name (text)",
    "description": "free text",
    "gravity": "gravity magnitude g (m/s²), default 9.81",
    "init": "initial alignment: {duration: s of stillness at the start (default 0.5)}",
    "calibration": "list of in-situ sensor calibrations applied first [{type: hard_iron}, ...]",
    "orientation": "orientation plug-in {type: ..., params}",
    "detector": "stance detector plug-in {type: ..., params}",
    "corrections": "list of correction plug-ins [{type: ..., params}, ...]",
    "analysis": "list of analysis plug-ins [{type: huang_fpa, ...}] run on the result",
    "smoother": "none (default), rts: Rauch-Tung-Striebel smoothing of the Kalman filter over the whole recording "
                "(offline), or stepwise: the same smoothing stride by stride (runs live)",
    "navigation": "process noise and initial uncertainty of the Kalman filter's INS core: {velocity_noise: 0.01, "
                  "...} (footzoo list --kind settings)",
    "guards": "what happens when the detector misses stances: {max_swing: 1.5, max_speed: 50, ...} "
              "(footzoo list --kind settings)",
    "plugins": "external plug-ins to load first: module names or .py paths (relative to the YAML file)",
}
REQUIRED = ("orientation", "detector")


#: Longest accepted ``init.duration`` (s): the still start used for the initial alignment.
INIT_DURATION_MAX = 60.0

#: The declaration of ``gravity``, the magnitude g (m/s²) a pipeline removes from the specific force.
GRAVITY_PARAMETER = Declared(
    "gravity", Real("m/s^2", f"[{GRAVITY_RANGE[0]}, {GRAVITY_RANGE[1]}]", "gravity magnitude g",
                    source="footzoo's conventions: 9.81 m/s²",
                    why="Earth's surface gravity lies between 9.76 and 9.834 m/s²"),
    GRAVITY_DEFAULT)


@dataclass
class Init(Settings):
    """The still start used for the initial alignment (``init:`` of a config).

    Parameters
    ----------
    duration : float
        Longest stretch of the start taken as still (s).
    max_gyr : float
        Largest angular rate of a still sample (rad/s).
    """

    duration: float = 0.5
    max_gyr: float = 0.6

    section = "init"
    example = "{duration: 0.5}"
    parameters = {
        "duration": Real("s", f"(0, {INIT_DURATION_MAX:g}]", "longest stretch of the start taken as still",
                         source="footzoo's: half a second of a quiet stand",
                         why="a minute of standing is plenty"),
        "max_gyr": Real("rad/s", "(0, 10]", "largest |ω| of a still sample", source="footzoo's: 0.6 rad/s",
                        why="a foot turning at 10 rad/s (573 °/s) is not still"),
    }


#: The keys of ``init:`` and their defaults.
INIT_KEYS: dict[str, Any] = Init().to_dict()


def load_yaml(path: str | Path) -> dict[str, Any]:
    """Read a YAML config (a path, or a shipped config's name) with the strict, bounded loader.

    See :mod:`footzoo.core.yamlsafe` for the loader and :func:`footzoo.config.library.resolve` for names.
    """
    p = resolve(path)
    data = load_file(p, ConfigError, "config file")
    if data is None:
        raise ConfigError(f"{p}: the file is empty; a config needs at least 'orientation' and 'detector'")
    if not isinstance(data, dict):
        raise ConfigError(f"{p}: the top level must be a mapping, got {type(data).__name__}")
    data.setdefault("name", p.stem)
    return data


def is_study_file(d: Any) -> bool:
    """True for a study or tune file's mapping (``base`` and ``recordings``, no ``orientation`` or ``detector``)."""
    return isinstance(d, dict) and {"base", "recordings"} <= set(d) and not {"orientation", "detector"} & set(d)


def top_level_errors(d: dict[str, Any]) -> list[str]:
    """Every problem with the top-level keys of a config (unknown, missing, badly typed), as messages."""
    if not isinstance(d, dict):
        hint = (f": a shipped config's name or a YAML file goes to Pipeline.from_yaml({d!r:.60})" if isinstance(d, str)
                else " of keys (orientation, detector, corrections, ...)")
        return [f"a config must be a mapping, got {type(d).__name__}{hint}"]
    if is_study_file(d):
        kind = "tune" if "tune" in d else "study"
        verb = "footzoo tune" if kind == "tune" else "footzoo ablate"
        return [f"this is a {kind} file (base, recordings), not a pipeline config: run it with {verb} FILE "
                "(footzoo validate FILE checks it); footzoo run takes a pipeline config (orientation, detector, ...)"]
    errors = []
    valid = list(TOP_LEVEL_KEYS)
    for key in d:
        if key not in TOP_LEVEL_KEYS:
            errors.append(f"unknown config key {key!r}{did_you_mean(key, valid)}; valid keys: {valid}")
    name = d.get("name")
    if "name" in d and (not isinstance(name, str) or not name.strip() or any(c in name for c in '/\\:\0')):
        errors.append(f"name must be a non-empty text without '/', '\\' or ':' (it names output files and "
                      f"study rows), got {type(name).__name__} {name!r}")
    for key in ("description",):
        if d.get(key) is not None and not isinstance(d[key], str):
            errors.append(f"{key} must be text, got {type(d[key]).__name__} {d[key]!r}; quote it")
    for key in REQUIRED:
        if key not in d:
            errors.append(f"config is missing {key!r} ({TOP_LEVEL_KEYS[key]})")
    init = d.get("init", {}) or {}
    if not isinstance(init, dict):
        errors.append(f"init must be a mapping like {Init.example}, got {init!r}")
    else:
        for key in init:
            if key not in INIT_KEYS:
                errors.append(f"unknown init key {key!r}{did_you_mean(str(key), list(INIT_KEYS))}; "
                              f"valid: {list(INIT_KEYS)}")
    for key, example in (("corrections", "[{type: zvu_dedrift}]"), ("analysis", "[{type: huang_fpa}]"),
                         ("calibration", "[{type: hard_iron}]")):
        if not isinstance(d.get(key, []) or [], list):
            errors.append(f"{key} must be a list, e.g. {example}")
    return errors


def check_top_level(d: dict[str, Any]) -> None:
    """Reject unknown or missing top-level keys, listing the valid ones (every problem in one message)."""
    errors = top_level_errors(d)
    if errors:
        raise ConfigError("; ".join(errors))


def check_init(init: dict[str, Any]) -> dict[str, float]:
    """Validate ``init`` (``duration`` in s, ``max_gyr`` in rad/s) and fill in the defaults."""
    return Init.from_dict(init).to_dict()
