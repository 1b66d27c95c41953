"""Adaptive-gain quaternion complementary filter (Yun et al. 2012, Sec. II-A)."""

from __future__ import annotations

import math

import numpy as np

from ..filters.strapdown import quat_product, rotvec_quat
from ..kernels.jit import njit
from ..plugins.base import Boolean, Real
from ..plugins.incremental import Chunk
from ..plugins.registry import register
from .fqa import fqa_sample
from .magnetic import REJECTION_PARAMETERS
from .recursive import RecursiveFilter

_NO_MAG = np.zeros((1, 3))


@njit
def complementary_kernel(
    q0: np.ndarray,
    gyr: np.ndarray,
    dt: np.ndarray,
    acc: np.ndarray,
    mag: np.ndarray,
    gain: np.ndarray,
    mag_ok: np.ndarray,
) -> np.ndarray:
    """Per-sample core of the complementary filter (plain arrays, no objects).

    ``q̂⁻ = q̂_{k-1} ⊗ exp(ω_k dt_k / 2)``,  ``q̂_k = normalise( q̂⁻ + k_k dt_k (±q_s,k − q̂⁻) )``

    The gyro branch ``q̇_d = ½ q̂ ⊗ ω`` (eq. 2) is integrated exactly for a rate
    that is constant over the sample interval; the feedback ``k e(t)`` with
    ``e = ±q_s − q̂`` (the sign of ``q_s`` chosen to match ``q̂``) is evaluated at
    ``t[k]``, with the static quaternion (:func:`static_sample`) and the
    gyro-propagated estimate of the same instant, and added with the same step.
    ``q_s`` is computed only where the gain is not zero. Where ``mag_ok[k]`` is false (no
    magnetometer, or a rejected sample) the static branch corrects roll and pitch only: ``q_s`` is the tilt-only FQA
    quaternion given the current estimate's heading.

    Parameters
    ----------
    q0 : (4,) ndarray
        Initial attitude.
    gyr : (N, 3) ndarray
        Angular rate (rad/s).
    dt : (N,) ndarray
        Sample intervals (s).
    acc : (N, 3) ndarray
        Specific force (m/s²).
    mag : (N, 3) ndarray
        Magnetic field (any unit); read only where ``mag_ok``.
    gain : (N,) ndarray
        k at each sample (1/s).
    mag_ok : (N,) bool ndarray
        Heading from the magnetometer at this sample.
    """
    n = gyr.shape[0]
    out = np.empty((n, 4))
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    for k in range(n):
        h = dt[k]
        gx, gy, gz = gyr[k, 0] * h, gyr[k, 1] * h, gyr[k, 2] * h
        ang = math.sqrt(gx * gx + gy * gy + gz * gz)
        if ang > 1e-12:
            s = math.sin(0.5 * ang) / ang
            dw, dx, dy, dz = math.cos(0.5 * ang), gx * s, gy * s, gz * s
        else:
            dw, dx, dy, dz = 1.0, 0.5 * gx, 0.5 * gy, 0.5 * gz
        # dynamic branch, eq. 2: q̂ ⊗ Δq
        pw = w * dw - x * dx - y * dy - z * dz
        px = w * dx + x * dw + y * dz - z * dy
        py = w * dy - x * dz + y * dw + z * dx
        pz = w * dz + x * dy - y * dx + z * dw
        kk = gain[k] * h
        if kk != 0.0:
            # use_mag a variable, not a constant: one compilation of static_sample, not one per constant
            use_mag = mag_ok[k]
            mx, my, mz = (mag[k, 0], mag[k, 1], mag[k, 2]) if use_mag else (0.0, 0.0, 0.0)
            sw, sx, sy, sz = static_sample(acc[k, 0], acc[k, 1], acc[k, 2], mx, my, mz, use_mag, gyr[k, 0], gyr[k, 1],
                                           gyr[k, 2], h)
            if not use_mag:
                # give q_s the current estimate's heading: q_z(ψ̂ − ψ_s) ⊗ q_s
                psi = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)) - math.atan2(
                    2.0 * (sw * sz + sx * sy), 1.0 - 2.0 * (sy * sy + sz * sz))
                cw, cz = math.cos(0.5 * psi), math.sin(0.5 * psi)
                sw, sx, sy, sz = cw * sw - cz * sz, cw * sx - cz * sy, cw * sy + cz * sx, cw * sz + cz * sw
            if sw * pw + sx * px + sy * py + sz * pz < 0.0:  # ±q_s: same sign as q̂
                sw, sx, sy, sz = -sw, -sx, -sy, -sz
            # feedback k e(t), e = ±q_s − q̂ (Fig. 2), both at t[k]
            pw += kk * (sw - pw)
            px += kk * (sx - px)
            py += kk * (sy - py)
            pz += kk * (sz - pz)
        nrm = math.sqrt(pw * pw + px * px + py * py + pz * pz)
        w, x, y, z = pw / nrm, px / nrm, py / nrm, pz / nrm
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
    return out


@njit
def static_sample(ax, ay, az, mx, my, mz, use_mag, wx, wy, wz, h):
    """FQA quaternion of one sample, carried to the sample's time stamp.

    An interval-average sample describes the middle of its interval
    ``(t[k-1], t[k]]``, so the FQA attitude is rotated on by half the
    interval's gyro rotation, ``q_s ⊗ exp(ω_k dt_k / 4)``, before it is
    compared with the estimate at ``t[k]``. Without this, a foot rotating at
    7.5 rad/s sampled at 50 Hz would see a 4° lag in ``q_s``.
    Specific force (m/s²), field (any unit), rate (rad/s), interval ``h`` (s).
    """
    w, x, y, z = fqa_sample(ax, ay, az, mx, my, mz, use_mag)
    # ⊗ exp(ω dt / 4): rotation by half the interval
    dw, dx, dy, dz = rotvec_quat(wx * 0.5 * h, wy * 0.5 * h, wz * 0.5 * h)
    return quat_product(w, x, y, z, dw, dx, dy, dz)


