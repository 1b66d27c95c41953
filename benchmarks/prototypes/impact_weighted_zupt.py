"""Prototype (benchmarks only): a zero-velocity update whose noise grows with the impact acceleration.

Not a shipped plug-in: benchmarks/height_drift.py loads it with ``plugins:`` to measure the idea before
it goes into ``footzoo/corrections/ekf_zupt.py``. The zero-velocity measurement ``z = v̂ − 0`` of
``zupt`` (Duong & Suh 2015, eq. 23) with, per stance sample and per axis,

    R = σ_v² + (τ · (|f| − g))²

where ``f`` is the specific force (m/s², body) and τ (s) a time scale: a foot that takes ``|f| − g``
of impact is, within τ of it, not known to be still to better than ``τ·(|f| − g)``. It is the
measurement-side counterpart of ``navigation.impact_noise`` (which grows the process noise instead):
a heel strike's or a push-off's samples weigh less than the still mid-stance's, by physics that do not
depend on the sampling rate or the motion class. τ = 0 is ``zupt``.
"""

from __future__ import annotations

import math

import numpy as np

import footzoo
from footzoo.filters.measurement import VEL, MeasurementModel, V, measurement_function
from footzoo.plugins.base import KalmanCorrection, Samples


@measurement_function
def impact_weighted_zv_measure(ctx, rows):
    """In stance: ``δv = v̂`` with ``R = σ_v² + (τ (|f| − g))²``; ``par`` = (σ_v m/s, τ s, g m/s²)."""
    nav, f, idx, par = ctx.nav, ctx.f, ctx.idx, ctx.par
    z, H, R, m = rows
    if not ctx.stance:
        return m
    excess = math.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) - par[2]
    r = par[0] * par[0] + par[1] * par[1] * excess * excess
    vel = idx[VEL]
    for i in range(3):
        H[m, vel + i] = 1.0
        z[m] = nav[V + i]
        R[m] = r
        m += 1
    return m


@footzoo.register
class ImpactWeightedZUPT(KalmanCorrection):
    """Zero-velocity update with measurement noise growing with the impact acceleration (prototype).

    Parameters
    ----------
    velocity_std : float
        σ_v of the zero-velocity measurement in a still sample (m/s).
    impact_time : float
        τ (s): the velocity uncertainty per m/s² of ``|f| − g``.
    gravity : float
        g (m/s²).
    """

    name = "impact_weighted_zupt"
    paper = "none (prototype; the measurement of Duong & Suh 2015, eq. 23, with a noise model of footzoo's)"
    units = {"velocity_std": "m/s", "impact_time": "s", "gravity": "m/s^2"}
    observes = ("velocity",)

    def __init__(self, velocity_std: float = 0.03, impact_time: float = 0.05, gravity: float = 9.81):
        for name, value in (("velocity_std", velocity_std), ("impact_time", impact_time), ("gravity", gravity)):
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)
                    and value >= 0):
                raise footzoo.ConfigError(f"{name} must be a non-negative number ({self.units[name]}), got {value!r}")
        if velocity_std <= 0:
            raise footzoo.ConfigError(f"velocity_std must be positive (m/s), got {velocity_std!r}")
        self.velocity_std = float(velocity_std)
        self.impact_time = float(impact_time)
        self.gravity = float(gravity)

    def model(self, samples: Samples) -> MeasurementModel:
        """Three velocity rows in every stance sample."""
        return MeasurementModel(measure=impact_weighted_zv_measure, max_rows=3,
                                par=np.array([self.velocity_std, self.impact_time, self.gravity]))
