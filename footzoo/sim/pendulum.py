"""Damped pendulum with an IMU at its end (Yun et al. 2012, Sec. III-A, eqs. 11–13, Fig. 7).

The pendulum swings in the body x–z plane about the body y axis; θ is the
pitch of the sensor (positive = clockwise in Fig. 7 = pitch up in FRD). With
the sensor at distance L from the pivot, its position is ``L [sin θ, 0, cos θ]``
below the pivot (NED), which gives exactly eq. 11 for the specific force,
``a_x = L θ̈ + g sin θ``, ``a_z = −L θ̇² − g cos θ``, eq. 12 for the rate
``ω_y = θ̇`` and eq. 13 for the magnetometer when the swing plane is
magnetic north.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from ..core.conventions import GRAVITY, quat_conj, quat_from_euler, quat_rotate
from ..core.data import Recording, Truth
from .sensors import NoiseModel, magnetic_field_ned, sample_imu


def simulate_pendulum(
    period: float = 2.0,
    amplitude: float = np.radians(30.0),
    damping: float = 0.02,
    duration: float = 60.0,
    rate: float = 50.0,
    noise: NoiseModel | None = None,
    location: str | tuple[float, float] = "monterey",
    sampling: str = "interval",
    still: float = 1.0,
    gravity: float = GRAVITY,
) -> Recording:
    """Simulate the pendulum: ``θ̈ = −(g/L) sin θ − c θ̇`` with ``L = g (T/2π)²``.

    Parameters
    ----------
    period : float
        Small-angle period T (s); Fig. 8 uses 2 s (slow walking).
    amplitude : float
        Initial angle (rad), released at rest after ``still`` seconds.
    damping : float
        c (1/s).
    duration, rate : float
        Length (s) and sampling rate (Hz).
    noise : NoiseModel, optional
        Sensor errors (eq. 18).
    """
    length = gravity * (period / (2 * np.pi)) ** 2

    def rhs(_t, y):
        return [y[1], -(gravity / length) * np.sin(y[0]) - damping * y[1]]

    t = np.arange(0.0, duration, 1.0 / rate)
    sol = solve_ivp(rhs, (0.0, duration), [amplitude, 0.0], dense_output=True, rtol=1e-11, atol=1e-12)
    tt = np.clip(t - still, 0.0, None)
    th, thd = sol.sol(tt)
    thd = np.where(t < still, 0.0, thd)
    thdd = -(gravity / length) * np.sin(th) - damping * thd
    thdd = np.where(t < still, 0.0, thdd)
    pos = length * np.column_stack([np.sin(th), np.zeros_like(th), np.cos(th)])
    vel = length * np.column_stack([thd * np.cos(th), np.zeros_like(th), -thd * np.sin(th)])
    acc_n = length * np.column_stack([thdd * np.cos(th) - thd**2 * np.sin(th), np.zeros_like(th),
                                      -thdd * np.sin(th) - thd**2 * np.cos(th)])
    q = quat_from_euler(np.zeros_like(th), th, np.zeros_like(th))
    w = np.column_stack([np.zeros_like(th), thd, np.zeros_like(th)])
    acc, gyr = sample_imu({"q": q, "v": vel, "a": acc_n, "w": w}, t, gravity, sampling)
    mag = quat_rotate(quat_conj(q), magnetic_field_ned(location))
    if noise is not None:
        acc, gyr, mag = noise.apply(acc, gyr, mag, t)
    truth = Truth(pos=pos - pos[0], vel=vel, quat=q, stance=np.zeros(t.size, bool))
    meta = {"name": "sim_pendulum", "source": "footzoo.sim", "format": "simulated", "period": period,
            "length_m": length}
    return Recording(t=t, acc=acc, gyr=gyr, mag=mag, meta=meta, truth=truth)