#: Why the gains stop at 100 1/s.
_GAIN_RANGE = ("k is the static branch's corner frequency in rad/s (eqs. 3-4): at 100 Hz, k = 100 replaces the "
               "estimate by the FQA quaternion at every sample")


@register
class FQAComplementary(RecursiveFilter):
    """Adaptive-gain quaternion complementary filter with an FQA static branch.

    Yun, Calusdian, Bachmann & McGhee, IEEE TIM 61(7), 2012, Sec. II-A, eqs. 2–4
    and Fig. 2. The gyro branch integrates ``q̇ = ½ q̂ ⊗ ω`` (eq. 2); the static
    branch is the FQA quaternion ``q_s`` from accelerometer and magnetometer;
    the error ``e = ±q_s − q̂`` times the gain ``k`` is added to the rate and the
    result normalised. The gain is ``static_gain`` (k_s) in stance and
    ``dynamic_gain`` (k_d) in swing, switched by the detector's gait phase with
    its switches dated back: a live system runs the filter Γ_th samples behind
    the sensor, as the paper's FIFOs do for the velocity. (Switching on the
    undelayed state would apply k_s for Γ_th samples after heel-off, pulling the
    attitude toward an FQA quaternion corrupted by the toe-roll accelerations;
    on the simulator that costs 5 % of the distance.)
    The transfer functions are ``k/(s+k)`` for the static and ``s/(s+k)`` for the
    dynamic branch (eqs. 3–4): k is the corner frequency in rad/s.

    Without a magnetometer the static branch corrects roll and pitch only.

    Magnetic disturbance rejection (footzoo's, not the paper's; see
    :mod:`footzoo.orientation.magnetic`): a magnetometer sample whose magnitude
    or dip departs from the values learned at the still start by more than
    ``mag_norm_tolerance`` or ``mag_dip_tolerance`` is not used: the static
    branch then corrects roll and pitch only, and the heading follows the gyro.
    Undisturbed recordings are barely affected (the dip is tested where ``| |f| − g | < 0.1 g``,
    which a foot turning fast can meet too: on a simulated 120 m walk the heading moves by less
    than 0.1°); near steel or a motor the paper's
    filter pulls the heading toward the disturbed field.

    Parameters
    ----------
    static_gain : float
        k_s (1/s), gain in stance; paper: 1.05 (Table II).
    dynamic_gain : float
        k_d (1/s), gain in swing; paper: 0.0 (Table II).
    use_magnetometer : bool
        Use the magnetometer for heading when the recording has one.
    mag_rejection : bool
        Reject disturbed magnetometer samples (False: the paper's filter).
    mag_norm_tolerance : float
        Accepted relative deviation of the field magnitude (1).
    mag_dip_tolerance : float
        Accepted deviation of the dip angle (rad); default 5°.

    Attributes
    ----------
    quat_ : (N, 4) ndarray
        Estimated attitude, body -> NED.
    gain_ : (N,) ndarray
        Gain used at each sample (1/s).
    mag_valid_ : (N,) bool ndarray or None
        Magnetometer samples used for heading (None without a magnetometer).
    """

    name = "fqa_complementary"
    paper = "Yun et al. 2012, IEEE TIM 61(7), Sec. II-A, eqs. 2-4, Table II"
    parameters = {
        "static_gain": Real("1/s", "[0, 100]", "k_s: the gain of the static (FQA) branch in stance",
                            source="Yun et al. 2012, Table II", why=_GAIN_RANGE),
        "dynamic_gain": Real("1/s", "[0, 100]", "k_d: the gain of the static branch in swing",
                             source="Yun et al. 2012, Table II", why=_GAIN_RANGE),
        "use_magnetometer": Boolean("use the magnetometer for heading when the recording has one",
                                    source="Yun et al. 2012 (a MARG filter)"),
        **REJECTION_PARAMETERS,
    }
    needs_stance = True
    checks_magnetometer = True

    def __init__(self, static_gain: float = 1.05, dynamic_gain: float = 0.0, use_magnetometer: bool = True,
                 mag_rejection: bool = True, mag_norm_tolerance: float = 0.1,
                 mag_dip_tolerance: float = float(np.radians(5.0))):
        self.static_gain = static_gain
        self.dynamic_gain = dynamic_gain
        self.use_magnetometer = use_magnetometer
        self.mag_rejection = mag_rejection
        self.mag_norm_tolerance = mag_norm_tolerance
        self.mag_dip_tolerance = mag_dip_tolerance

    def propagate(self, q_prev: np.ndarray, first: bool, t: np.ndarray, dt: np.ndarray, acc: np.ndarray,
                  gyr: np.ndarray, mag: np.ndarray | None, stance: np.ndarray,
                  mag_ok: np.ndarray | None) -> Chunk:
        """Eqs. 2–4 over the chunk (:func:`complementary_kernel`): ``quat``; ``gain`` k_s in stance, k_d in swing."""
        gain = np.where(stance, self.static_gain, self.dynamic_gain)
        ok = np.zeros(t.shape[0], dtype=bool) if mag_ok is None else np.ascontiguousarray(mag_ok)
        quat = complementary_kernel(np.asarray(q_prev, dtype=float), gyr, dt, acc, _NO_MAG if mag is None else mag,
                                    gain, ok)
        return {"quat": quat, "gain": gain}
