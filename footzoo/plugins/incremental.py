"""The incremental protocol: how every block runs live, and how far it looks ahead.

Every detector, orientation filter, correction and guard of a pipeline runs both on a whole
recording (its one action method: ``detect``, ``estimate``, ``apply``, ...) and sample by
sample (``begin(ctx)``, then ``step(...)`` for each new chunk of samples, ``finish()`` at the
end of the data). ``step`` returns the per-sample outputs of the samples whose output has
become **final** — it will not change whatever comes next — in order, as a dict of arrays
(a detector's ``stance``, an orientation filter's ``quat``, ...); ``provisional()`` gives the
block's current guess for the samples pushed but not final yet. Fed the same samples in any
chunks, a block's final outputs equal its batch outputs: that is what makes a live
:class:`footzoo.Stream` give the batch :meth:`footzoo.Pipeline.run`'s numbers.

A block declares how long after a sample its final output comes: :meth:`latency` returns a
:class:`Latency` — seconds of look-ahead (0 for a causal filter, half a window for a centred
window) and the events it waits for ("the end of the swing" for a dedrift that corrects a
swing once it has ended).

Two ways to implement ``step``:

* **carry the state** — a recursive filter (the orientation filters, the Kalman engine, DGP's
  dynamic threshold) keeps its state between calls and processes each sample once;
* **overlap-save** (:class:`OverlapSave`) — a computation that looks a bounded way ahead (a
  centred window, a state machine that dates its switches back, a swing corrected at its end)
  is recomputed, with its batch code, over a window of the recent samples that starts at a
  *restart point*: a sample from which the computation started afresh gives the same outputs
  as the whole recording (any sample one window back for a centred window; the end of a stance
  for the state machines). The batch code stays the one source of the numbers.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

#: The event a block that is not incremental waits for.
WHOLE_RECORDING = "the end of the recording"

#: Per-sample outputs of a block, one array per name, all of the same length (the samples' count).
Chunk = dict[str, np.ndarray]


@dataclass(frozen=True)
class Latency:
    """How long after a sample a block's output for it is final.

    Parameters
    ----------
    seconds : float
        Fixed look-ahead (s): 0 for a causal block, half the window for a centred window.
    until : tuple of str
        Events the block waits for beyond that (e.g. ``"the end of the swing"``); their time
        depends on the gait.
    warmup : float
        At the start of a run only: how long the block collects samples before its first
        output (s), e.g. to learn a reference (0: none).
    """

    seconds: float = 0.0
    until: tuple[str, ...] = ()
    warmup: float = 0.0

    def __add__(self, other: Latency) -> Latency:
        """Blocks in a chain: the look-aheads and warm-ups add up, the events are all waited for."""
        return Latency(self.seconds + other.seconds, tuple(dict.fromkeys(self.until + other.until)),
                       self.warmup + other.warmup)

    @property
    def causal(self) -> bool:
        """Final at once: no look-ahead and no event."""
        return self.seconds == 0.0 and not self.until

    @property
    def live(self) -> bool:
        """Can run live: a bounded look-ahead (it does not wait for the end of the recording)."""
        return math.isfinite(self.seconds) and WHOLE_RECORDING not in self.until

    def __str__(self) -> str:
        if self.causal:
            text = "0 s (causal)"
        elif self.seconds == 0.0:
            text = "until " + " + ".join(self.until)
        else:
            text = " + ".join([f"{self.seconds:.3g} s", *self.until])
        return text + (f"; warm-up {self.warmup:.3g} s at the start" if self.warmup else "")

    def to_dict(self) -> dict[str, Any]:
        """Plain values (for listings and results)."""
        return {"seconds": self.seconds, "until": list(self.until), "warmup": self.warmup, "text": str(self)}


def total(latencies: Iterable[Latency]) -> Latency:
    """The latency of blocks run one after the other."""
    out = Latency()
    for lat in latencies:
        out = out + lat
    return out


def concat(parts: Iterable[Chunk], copy: bool = True) -> Chunk:
    """Chunks of consecutive samples, joined key by key (empty parts skipped).

    ``copy=False``: a single non-empty part is returned with its own arrays, not copies (a batch
    run's ``step`` followed by an empty ``finish``, whose output nothing else holds).
    """
    parts = [p for p in parts if p]
    if not parts:
        return {}
    if len(parts) == 1 and not copy:
        return dict(parts[0])
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def length(chunk: Chunk) -> int:
    """Number of samples of a chunk."""
    return 0 if not chunk else len(next(iter(chunk.values())))


def take(chunk: Chunk, start: int, stop: int | None = None) -> Chunk:
    """Samples ``start:stop`` of a chunk (copies)."""
    return {k: np.array(v[start:stop]) for k, v in chunk.items()}


class Columns:
    """Per-sample arrays that grow at the end and are dropped at the front, without copying the rest.

    Appending copies only the new samples into spare capacity (doubled when full); dropping the
    front moves a start index (the arrays are compacted when more than half of them is dropped).
    :meth:`view` gives the current samples as views: read them before the next change.
    """

    def __init__(self) -> None:
        self._data: dict[str, np.ndarray] = {}
        self._lo = 0
        self._hi = 0

    def __len__(self) -> int:
        return self._hi - self._lo

    def append(self, chunk: Chunk) -> None:
        n = length(chunk)
        if not n:
            return
        if not self._data:
            self._data = {k: np.empty((max(2 * n, 64), *np.shape(v)[1:]), dtype=np.asarray(v).dtype)
                          for k, v in chunk.items()}
        cap = next(iter(self._data.values())).shape[0]
        if self._hi + n > cap:
            keep = self._hi - self._lo
            new_cap = max(2 * (keep + n), 64)
            for k, arr in self._data.items():
                grown = np.empty((new_cap, *arr.shape[1:]), dtype=arr.dtype)
                grown[:keep] = arr[self._lo:self._hi]
                self._data[k] = grown
            self._lo, self._hi = 0, keep
        for k, arr in self._data.items():
            arr[self._hi:self._hi + n] = chunk[k]
        self._hi += n

    def drop(self, n: int) -> None:
        """Forget the first ``n`` samples."""
        self._lo = min(self._lo + max(int(n), 0), self._hi)

    def view(self) -> Chunk:
        return {k: v[self._lo:self._hi] for k, v in self._data.items()}


class OverlapSave:
    """Incremental evaluation of a batch computation that looks a bounded way ahead.

    The computation ``compute(**inputs) -> Chunk`` maps per-sample input arrays to per-sample
    output arrays of the same length. It runs on a window of the most recent inputs, from a
    restart point ``r`` to the newest sample ``n``; its outputs for samples up to
    ``n − lookahead`` are final. Then the window's start moves to the latest restart point the
    ``restart`` rule finds, so the window stays short. Nothing is computed while no output can
    become final (only :meth:`provisional` asks for it).

    Parameters
    ----------
    compute : callable
        ``compute(**inputs) -> dict of (m, ...) arrays`` for ``m`` input samples: the block's batch code.
    lookahead : int or callable
        Samples after sample k that can change its output (0: none); or
        ``lookahead(inputs, start) -> index``: the absolute index of the first sample whose output
        may still change, from the window's inputs (which begin at absolute index ``start``) — for a
        look-ahead that depends on the data, e.g. "until the swing ends".
    restart : callable or int
        ``restart(outputs, inputs, start, final) -> index``: the latest absolute sample index in
        ``[start, final]`` from which ``compute`` started afresh gives the same outputs from there
        on, given this window's ``outputs`` and ``inputs`` (both from absolute index ``start``) and
        the first sample not final yet, ``final``. An int ``c`` means "``c`` samples of context
        before the first sample not final" (a centred window of half-width ``c``).
    wants : tuple of str, optional
        The input names ``compute`` takes: :func:`feed` passes only these from the chunk it gets.

    Notes
    -----
    The batch call ``compute(**whole_recording)`` gives the same outputs as any sequence of
    :meth:`step` calls followed by :meth:`finish` exactly when the restart rule and the
    look-ahead are right; ``footzoo.check_plugin`` and footzoo's tests feed every built-in
    block in random chunks to check that.
    """

    def __init__(self, compute: Callable[..., Chunk], lookahead: int | Callable[[Chunk, int], int],
                 restart: Callable[[Chunk, Chunk, int, int], int] | int, wants: tuple[str, ...] | None = None):
        self.compute = compute
        self.lookahead = lookahead if callable(lookahead) else max(int(lookahead), 0)
        self.restart = restart
        self.wants = wants
        self.start = 0  # absolute index of the window's first sample
        self.final = 0  # absolute index of the first sample whose output is not final
        self._window = Columns()
        self._outputs: Chunk | None = None  # compute() over the window, while it is current

    @property
    def inputs(self) -> Chunk:
        """The window's inputs (views)."""
        return self._window.view()

    @property
    def end(self) -> int:
        """Absolute index after the newest sample."""
        return self.start + len(self._window)

    def step(self, **chunk: np.ndarray) -> Chunk:
        """Add the next samples; the outputs that became final (possibly none)."""
        self._window.append(chunk)
        self._outputs = None
        if callable(self.lookahead):
            ready = min(int(self.lookahead(self.inputs, self.start)), self.end)
        else:
            ready = self.end - self.lookahead
        if ready <= self.final:
            return {}
        out = self._current()
        emitted = take(out, self.final - self.start, ready - self.start)
        self.final = ready
        self._move_start(out)
        return emitted

    def provisional(self) -> Chunk:
        """The outputs of the samples that are not final yet, as the computation gives them now."""
        if self.end <= self.final:
            return {}
        return take(self._current(), self.final - self.start)

    def finish(self) -> Chunk:
        """End of the data: the outputs of every sample not final yet."""
        if self.end <= self.final:
            return {}
        out = take(self._current(), self.final - self.start)
        self.final = self.end
        return out

    def pending_seconds(self, rate: float) -> float:
        """How much input the window holds (s): its memory."""
        return len(self._window) / rate

    def _current(self) -> Chunk:
        if self._outputs is None:
            self._outputs = self.compute(**self.inputs)
        return self._outputs

    def _move_start(self, out: Chunk) -> None:
        if isinstance(self.restart, int):
            r = self.final - self.restart
        else:
            r = int(self.restart(out, self.inputs, self.start, self.final))
        r = min(max(r, self.start), self.final)
        if r > self.start:
            cut = r - self.start
            self._window.drop(cut)
            self._outputs = {k: v[cut:] for k, v in out.items()}
            self.start = r


def feed(stages: list[Any], chunk: Chunk, finish: bool = False) -> Chunk:
    """Blocks in series: each stage's final outputs are the next one's inputs.

    Each stage has ``step(**inputs)`` and ``finish()`` (an :class:`OverlapSave` or a block that
    carries its state) and may name the inputs it takes (``wants``); with ``finish`` the data
    ends after ``chunk`` and every stage is finished in turn.
    """
    out = chunk
    for stage in stages:
        wants = getattr(stage, "wants", None)
        given = {k: v for k, v in out.items() if wants is None or k in wants}
        out = stage.step(**given) if length(given) else {}
        if finish:
            out = concat([out, stage.finish()])
    return out


def last_index(mask: np.ndarray, start: int) -> int | None:
    """The absolute index of the last True of ``mask`` (which begins at absolute ``start``), or None."""
    hits = np.flatnonzero(mask)
    return None if hits.size == 0 else start + int(hits[-1])


def run_starts(mask: np.ndarray) -> np.ndarray:
    """Indices where a run of equal values starts (0 first)."""
    m = np.asarray(mask, dtype=bool)
    return np.concatenate([[0], np.flatnonzero(m[1:] != m[:-1]) + 1]).astype(np.int64) if m.size else np.zeros(0, int)


def after_stance(mask: np.ndarray, start: int, final: int) -> int:
    """The latest stance sample ``≤ final`` (absolute; ``mask`` starts at absolute ``start``), else ``start``.

    A restart point of the run filters that treat only the swings of a mask (e.g.
    :func:`footzoo.detectors.runs.close_short_swings`): started on a stance sample they see every later swing whole.
    """
    hits = np.flatnonzero(np.asarray(mask[: final - start + 1], dtype=bool))
    return start + int(hits[-1]) if hits.size else start
