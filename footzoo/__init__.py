"""footzoo: foot-mounted IMU motion estimation, a zoo of published building blocks.

Conventions: NED navigation frame, FRD body frame, scalar-first body -> NED
quaternions, SI units (see :mod:`footzoo.conventions`).
"""

from ._version import __version__  # noqa: E402
from .data import Recording, Result, Truth  # noqa: E402
from .errors import ConfigError, FootzooError, FormatError, RecordingError  # noqa: E402
from .io import load  # noqa: E402
from .pipeline import Pipeline  # noqa: E402
from .registry import register  # noqa: E402
from .session import Session, SessionResult  # noqa: E402

__all__ = [
    "ConfigError",
    "FootzooError",
    "FormatError",
    "Pipeline",
    "Recording",
    "RecordingError",
    "Result",
    "Session",
    "SessionResult",
    "Truth",
    "load",
    "register",
    "__version__",
]
