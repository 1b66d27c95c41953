"""Where footzoo is being used from — Python, the command line or a study — so that a message names the fix that
applies there.

The command line and the study runner say where they are (:func:`used_from`); a message that tells the user
what to change asks :func:`fix` for its wording in each place and gets the one that applies (the recording
entry's ``foot:`` key in a study, ``--foot`` on the command line, ``footzoo.load(path, foot=...)`` in Python).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

#: The places footzoo is used from.
PLACES = ("python", "command line", "study")

_WHERE: ContextVar[str] = ContextVar("footzoo_used_from", default="python")


@contextmanager
def used_from(place: str) -> Iterator[None]:
    """Within the block, footzoo is used from ``place`` (one of :data:`PLACES`); the enclosing place after it."""
    if place not in PLACES:
        raise ValueError(f"used_from: place must be one of {PLACES}, got {place!r}")
    token = _WHERE.set(place)
    try:
        yield
    finally:
        _WHERE.reset(token)


def where() -> str:
    """The place footzoo is used from now (``"python"`` unless the command line or a study said otherwise)."""
    return _WHERE.get()


def fix(python: str, command_line: str | None = None, study: str | None = None) -> str:
    """The wording of a fix for the place footzoo is used from now (Python's where no other is given)."""
    return {"command line": command_line, "study": study}.get(where()) or python
