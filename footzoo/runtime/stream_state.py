"""What a :class:`~footzoo.runtime.stream.Stream` accepts in its state: the checks of a stream used wrongly.

A stream is one recording's life: samples pushed in order, then :meth:`~footzoo.Stream.close`
(which :meth:`~footzoo.Stream.run` calls at its end). Using it after that, running a second
recording through it, or a channel (the magnetometer) that stops or starts part-way are each a
:class:`~footzoo.core.errors.RecordingError` that says what happened, where, and the fix
(a new ``Stream`` per recording; a channel with every sample or with none).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.errors import ConfigError, RecordingError


def check_open(stream: Any, call: str) -> None:
    """Refuse ``call`` (``push``, ``extend``) on a stream that was closed (by :meth:`close` or :meth:`run`)."""
    if stream._closed:
        where = f" after {stream._k} sample(s), the last at t = {stream._t_prev:g} s" if stream._t_prev is not None \
            else ""
        raise RecordingError(f"Stream.{call}(): the stream is closed (close() or run() ended it{where}); a stream "
                             "takes one recording: start a new Stream for new data")


def check_unused(stream: Any) -> None:
    """Refuse :meth:`~footzoo.Stream.run` on a stream that already ran or was pushed samples."""
    if stream._closed:
        raise RecordingError("Stream.run(): this stream has run (or was closed) already; a stream takes one "
                             "recording: make a new Stream(pipeline) for each recording")
    if stream._k:
        raise RecordingError(f"Stream.run() pushes a whole recording from its first sample, but this stream was "
                             f"pushed {stream._k} sample(s) already (up to t = {stream._t_prev:g} s): make a new "
                             "Stream for the recording, or push the rest of yours with push()/extend()")


def check_channel(stream: Any, name: str, present: bool, t: Any) -> None:
    """Refuse a channel (``mag``) that stops or starts part-way: the first sample decides whether it comes."""
    had = getattr(stream, f"_has_{name}")
    if had is None or had == present:
        return
    what = (f"{name} stopped at t = {float(t):g} s (sample {stream._k}) after coming with every sample before" if had
            else f"{name} started at t = {float(t):g} s (sample {stream._k}), after {stream._k} sample(s) without it")
    raise RecordingError(f"{what}: a channel must come with every sample or with none (the first sample decides); "
                         f"a sensor that drops out mid-stream cannot be bridged: push {name} with every sample (repair "
                         "the gap), or start a new Stream without it")


def chunk_sizes(chunk: Any) -> np.ndarray:
    """The block sizes of :meth:`~footzoo.Stream.run`: a whole number of samples >= 1, or a non-empty array of them."""
    problem = f"Stream.run(): chunk must be a number of samples >= 1 or a non-empty list of them, got {chunk!r:.80}"
    try:
        sizes = np.asarray(chunk).reshape(-1)
    except (TypeError, ValueError):
        raise ConfigError(problem) from None
    if (sizes.size == 0 or sizes.dtype.kind not in "iuf" or sizes.dtype == bool
            or not np.all(np.isfinite(sizes)) or np.any(sizes < 1) or np.any(sizes != np.round(sizes))):
        raise ConfigError(f"{problem}; e.g. chunk=1 (push() sample by sample) or chunk=50 (extend() 50 at a time)")
    return sizes.astype(int)
