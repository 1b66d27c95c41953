"""Adaptive-gain quaternion complementary filter (Yun et al. 2012, Sec. II-A)."""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from ..registry import Plugin, check_positive, register
from .fqa import fqa_sample
from .magnetic import magnetometer_valid


@njit
def complementary_kernel(
    q0: np.ndarray,
    gyr: np.ndarray,
    dt: np.ndarray,
    q_static: np.ndarray,
    gain: np.ndarray,
    keep_yaw: np.ndarray,
    static_yaw: np.ndarray,
) -> np.ndarray:
    """Per-sample core of the complementary filter (plain arrays, no objects).

    ``q̂⁻ = q̂_{k-1} ⊗ exp(ω_k dt_k / 2)``,  ``q̂_k = normalise( q̂⁻ + k_k dt_k (±q_s,k − q̂⁻) )``

    The gyro branch ``q̇_d = ½ q̂ ⊗ ω`` (eq. 2) is integrated exactly for a rate
    that is constant over the sample interval; the feedback ``k e(t)`` with
    ``e = ±q_s − q̂`` (the sign of ``q_s`` chosen to match ``q̂``) is evaluated at
    ``t[k]``, with the static quaternion and the gyro-propagated estimate of
    the same instant, and added with the same step. Where ``keep_yaw[k]`` (no
    magnetometer, or a rejected sample) ``q_s`` is the tilt-only FQA quaternion
    given the current estimate's heading, so the static branch corrects roll and
    pitch only: ``q_static`` then holds the tilt quaternion and ``static_yaw`` its
    heading, which is replaced by the estimate's.
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
            sw, sx, sy, sz = q_static[k, 0], q_static[k, 1], q_static[k, 2], q_static[k, 3]
            if keep_yaw[k]:
                # give q_s the current estimate's heading: q_z(ψ̂ − ψ_s) ⊗ q_s
                psi = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)) - static_yaw[k]
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
def _static_kernel(acc, gyr, dt, mag, use_mag):
    n = acc.shape[0]
    q_s = np.empty((n, 4))
    yaw = np.empty(n)
    for k in range(n):
        if use_mag:
            w, x, y, z = fqa_sample(acc[k, 0], acc[k, 1], acc[k, 2], mag[k, 0], mag[k, 1], mag[k, 2], True)
        else:
            w, x, y, z = fqa_sample(acc[k, 0], acc[k, 1], acc[k, 2], 0.0, 0.0, 0.0, False)
        # ⊗ exp(ω dt / 4): rotation by half the interval
        rx, ry, rz = gyr[k, 0] * 0.5 * dt[k], gyr[k, 1] * 0.5 * dt[k], gyr[k, 2] * 0.5 * dt[k]
        angle = math.sqrt(rx * rx + ry * ry + rz * rz)
        half = 0.5 * angle
        kk = math.sin(half) / angle if angle > 1e-12 else 0.5 - angle * angle / 48.0
        dw, dx, dy, dz = math.cos(half), kk * rx, kk * ry, kk * rz
        qw = w * dw - x * dx - y * dy - z * dz
        qx = w * dx + x * dw + y * dz - z * dy
        qy = w * dy - x * dz + y * dw + z * dx
        qz = w * dz + x * dy - y * dx + z * dw
        q_s[k, 0], q_s[k, 1], q_s[k, 2], q_s[k, 3] = qw, qx, qy, qz
        yaw[k] = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return q_s, yaw


def static_quaternion(acc: np.ndarray, gyr: np.ndarray, dt: np.ndarray, mag: np.ndarray | None):
    """FQA quaternion of each sample, carried to the sample's time stamp, and its heading.

    An interval-average sample describes the middle of its interval
    ``(t[k-1], t[k]]``, so the FQA attitude is rotated on by half the
    interval's gyro rotation, ``q_s ⊗ exp(ω_k dt_k / 4)``, before it is
    compared with the estimate at ``t[k]``. Without this, a foot rotating at
    7.5 rad/s sampled at 50 Hz would see a 4° lag in ``q_s``.

    Returns
    -------
    q_s : (N, 4) ndarray
    yaw : (N,) ndarray
        Z-Y-X heading of ``q_s`` (rad).
    """
    use_mag = mag is not None
    m = np.ascontiguousarray(mag, dtype=float) if use_mag else np.zeros((1, 3))
    return _static_kernel(np.ascontiguousarray(acc, dtype=float), np.ascontiguousarray(gyr, dtype=float),
                          np.ascontiguousarray(dt, dtype=float), m, use_mag)


@register
class FQAComplementary(Plugin):
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
    Undisturbed recordings are unaffected; near steel or a motor the paper's
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

    kind = "orientation"
    name = "fqa_complementary"
    paper = "Yun et al. 2012, IEEE TIM 61(7), Sec. II-A, eqs. 2-4, Table II"
    units = {"static_gain": "1/s", "dynamic_gain": "1/s", "mag_norm_tolerance": "1", "mag_dip_tolerance": "rad"}
    needs_stance = True

    def __init__(self, static_gain: float = 1.05, dynamic_gain: float = 0.0, use_magnetometer: bool = True,
                 mag_rejection: bool = True, mag_norm_tolerance: float = 0.1,
                 mag_dip_tolerance: float = float(np.radians(5.0))):
        self.static_gain = check_positive("static_gain", static_gain, allow_zero=True)
        self.dynamic_gain = check_positive("dynamic_gain", dynamic_gain, allow_zero=True)
        self.use_magnetometer = bool(use_magnetometer)
        self.mag_rejection = bool(mag_rejection)
        self.mag_norm_tolerance = check_positive("mag_norm_tolerance", mag_norm_tolerance)
        self.mag_dip_tolerance = check_positive("mag_dip_tolerance", mag_dip_tolerance)

    def estimate(
        self,
        t: np.ndarray,
        acc: np.ndarray,
        gyr: np.ndarray,
        mag: np.ndarray | None,
        stance: np.ndarray,
        q0: np.ndarray,
    ) -> FQAComplementary:
        """Run the filter over a recording.

        Parameters
        ----------
        t : (N,) ndarray
            Time (s).
        acc, gyr : (N, 3) ndarray
            Specific force (m/s²) and angular rate (rad/s) in FRD.
        mag : (N, 3) ndarray or None
            Magnetic field in FRD (any unit).
        stance : (N,) bool ndarray
            Gait phase at each sample (True = stance, gain k_s).
        q0 : (4,) ndarray
            Initial attitude.
        """
        dt = np.empty_like(t)
        dt[1:] = np.diff(t)
        dt[0] = 0.0
        use_mag = self.use_magnetometer and mag is not None
        q_static, static_yaw = static_quaternion(acc, gyr, dt, mag if use_mag else None)
        keep_yaw = np.full(t.shape[0], not use_mag)
        self.mag_valid_ = None
        if use_mag:
            self.mag_valid_ = np.ones(t.shape[0], dtype=bool)
            if self.mag_rejection:
                self.mag_valid_ = magnetometer_valid(t, acc, mag, stance, self.mag_norm_tolerance,
                                                     self.mag_dip_tolerance)[0]
                if not self.mag_valid_.all():
                    q_tilt, tilt_yaw = static_quaternion(acc, gyr, dt, None)
                    bad = ~self.mag_valid_
                    q_static[bad], static_yaw[bad] = q_tilt[bad], tilt_yaw[bad]
                    keep_yaw = bad
        self.gain_ = np.where(stance, self.static_gain, self.dynamic_gain)
        self.quat_ = complementary_kernel(
            np.asarray(q0, dtype=float), gyr, dt, q_static, self.gain_, keep_yaw, static_yaw
        )
        return self
