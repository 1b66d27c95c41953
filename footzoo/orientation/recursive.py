"""What the recursive orientation filters share: their state between samples, and the magnetometer check.

A recursive filter's attitude at sample k depends on the attitude at k − 1 and sample k only,
so it runs live as it runs on a recording: :class:`RecursiveFilter` keeps the last attitude and
time stamp between chunks and hands each chunk to the filter's compiled kernel, which
continues exactly where the last one stopped (``estimate`` is one such chunk). The only
look-ahead is at the start: with magnetic-disturbance rejection, the reference field is
learned over the leading still samples (at most 1 s, :mod:`footzoo.orientation.magnetic`),
so the first samples wait for it.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from ..core.context import RunContext
from ..plugins.base import Orientation, run_context
from ..plugins.incremental import Chunk, Latency, concat, length
from .magnetic import REFERENCE_DURATION, reference_field, valid_samples


class RecursiveFilter(Orientation):
    """Base of an orientation filter whose kernel can resume from the previous sample's attitude.

    Subclasses implement :meth:`propagate`; ``estimate``, ``begin``, ``step``, ``finish`` and
    ``latency`` follow. ``checks_magnetometer``: the filter rejects disturbed magnetometer
    samples (its ``mag_rejection`` parameter), against the reference learned at the start.
    """

    checks_magnetometer: ClassVar[bool] = False
    causal: ClassVar[bool] = True

    def propagate(self, q_prev: np.ndarray, first: bool, t: np.ndarray, dt: np.ndarray, acc: np.ndarray,
                  gyr: np.ndarray, mag: np.ndarray | None, stance: np.ndarray,
                  mag_ok: np.ndarray | None) -> Chunk:
        """``{"quat": (m, 4), ...}``: the attitude of the chunk's samples from ``q_prev``, the one before them.

        Other per-sample arrays the filter reports may follow (e.g. its gain).

        ``first``: the chunk starts the run (``q_prev`` is then the initial attitude of sample 0,
        ``dt[0] = 0``); ``dt`` (s) the intervals to the previous samples; ``mag_ok`` the
        magnetometer samples to use (None: no magnetometer).
        """
        raise NotImplementedError

    def _uses_mag(self, mag: np.ndarray | None) -> bool:
        return bool(getattr(self, "use_magnetometer", False)) and mag is not None

    def _rejects(self) -> bool:
        return self.checks_magnetometer and bool(getattr(self, "mag_rejection", False))

    # ------------------------------------------------------------------ batch
    def estimate(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, mag: np.ndarray | None,
                 stance: np.ndarray, q0: np.ndarray, ctx: RunContext | None = None) -> RecursiveFilter:
        """Run the filter over a recording (see the class docstring for the inputs' units)."""
        self.begin(run_context(ctx, t), q0)
        out = concat([self.step(t, acc, gyr, mag, stance), self.finish()], copy=False)
        self.mag_valid_ = None
        for key, value in out.items():
            setattr(self, f"{key}_", value)
        return self

    # ------------------------------------------------------------------ live
    def latency(self, ctx: RunContext) -> Latency:
        """None; with magnetometer rejection, a warm-up of at most 1 s at the start for the reference field."""
        return Latency(warmup=REFERENCE_DURATION if self._rejects() else 0.0)

    def begin(self, ctx: RunContext, q0: np.ndarray | None = None) -> RecursiveFilter:
        """Start from the attitude ``q0`` at the first sample."""
        super().begin(ctx, q0)
        self._q = None if q0 is None else np.array(q0, dtype=float).reshape(4)
        self._t_prev: float | None = None
        self._reference: tuple[float, float] | None = None
        self._held: Chunk = {}  # the first samples, while the reference field is not known yet
        return self

    def step(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, mag: np.ndarray | None,
             stance: np.ndarray) -> Chunk:
        """The attitude of the next samples (held back at the start until the reference field is known)."""
        chunk = {"t": np.asarray(t, float), "acc": np.asarray(acc, float).reshape(-1, 3),
                 "gyr": np.asarray(gyr, float).reshape(-1, 3), "stance": np.asarray(stance, bool).reshape(-1)}
        if self._uses_mag(mag):
            chunk["mag"] = np.asarray(mag, float).reshape(-1, 3)
        if self._rejects() and "mag" in chunk and self._reference is None:
            h = concat([self._held, chunk], copy=False)  # the caller's arrays while they are not held
            self._reference = reference_field(h["t"], h["acc"], h["mag"], h["stance"], complete=False)
            if self._reference is None:  # held until the next samples: copies of our own
                self._held = {k: np.array(v) for k, v in h.items()} if not self._held else h
                return {}
            chunk, self._held = h, {}
        return self._run(chunk)

    def finish(self) -> Chunk:
        """A recording shorter than the warm-up: its reference field from what there is."""
        if not length(self._held):
            return {}
        h, self._held = self._held, {}
        self._reference = reference_field(h["t"], h["acc"], h["mag"], h["stance"], complete=True)
        return self._run(h)

    def provisional(self) -> Chunk:
        """Nothing is pending but the warm-up's samples (their attitude is not known before the reference)."""
        return {}

    def _run(self, c: Chunk) -> Chunk:
        if self._q is None:
            raise RuntimeError(f"{self.name}: begin(ctx, q0) with the initial attitude before step()")
        t = np.ascontiguousarray(c["t"], dtype=float)
        dt = np.empty_like(t)
        dt[1:] = t[1:] - t[:-1]
        first = self._t_prev is None
        dt[0] = 0.0 if first else t[0] - self._t_prev
        mag = c.get("mag")
        mag_ok = None
        if mag is not None:
            mag_ok = (valid_samples(c["acc"], mag, *self._reference, self.mag_norm_tolerance, self.mag_dip_tolerance)
                      if self._rejects() else np.ones(t.shape[0], dtype=bool))
        out = self.propagate(self._q, first, t, dt, np.ascontiguousarray(c["acc"], dtype=float),
                             np.ascontiguousarray(c["gyr"], dtype=float),
                             None if mag is None else np.ascontiguousarray(mag, dtype=float), c["stance"], mag_ok)
        self._q, self._t_prev = out["quat"][-1].copy(), float(t[-1])
        if mag_ok is not None:
            out["mag_valid"] = mag_ok
        return out

