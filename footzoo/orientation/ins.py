"""Strapdown INS attitude, carried by the error-state Kalman filter when one is configured."""

from __future__ import annotations

import numpy as np

from ..filters.strapdown import sample_intervals
from ..registry import Plugin, check_positive, register
from .fqa_complementary import complementary_kernel


@register
class INS(Plugin):
    """Strapdown attitude from the gyro, corrected by the error-state Kalman filter.

    Nguyen & La 2016, eqs. 37–39 and 51–52 (attitude propagation and feedback);
    Duong & Suh 2015, eqs. 3–8 (quaternion error state). The attitude starts
    from the initial alignment (gravity, and magnetometer heading when present —
    the paper's ``M_NED^{1|0}`` from the IMU's Euler angles, eq. 39) and is then
    propagated with the bias-corrected gyro; the magnetometer is not used again.
    With a Kalman correction (``ekf_zupt``, ``zupt``) the attitude error is a
    state of that filter; without one, this is plain gyro integration.

    The process noise of the error state is given as variance growth per
    second. Nguyen & La (Sec. VI) set ``Q = diag(1e-4·I, 0, 0, 1e-4·I, 0)`` per
    sample; at the 100 Hz the paper's sample counts assume, that is 0.01 per
    second for attitude (rad²) and velocity ((m/s)²).

    Parameters
    ----------
    attitude_noise : float
        Attitude error variance growth (rad²/s).
    velocity_noise : float
        Velocity error variance growth ((m/s)²/s).
    position_noise : float
        Position error variance growth (m²/s); paper: 0.
    initial_attitude_std : float
        Standard deviation of the initial attitude error (rad).

    Attributes
    ----------
    quat_ : (N, 4) ndarray
        Attitude from gyro integration (only when run without a Kalman filter).
    """

    kind = "orientation"
    name = "ins"
    paper = "Nguyen & La 2016, eqs. 37-39, 51-52, Sec. VI (Q); Duong & Suh 2015, eqs. 3-8"
    units = {"attitude_noise": "rad^2/s", "velocity_noise": "(m/s)^2/s", "position_noise": "m^2/s",
             "initial_attitude_std": "rad"}
    use_magnetometer = True  # for the initial alignment only

    def __init__(
        self,
        attitude_noise: float = 0.01,
        velocity_noise: float = 0.01,
        position_noise: float = 0.0,
        initial_attitude_std: float = 0.01,
    ):
        self.attitude_noise = check_positive("attitude_noise", attitude_noise, allow_zero=True)
        self.velocity_noise = check_positive("velocity_noise", velocity_noise, allow_zero=True)
        self.position_noise = check_positive("position_noise", position_noise, allow_zero=True)
        self.initial_attitude_std = check_positive("initial_attitude_std", initial_attitude_std, allow_zero=True)

    def estimate(self, t, acc, gyr, mag, stance, q0) -> INS:
        """Gyro integration from ``q0`` (no Kalman filter configured)."""
        dt = sample_intervals(t)
        n = t.shape[0]
        self.quat_ = complementary_kernel(np.asarray(q0, float), np.ascontiguousarray(gyr, dtype=float), dt,
                                          np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(n), False)
        return self
