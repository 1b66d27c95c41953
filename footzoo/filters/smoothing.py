"""The smoothers of the Kalman pipelines, one design: where segments end, and what the forward pass keeps.

A smoother corrects the forward filter's estimates with the closed-loop RTS recursion of
:mod:`footzoo.filters.smoother`, segment by segment, each segment smoothed from the filtered
estimate at its end (``e_end = 0``). The smoothers differ only in where their segments end:

``none`` (:class:`NoSmoothing`)
    No segment: the forward filter's estimates.
``rts`` (:class:`Rts`, Rauch, Tung & Striebel 1965)
    One segment, the whole recording: offline only.
``stepwise`` (:class:`Stepwise`, Colomar, Nilsson & Händel 2012)
    A segment per stride (:func:`footzoo.filters.stepwise.segment_ends`): live, with the latency
    of one stride.

How an implementation keeps what the recursion reads is its own business, chosen by the
smoother's type (the reference engine keeps a row per sample; the compiled one smooths each stride
in the loop, and the whole recording in bounded memory: :mod:`footzoo.filters.compiled`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from ..core.errors import ConfigError
from .smoother import smooth_segments
from .stepwise import WAITS_FOR, segment_ends, smooth_strides
from .structures import Offsets, Record, Trajectory


class Smoothing(ABC):
    """Where a smoother's segments end (module docstring)."""

    #: The name in a config's ``smoother:``.
    name: ClassVar[str]
    #: What a live stream's smoothed estimate of a sample waits for ("" : nothing; None: cannot run live).
    waits_for: ClassVar[str | None]

    @abstractmethod
    def ends(self, stance: np.ndarray, t: np.ndarray, closed: bool) -> np.ndarray:
        """The last sample of each segment that has closed (int, increasing); ``closed``: the data ends here."""

    def smooth(self, rec: Record, ends: np.ndarray, offsets: Offsets, use_ext: bool, traj: Trajectory,
               t: np.ndarray) -> None:
        """Smooth ``traj`` in place, segment by segment up to each of ``ends`` (sample k in row k of ``rec``; ``t``
        (N,) s): the closed-loop RTS recursion of :func:`footzoo.filters.smoother.smooth_segments`."""
        smooth_segments(rec, ends, 0, 0, offsets, use_ext, traj)

    def __bool__(self) -> bool:
        return self.name != "none"


class NoSmoothing(Smoothing):
    """The forward filter's estimates."""

    name = "none"
    waits_for = ""

    def ends(self, stance: np.ndarray, t: np.ndarray, closed: bool) -> np.ndarray:
        return np.zeros(0, np.int64)


class Rts(Smoothing):
    """The RTS smoother over the whole recording: one segment, ending at the last sample."""

    name = "rts"
    waits_for = None

    def ends(self, stance: np.ndarray, t: np.ndarray, closed: bool) -> np.ndarray:
        return np.array([len(t) - 1], np.int64) if closed and len(t) else np.zeros(0, np.int64)


class Stepwise(Smoothing):
    """The step-wise smoother: a segment per stride (:mod:`footzoo.filters.stepwise`)."""

    name = "stepwise"
    waits_for = WAITS_FOR

    def ends(self, stance: np.ndarray, t: np.ndarray, closed: bool) -> np.ndarray:
        return segment_ends(stance, t, closed)

    def smooth(self, rec: Record, ends: np.ndarray, offsets: Offsets, use_ext: bool, traj: Trajectory,
               t: np.ndarray) -> None:
        """Each stride smoothed and its start pinned (:func:`footzoo.filters.stepwise.smooth_strides`)."""
        smooth_strides(rec, ends, 0, 0, offsets, use_ext, traj, np.ascontiguousarray(t, dtype=float))


#: The smoothers by name.
SMOOTHERS: dict[str, Smoothing] = {s.name: s for s in (NoSmoothing(), Rts(), Stepwise())}


def smoothing(spec: bool | str | Smoothing) -> Smoothing:
    """The smoother a config names (``True``: ``rts``, ``False``: ``none``)."""
    if isinstance(spec, Smoothing):
        return spec
    name = {True: "rts", False: "none"}.get(spec, spec) if isinstance(spec, bool) else spec
    if name not in SMOOTHERS:
        raise ConfigError(f"smoother must be one of {list(SMOOTHERS)}, got {spec!r}")
    return SMOOTHERS[name]
