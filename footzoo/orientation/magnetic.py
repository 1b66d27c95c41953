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

import math

import numpy as np

from ..core.conventions import GRAVITY
from ..core.norms import row_norms
from ..core.params import Boolean, Real
from ..kernels.jit import njit

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
    mn = row_norms(m)
    fn = row_norms(f)
    s = -np.einsum("ij,ij->i", m, f) / np.maximum(mn * fn, 1e-300)
    return mn, np.arcsin(np.clip(s, -1.0, 1.0))


def magnetometer_valid(
    t: np.ndarray, acc: np.ndarray, mag: np.ndarray, still: np.ndarray, norm_tolerance: float, dip_tolerance: float
) -> tuple[np.ndarray, float, float]:
    """Which magnetometer samples agree with the undisturbed field, learned at the still start.

    The reference comes from the leading samples only; the check of every sample is one
    compiled pass (:func:`_valid_kernel`) that writes nothing but the flags.

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
    t = np.ascontiguousarray(t, dtype=float)
    f = np.ascontiguousarray(acc, dtype=float)
    m = np.ascontiguousarray(mag, dtype=float)
    norm_ref, dip_ref = reference_field(t, f, m, np.asarray(still, dtype=bool), complete=True)
    return valid_samples(f, m, norm_ref, dip_ref, norm_tolerance, dip_tolerance), norm_ref, dip_ref


def reference_field(t: np.ndarray, acc: np.ndarray, mag: np.ndarray, still: np.ndarray,
                    complete: bool) -> tuple[float, float] | None:
    """Reference magnitude and dip (rad) of the undisturbed field, from the leading still samples.

    The median over the leading still run (at most :data:`REFERENCE_DURATION`), or over the first
    0.5 s if the recording does not start still. ``t``, ``acc``, ``mag``, ``still`` are the first
    samples of a recording; with ``complete`` False more may follow (a live stream), and the result
    is None while they could still change the reference (its warm-up, at most 1 s).
    """
    n = t.shape[0]
    if n == 0:
        return None
    moving = np.flatnonzero(~still)
    n_lead = int(moving[0]) if moving.size else n
    # the reference samples are a prefix: t − t[0] <= T (t increases) and before the first moving sample
    n_ref = min(_leading_within(t, REFERENCE_DURATION), n_lead)
    seen_1s = t[-1] - t[0] > REFERENCE_DURATION
    if not complete and not (moving.size or seen_1s):
        return None
    if n_ref < 2:
        if not complete and not t[-1] - t[0] > 0.5:
            return None
        n_ref = _leading_within(t, 0.5)
    mn, dip = field_norm_and_dip(acc[:n_ref], mag[:n_ref])
    return float(np.median(mn)), float(np.median(dip))


def valid_samples(acc: np.ndarray, mag: np.ndarray, norm_ref: float, dip_ref: float, norm_tolerance: float,
                  dip_tolerance: float) -> np.ndarray:
    """Per sample: the field agrees with the reference (see :func:`_valid_kernel`)."""
    valid = np.empty(acc.shape[0], dtype=np.bool_)
    _valid_kernel(np.ascontiguousarray(acc, dtype=float), np.ascontiguousarray(mag, dtype=float), norm_ref, dip_ref,
                  norm_tolerance, dip_tolerance, GRAVITY, valid)
    return valid


@njit
def _leading_within(t: np.ndarray, duration: float) -> int:
    """Number of leading samples with ``t[k] − t[0] <= duration`` (s)."""
    k = 0
    while k < t.shape[0] and t[k] - t[0] <= duration:
        k += 1
    return k


@njit
def _valid_kernel(acc: np.ndarray, mag: np.ndarray, norm_ref: float, dip_ref: float, norm_tolerance: float,
                  dip_tolerance: float, g: float, valid: np.ndarray) -> None:
    """``valid[k]``: ``| |m| − |m|_ref | <= tol |m|_ref``, and the dip within tolerance where ``| |f| − g | < 0.1 g``.

    The arithmetic of :func:`field_norm_and_dip` per sample (the dip
    ``asin(−m·f / (|m| |f|))`` clipped to ±1), evaluated only where it decides.
    """
    for k in range(acc.shape[0]):
        mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
        fx, fy, fz = acc[k, 0], acc[k, 1], acc[k, 2]
        mn = math.sqrt(mx * mx + my * my + mz * mz)
        ok = abs(mn - norm_ref) <= norm_tolerance * norm_ref
        if ok:
            fn = math.sqrt(fx * fx + fy * fy + fz * fz)
            if abs(fn - g) < 0.1 * g:  # quiet: |f| ≈ g, the dip is meaningful
                s = -(mx * fx + my * fy + mz * fz) / max(mn * fn, 1e-300)
                dip = math.asin(min(max(s, -1.0), 1.0))
                ok = abs(dip - dip_ref) <= dip_tolerance
        valid[k] = ok


#: Declarations of the rejection's parameters, shared by the filters that use it.
REJECTION_PARAMETERS = {
    "mag_rejection": Boolean("reject disturbed magnetometer samples (false: the paper's filter)",
                             source="footzoo's (not the paper's)"),
    "mag_norm_tolerance": Real("1", "(0, 1]", "accepted relative deviation of the field magnitude",
                               source="footzoo's: 10 %"),
    "mag_dip_tolerance": Real("rad", "(0, pi]", "accepted deviation of the dip angle", source="footzoo's: 5°"),
}
