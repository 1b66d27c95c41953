"""Strapdown INS attitude, carried by the error-state Kalman filter when one is configured."""

from __future__ import annotations

import numpy as np

from ..plugins.incremental import Chunk
from ..plugins.registry import register
from .fqa_complementary import complementary_kernel
from .recursive import RecursiveFilter


@register
class INS(RecursiveFilter):
    """Strapdown attitude from the gyro, corrected by the error-state Kalman filter.

    Nguyen & La 2016, eqs. 37–39 and 51–52 (attitude propagation and feedback);
    Duong & Suh 2015, eqs. 3–8 (quaternion error state). The attitude starts
    from the initial alignment (gravity, and magnetometer heading when present —
    the paper's ``M_NED^{1|0}`` from the IMU's Euler angles, eq. 39) and is then
    propagated with the bias-corrected gyro; the magnetometer is not used again.
    With a Kalman correction (``ekf_zupt``, ``zupt``) the attitude error is a
    state of that filter; without one, this is plain gyro integration.

    The filter's process noise and initial uncertainty (attitude, velocity,
    position) are the INS core's and are set under ``navigation:`` in the
    pipeline's YAML (:class:`footzoo.filters.engine.NavigationNoise`), whatever the
    orientation source.

    Attributes
    ----------
    quat_ : (N, 4) ndarray
        Attitude from gyro integration (only when run without a Kalman filter).
    """

    name = "ins"
    paper = "Nguyen & La 2016, eqs. 37-39, 51-52, Sec. VI (Q); Duong & Suh 2015, eqs. 3-8"
    carried_by_filter = True
    causal = True
    use_magnetometer = True  # for the initial alignment only
    #: Parameters that moved to the pipeline's ``navigation:`` block.
    moved = {p: f"navigation.{p}" for p in ("attitude_noise", "velocity_noise", "position_noise",
                                             "initial_attitude_std")}

    def __init__(self) -> None:
        pass

    def _uses_mag(self, mag: np.ndarray | None) -> bool:
        return False  # the magnetometer serves the initial alignment only

    def propagate(self, q_prev: np.ndarray, first: bool, t: np.ndarray, dt: np.ndarray, acc: np.ndarray,
                  gyr: np.ndarray, mag: np.ndarray | None, stance: np.ndarray,
                  mag_ok: np.ndarray | None) -> Chunk:
        """Gyro integration from the previous attitude (no Kalman filter configured)."""
        n = t.shape[0]
        return {"quat": complementary_kernel(np.asarray(q_prev, float), gyr, dt, np.zeros((1, 3)), np.zeros((1, 3)),
                                             np.zeros(n), np.zeros(n, dtype=bool))}
