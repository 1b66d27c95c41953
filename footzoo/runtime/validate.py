"""Every problem of a pipeline config at once (``footzoo validate``), not only the first.

``Pipeline.from_dict`` stops at the first error; :func:`config_errors` goes the same way
(:func:`~footzoo.runtime.pipeline.pipeline_arguments`: the ``plugins:`` list loaded first, relative
to the config file's folder, then each plug-in built) but builds each section on its own, so that
an error in one does not hide the others, then (when all built) checks their compatibility.
:func:`settings_declarations` gives the declarations of the settings blocks, for ``footzoo list``
and the documentation.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..config.schema import GRAVITY_PARAMETER, Init, top_level_errors
from ..core.errors import ConfigError
from ..core.params import Declared
from ..filters.engine import NavigationNoise
from .guards import StanceGuard
from .pipeline import Pipeline, pipeline_arguments


def config_errors(d: dict[str, Any], base_dir: str | Path | None = None) -> list[str]:
    """All problems of the config mapping ``d``, each a message naming the place and the fix; empty when valid.

    Parameters
    ----------
    d : dict
        The config mapping.
    base_dir : path, optional
        The config file's folder: its ``plugins:`` paths are relative to it (as in ``footzoo run``).
    """
    errors = top_level_errors(d)
    if not isinstance(d, dict):
        return errors
    arguments = pipeline_arguments(d, base_dir, errors)
    if not errors:
        try:
            Pipeline(**arguments)
        except ConfigError as err:
            errors.append(str(err))
    return errors


def settings_declarations() -> dict[str, Declared]:
    """``{name: Declared}`` of a config's settings, named as in a config (``gravity``, ``init.duration``, ...)."""
    out = {"gravity": GRAVITY_PARAMETER}
    for block in (Init, NavigationNoise, StanceGuard):
        out.update({f"{block.section}.{k}": d for k, d in block.declaration().items()})
    return out
