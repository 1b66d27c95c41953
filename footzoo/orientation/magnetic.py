"""Magnetometer disturbance rejection shared by the filters that use the magnetometer.

Not from footzoo's papers (Yun 2012 and Huang 2016 trust every magnetometer
sample): the classic check of the field's magnitude and dip (inclination)
against their reference values, as in Madgwick-type MARG filters with
disturbance rejection (e.g. Roetenberg et al. 2005, IEEE TNSRE 13(3);
Fan et al. 2018, Sensors 18(1)). The reference is learned from the still start
of the recording, so no field model is needed. A rejected sample leaves
the heading to the gyro; roll and pitch still come from the accelerometer.
"""

from __future__ import annotations

import numpy as np

from ..checks import check_bool, check_range
from ..conventions import GRAVITY

#: Longest stretch of the still start used to learn the reference (s).
REFERENCE_DURATION = 1.0


def field_norm_and_dip(acc: np.ndarray, mag: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Field magnitude (the magnetometer's unit) and dip angle (rad, positive down) per sample.

    The dip is ``asin(m · d / |m|)`` with ``d = −f/|f|`` the downward direction
    from the specific force ``f`` (FRD: at rest ``f = (0, 0, −g)``, so ``d`` = +z).
    It is meaningful where ``|f| ≈ g`` (the foot is not accelerating).
    """
    m = np.asarray(mag, dtype=float)
    f = np.asarray(acc, dtype=float)
    mn = np.linalg.norm(m, axis=1)
    fn = np.linalg.norm(f, axis=1)
    s = -np.einsum("ij,ij->i", m, f) / np.maximum(mn * fn, 1e-300)
    return mn, np.arcsin(np.clip(s, -1.0, 1.0))


def magnetometer_valid(
    t: np.ndarray, acc: np.ndarray, mag: np.ndarray, still: np.ndarray, norm_tolerance: float, dip_tolerance: float
) -> tuple[np.ndarray, float, float]:
    """Which magnetometer samples agree with the undisturbed field, learned at the still start.

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    acc, mag : (N, 3) ndarray
        Specific force (m/s²) and magnetic field (any unit).
    still : (N,) bool ndarray
        The detector's stance flag: the reference is the median over the
        leading still run (at most ``REFERENCE_DURATION``); if the recording does
        not start still, over its first 0.5 s.
    norm_tolerance : float
        Accepted relative deviation of ``|m|`` from the reference (1, e.g. 0.1 = 10 %).
    dip_tolerance : float
        Accepted deviation of the dip angle from the reference (rad); checked
        only where ``| |f| − g | < 0.1 g``.

    Returns
    -------
    valid : (N,) bool ndarray
    norm_ref : float
        Reference magnitude.
    dip_ref : float
        Reference dip (rad).
    """
    mn, dip = field_norm_and_dip(acc, mag)
    still = np.asarray(still, dtype=bool)
    n_lead = int(np.argmin(still)) if not still.all() else still.size
    ref = (t - t[0] <= REFERENCE_DURATION) & (np.arange(t.size) < n_lead)
    if ref.sum() < 2:
        ref = t - t[0] <= 0.5
    norm_ref = float(np.median(mn[ref]))
    dip_ref = float(np.median(dip[ref]))
    quiet = np.abs(np.linalg.norm(acc, axis=1) - GRAVITY) < 0.1 * GRAVITY
    valid = np.abs(mn - norm_ref) <= norm_tolerance * norm_ref
    valid &= ~quiet | (np.abs(dip - dip_ref) <= dip_tolerance)
    return valid, norm_ref, dip_ref


def rejection_parameters(rejection: bool, norm_tolerance: float, dip_tolerance: float) -> tuple[bool, float, float]:
    """Validated ``mag_rejection``, ``mag_norm_tolerance`` (fraction) and ``mag_dip_tolerance`` (rad)."""
    return (check_bool("mag_rejection", rejection),
            check_range("mag_norm_tolerance", norm_tolerance, 0.0, 1.0, "1", lo_open=True),
            check_range("mag_dip_tolerance", dip_tolerance, 0.0, float(np.pi), "rad", lo_open=True))
