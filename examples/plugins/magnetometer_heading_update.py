"""A Kalman correction as a footzoo plug-in: the magnetometer heading update (MAGU) in stance.

Jiménez, Seco, Prieto & Guevara, "Indoor Pedestrian Navigation using an INS/EKF framework for
Yaw Drift Reduction and a Foot-mounted IMU", WPNC 2010 (the MAGU update): while the foot is
still, the heading of the Earth's field seen by the magnetometer is compared with its heading at
the start; the difference is the filter's heading error. Readings whose magnitude or dip angle
depart from the start's are rejected as disturbed (a common gate; the thresholds are ours).

With footzoo's conventions (NED, ``C_est = (I + [δφ×]) C_true``): the field in NED computed with
the estimated attitude is the true one turned by δψ about the vertical, so its heading
``ψ_m = atan2(m_E, m_N)`` exceeds the reference ``ψ_0`` by δψ, the measurement is
``z = wrap(ψ_m − ψ_0)`` and its H row picks the attitude error's z component (as HDR's).

The reference ``ψ_0``, magnitude and dip are the means over the still start (the alignment
period), learnt inside the filter, so the correction also runs live.
"""

from __future__ import annotations

import math

import numpy as np

import footzoo
from footzoo.filters.measurement import ATT, MeasurementModel, Q, measurement_function
from footzoo.plugins.base import KalmanCorrection, Real, Samples

#: Positions in ``par``: σ_ψ (rad), the field magnitude's tolerance (a fraction), the dip's tolerance (rad).
HEADING_STD, NORM_TOLERANCE, DIP_TOLERANCE = 0, 1, 2
#: In ``data``: in the still start, the reading is valid, the field m_x, m_y, m_z (body frame, any unit).
IN_START, VALID, FIELD = 0, 1, 2
#: In ``mem``: the sums Σm_N, Σm_E, Σm_D, Σ|m| and their count over the still start, the reference is ready,
#: its heading ψ_0 (rad), magnitude |m|_0 and dip (rad).
SUM_N, SUM_E, SUM_D, SUM_NORM, COUNT, READY, HEADING_0, NORM_0, DIP_0 = range(9)


@measurement_function
def magu_measure(ctx, rows):
    """In stance: the heading of the field in NED against the still start's (``ctx`` and ``rows``: see
    footzoo.filters.measurement; ``par``, ``data``, ``mem``: the positions above)."""
    nav, par, mem, data = ctx.nav, ctx.par, ctx.mem, ctx.data
    z, H, R, m = rows
    if data[VALID] == 0.0:
        return m
    qw, qx, qy, qz = nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3]
    mx, my, mz = data[FIELD], data[FIELD + 1], data[FIELD + 2]
    m_n = (1 - 2 * (qy * qy + qz * qz)) * mx + 2 * (qx * qy - qw * qz) * my + 2 * (qx * qz + qw * qy) * mz
    m_e = 2 * (qx * qy + qw * qz) * mx + (1 - 2 * (qx * qx + qz * qz)) * my + 2 * (qy * qz - qw * qx) * mz
    m_d = 2 * (qx * qz - qw * qy) * mx + 2 * (qy * qz + qw * qx) * my + (1 - 2 * (qx * qx + qy * qy)) * mz
    norm = math.sqrt(mx * mx + my * my + mz * mz)
    if data[IN_START] != 0.0:  # still start: accumulate the reference
        mem[SUM_N] += m_n
        mem[SUM_E] += m_e
        mem[SUM_D] += m_d
        mem[SUM_NORM] += norm
        mem[COUNT] += 1.0
        return m
    if mem[READY] == 0.0:
        if mem[COUNT] == 0.0:
            return m
        mem[HEADING_0] = math.atan2(mem[SUM_E], mem[SUM_N])
        mem[NORM_0] = mem[SUM_NORM] / mem[COUNT]
        mem[DIP_0] = math.atan2(mem[SUM_D], math.sqrt(mem[SUM_N] * mem[SUM_N] + mem[SUM_E] * mem[SUM_E]))
        mem[READY] = 1.0
    if not ctx.stance:
        return m
    dip = math.atan2(m_d, math.sqrt(m_n * m_n + m_e * m_e))
    if abs(norm - mem[NORM_0]) > par[NORM_TOLERANCE] * mem[NORM_0] or abs(dip - mem[DIP_0]) > par[DIP_TOLERANCE]:
        return m  # disturbed field: no update
    d = math.atan2(m_e, m_n) - mem[HEADING_0]
    d = -((-d + math.pi) % (2 * math.pi) - math.pi)
    H[m, ctx.idx[ATT] + 2] = 1.0
    z[m] = d
    R[m] = par[HEADING_STD] * par[HEADING_STD]
    return m + 1


@footzoo.register
class MagnetometerHeadingUpdate(KalmanCorrection):
    """Magnetometer heading update in stance, with disturbance rejection (Jiménez et al. 2010, MAGU).

    ``z = wrap(ψ_m − ψ_0)`` with ``ψ_m`` the heading of the field in NED under the estimated
    attitude and ``ψ_0`` its mean over the still start; H picks the attitude error's z component.

    Parameters
    ----------
    heading_std : float
        Measurement noise of the magnetic heading (rad).
    norm_tolerance : float
        Reject readings whose magnitude differs from the start's by more than this fraction (1).
    dip_tolerance : float
        Reject readings whose dip angle differs from the start's by more than this (rad).
    """

    name = "magnetometer_heading"
    paper = "Jiménez, Seco, Prieto & Guevara 2010, WPNC (MAGU)"
    # one declaration per parameter: unit, accepted range, meaning, source of the default
    parameters = {
        "heading_std": Real("rad", "(0, pi]", "σ of the magnetic heading", source="chosen: 0.1 rad (5.7°)"),
        "norm_tolerance": Real("1", "(0, 1]", "rejects a reading whose |m| differs from the start's by more",
                               source="chosen: 5 %"),
        "dip_tolerance": Real("rad", "(0, pi/2]", "rejects a reading whose dip differs from the start's by more",
                              source="chosen: 0.05 rad (2.9°)"),
    }
    needs_magnetometer = True
    observes = ("magnetic_heading",)

    def __init__(self, heading_std: float = 0.1, norm_tolerance: float = 0.05, dip_tolerance: float = 0.05):
        # footzoo has checked each value against its declaration before this runs
        self.heading_std = heading_std
        self.norm_tolerance = norm_tolerance
        self.dip_tolerance = dip_tolerance

    def requires_attitude_state(self) -> bool:
        """The heading error is the attitude error's z component."""
        return True

    def sample_data(self, samples: Samples) -> np.ndarray:
        """Per sample: in the still start, reading valid, the magnetometer reading (any unit)."""
        if samples.mag is None:
            raise footzoo.RecordingError("magnetometer_heading needs a magnetometer (mag_x, mag_y, mag_z)")
        mag = np.asarray(samples.mag, dtype=float)
        valid = np.isfinite(mag).all(axis=1) & (np.linalg.norm(mag, axis=1) > 0)
        return np.column_stack([np.asarray(samples.init_window, float), valid.astype(float),
                                np.where(valid[:, None], mag, 0.0)])

    def model(self, samples: Samples) -> MeasurementModel:
        """One heading row per undisturbed stance sample."""
        return MeasurementModel(measure=magu_measure, max_rows=1,
                                par=np.array([self.heading_std, self.norm_tolerance, self.dip_tolerance]),
                                mem=np.zeros(9))
