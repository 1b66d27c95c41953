"""Exceptions footzoo raises; every message names the problem and the fix."""


class FootzooError(Exception):
    """Base class of footzoo's own errors."""


class RecordingError(FootzooError, ValueError):
    """A recording is malformed: missing columns, bad time stamps, wrong units, …"""


class ConfigError(FootzooError, ValueError):
    """A pipeline configuration is invalid: unknown keys, types or values."""


class FormatError(FootzooError, ValueError):
    """A file cannot be read in the requested (or detected) format."""


class FootzooWarning(UserWarning):
    """Something footzoo repaired or bridged that the user should know about (e.g. a short logger gap)."""
