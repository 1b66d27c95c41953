"""The interface of a stage of a run (:class:`Stage`) and the queue of samples between stages.

A stream pushes chunk after chunk through a pipeline's stages (:mod:`footzoo.runtime.stages`);
a batch run pushes the whole recording as one chunk with ``finish``. Chunks are dicts of
per-sample arrays (:data:`footzoo.plugins.incremental.Chunk`), all with the samples' absolute
index in ``k``.
"""

from __future__ import annotations

import abc
from typing import Any

import numpy as np

from ..plugins.incremental import Chunk, Columns, length, take


def pad_to(guess: Chunk, samples: Chunk, name: str, last: Any) -> np.ndarray:
    """``guess[name]`` for the first samples, then ``last`` repeated up to the length of ``samples``."""
    have = guess.get(name, np.zeros(0))
    n = length(samples)
    if len(have) >= n:
        return np.asarray(have[:n])
    fill = np.repeat(np.asarray([last]), n - len(have), axis=0)
    return np.concatenate([np.asarray(have), fill]) if len(have) else fill


class Queue:
    """Samples waiting between stages: appended at the end, taken from the front, by absolute index ``k``.

    Backed by :class:`~footzoo.plugins.incremental.Columns`: appending and taking cost the samples
    moved, not the samples held.
    """

    def __init__(self) -> None:
        self._columns = Columns()

    def put(self, chunk: Chunk) -> None:
        if length(chunk):
            self._columns.append(chunk)

    def take(self, stop_k: int) -> Chunk:
        """The samples with absolute index below ``stop_k`` (removed)."""
        if not len(self._columns):
            return {}
        view = self._columns.view()
        n = int(np.searchsorted(view["k"], stop_k))
        out = take(view, 0, n)
        self._columns.drop(n)
        return out

    def peek(self) -> Chunk:
        """The samples held (views: read them before the next change)."""
        return self._columns.view() if len(self._columns) else {}

    def __len__(self) -> int:
        return len(self._columns)


class Stage(abc.ABC):
    """One block of a pipeline in the chain of a run (batch or live).

    The first call decides how the stage runs: :meth:`push` of a chunk with ``finish`` is the
    whole recording at once, and the stage runs its block's batch code on it (:meth:`whole`);
    any other first call begins the block's incremental state (:meth:`begin`) and each push
    steps it (:meth:`step`). Either way the outputs of a sample are the same: the blocks'
    incremental protocol reproduces their batch code.
    """

    _begun = False  # the first call has been made

    def push(self, chunk: Chunk, finish: bool = False) -> Chunk:
        """The next samples (``finish``: the data ends after them); the samples whose outputs became final."""
        if not self._begun:
            self._begun = True
            if finish:  # one finished chunk: the whole recording
                return self.whole(chunk) if length(chunk) else {}
            self.begin()
        return self.step(chunk, finish)

    def finish(self) -> Chunk:
        """End of the data: the outputs of every sample not final yet."""
        return self.push({}, finish=True)

    def guess(self, extra: Chunk) -> Chunk:
        """The current guess for every sample after the final ones: the samples held, then ``extra``."""
        if not self._begun:
            self._begun = True
            self.begin()
        return self.provisional(extra)

    def begin(self) -> None:  # noqa: B027 (a stage without incremental state has nothing to begin)
        """Start the incremental state (the first push of a stream)."""

    @abc.abstractmethod
    def whole(self, chunk: Chunk) -> Chunk:
        """The outputs of a whole recording given as one chunk (the block's batch code)."""

    @abc.abstractmethod
    def step(self, chunk: Chunk, finish: bool) -> Chunk:
        """Push the next samples into the incremental state; the outputs that became final."""

    @abc.abstractmethod
    def held(self) -> int:
        """Samples pushed whose outputs are not final yet (the stage's memory)."""

    @abc.abstractmethod
    def provisional(self, extra: Chunk) -> Chunk:
        """:meth:`guess` once the state has begun."""

    def report(self) -> dict[str, Any]:
        """What the stage adds to ``Result.diagnostics`` (default: nothing)."""
        return {}
