"""The velocity process noise that follows the signals: impacts and the integration over a sample interval.

Both add to the velocity rows of ``Q_k`` (the three axes alike, so the frame does not matter) on top of
the noise uniform in time (``navigation.velocity_noise``); both are off by default, as in the papers.

``impact_noise`` (s)
    ``impact · |a_k|² · dt_k``, ``a_k`` the NED motion acceleration of sample k: accelerometer scale,
    misalignment and clipping errors grow with the acceleration (footzoo's; a white-noise stand-in).
``integration_noise`` κ (1)
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
"""

from __future__ import annotations

import math

from ..kernels.jit import njit

#: κ of a change at an instant uniform within the sample interval: σ of u on [−½, ½] (1).
UNIFORM_TIMING = 1.0 / math.sqrt(12.0)


@njit(inline=True)
def signal_velocity_variance(impact, integration, a_n, acc, k, dt):
    """Velocity variance ((m/s)², each axis) that sample k adds beyond the uniform noise.

    ``impact`` s and ``integration`` κ (1) as in the module's text; ``a_n`` (3,) the sample's NED
    motion acceleration (m/s²); ``acc`` (N, 3) the specific force as sampled (m/s²), ``k ≥ 1``;
    ``dt`` s.
    """
    q = 0.0
    if impact > 0.0:
        q += impact * (a_n[0] * a_n[0] + a_n[1] * a_n[1] + a_n[2] * a_n[2]) * dt
    if integration > 0.0:
        d0, d1, d2 = acc[k, 0] - acc[k - 1, 0], acc[k, 1] - acc[k - 1, 1], acc[k, 2] - acc[k - 1, 2]
        q += (integration * dt) ** 2 * (d0 * d0 + d1 * d1 + d2 * d2)
    return q
