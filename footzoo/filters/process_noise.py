"""The error state's process noise: ``Q_k`` of each sample, one definition for every engine and smoother.

``Q_k = diag(q) dt_k`` (Nguyen & La 2016 eq. 44: each state's variance growth per second, from
``navigation:`` and the corrections' state blocks), plus a velocity variance that follows the
signals, the three axes alike (so the frame does not matter), off by default as in the papers:

``impact`` (s; ``navigation.impact_noise``)
    ``impact · |a_k|² · dt_k``, ``a_k`` the NED motion acceleration of sample k: accelerometer scale,
    misalignment and clipping errors grow with the acceleration (footzoo's; a white-noise stand-in).
``integration`` κ (1; ``navigation.integration_noise``)
    ``(κ · |f_k − f_{k−1}| · dt_k)²``, ``f`` the specific force as sampled (m/s²): the strapdown loop
    integrates each interval as if the specific force went from one sample to the next in a straight
    line, but a heel strike shorter than the interval changes it at an instant the samples cannot tell
    (an accelerometer not band-limited below the Nyquist rate). Where in the interval the change
    ``Δf`` happened is then uniform, so the velocity integral over the interval is uncertain by
    ``Δf · dt · u``, ``u`` uniform on [−½, ½]: σ = ``|Δf| dt / √12`` — κ = 1/√12 ≈ 0.29
    (:data:`UNIFORM_TIMING`). A band-limited signal changes little between samples, so the term is
    small where the samples resolve the motion and large at an unresolved impact, whose velocity
    error the RTS smoother can then put at the impact instead of spreading it over the swing (measured
    on gaitmap's example; on a 100 Hz simulated swing its own changes weigh as much: docs/results.md).

The compiled loop (:mod:`footzoo.filters.forward`), the closed-form smoother of a swing
(:func:`footzoo.filters.smoother.smooth_free_span`) and the reference filter
(:class:`footzoo.filters.eskf.ErrorStateFilter`) all call :func:`velocity_variance` (the compiled ones
on :func:`unowned_noise`). A new term touches two files: a field of :class:`Noise` and a line of
:func:`velocity_variance` here, and a parameter of :class:`footzoo.filters.engine.NavigationNoise` of
the same name (:func:`noise_of` copies it over); ``tests/filters/test_process_noise_terms.py``
checks that no other module names a term.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..kernels.jit import njit
from ..kernels.views import unowned

#: κ of a change at an instant uniform within the sample interval: σ of u on [−½, ½] (1).
UNIFORM_TIMING = 1.0 / math.sqrt(12.0)


class Noise(NamedTuple):
    """The process noise's parameters: ``q`` (n,) each state's variance growth per second (unit²/s), then
    the signal-dependent velocity terms named as in ``navigation:`` without ``_noise``: ``impact`` (s),
    ``integration`` (1)."""

    q: np.ndarray
    impact: float
    integration: float


def noise_of(q: np.ndarray, settings: Any) -> Noise:
    """The :class:`Noise` of variance growths ``q`` and the ``<term>_noise`` parameters of ``settings``
    (a :class:`~footzoo.filters.engine.NavigationNoise`), for every signal term of :class:`Noise`."""
    terms = {name: float(getattr(settings, f"{name}_noise")) for name in Noise._fields[1:]}
    return Noise(np.ascontiguousarray(q, dtype=float), **terms)


@njit(inline=True)
def unowned_noise(noise):
    """``noise`` with ``q`` a view that owns no reference (for the compiled loops, which read it at every
    sample), every other term as it is."""
    return Noise(unowned(noise.q), *noise[1:])


@njit(inline=True)
def velocity_variance(noise, a_n, acc, k, dt):
    """Velocity variance ((m/s)², each axis) that sample k adds beyond ``q dt`` (the module's terms).

    ``a_n`` (3,) the sample's NED motion acceleration (m/s²); ``acc`` (N, 3) the specific force as
    sampled (m/s²), ``k ≥ 1``; ``dt`` s.
    """
    q = 0.0
    if noise.impact > 0.0:
        q += noise.impact * (a_n[0] * a_n[0] + a_n[1] * a_n[1] + a_n[2] * a_n[2]) * dt
    if noise.integration > 0.0:
        d0, d1, d2 = acc[k, 0] - acc[k - 1, 0], acc[k, 1] - acc[k - 1, 1], acc[k, 2] - acc[k - 1, 2]
        q += (noise.integration * dt) ** 2 * (d0 * d0 + d1 * d1 + d2 * d2)
    return q


@njit(inline=True)
def add_process_noise(P, vel, noise, a_n, acc, k, dt):
    """``P ← P + Q_k`` (the second half of eq. 44): ``q dt`` on the diagonal, :func:`velocity_variance` on
    the three velocity rows (from offset ``vel``)."""
    qv = velocity_variance(noise, a_n, acc, k, dt)
    qn = noise.q
    for i in range(P.shape[0]):
        P[i, i] += qn[i] * dt
    if qv > 0.0:
        for i in range(3):
            P[vel + i, vel + i] += qv
