"""Config files: the pipeline schema (:mod:`~footzoo.config.schema`) and the shipped configs by name
(:mod:`~footzoo.config.library`)."""

from .library import BUILTIN, copy, is_name, names, path, resolve
from .schema import INIT_KEYS, TOP_LEVEL_KEYS, check_init, check_top_level, load_yaml, top_level_errors

__all__ = ["BUILTIN", "INIT_KEYS", "TOP_LEVEL_KEYS", "check_init", "check_top_level", "copy", "is_name", "load_yaml",
           "names", "path", "resolve", "top_level_errors"]
