"""Every problem of a pipeline config at once (``footzoo validate``), not only the first.

``Pipeline.from_dict`` stops at the first error; :func:`config_errors` checks
the top-level keys, then builds each plug-in on its own so that an error in one
does not hide the others, then (when all built) their compatibility.
"""

from __future__ import annotations

from typing import Any

from ..config.schema import top_level_errors
from ..core.errors import ConfigError
from ..plugins.registry import build
from .pipeline import Pipeline


def config_errors(d: dict[str, Any]) -> list[str]:
    """All problems of the config mapping ``d``, each a message naming the place and the fix; empty when valid."""
    errors = top_level_errors(d)
    if not isinstance(d, dict):
        return errors
    sections: list[tuple[str, str, Any]] = [(k, k, d[k]) for k in ("orientation", "detector") if k in d]
    for key, kind in (("calibration", "calibration"), ("corrections", "correction"), ("analysis", "analysis")):
        items = d.get(key) or []
        if isinstance(items, list):
            sections += [(f"{key}[{i}]", kind, spec) for i, spec in enumerate(items)]
    for where, kind, spec in sections:
        try:
            build(kind, spec, where)
        except ConfigError as err:
            errors.append(str(err))
    if not errors:
        try:
            Pipeline.from_dict(d)
        except ConfigError as err:
            errors.append(str(err))
    return errors
