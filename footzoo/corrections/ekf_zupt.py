"""Zero-velocity (and zero-angular-rate) update of the error-state Kalman filter (Nguyen & La 2016)."""

from __future__ import annotations

import numpy as np

from ..core.errors import ConfigError
from ..filters.measurement import (
    ACC_BIAS,
    BA,
    BG,
    GYRO_BIAS,
    VEL,
    MeasurementModel,
    StateBlock,
    V,
    after_function,
    measurement_function,
)
from ..plugins.base import Boolean, KalmanCorrection, Real, Samples
from ..plugins.registry import register
from .stillness import HOLD_DEFAULTS, HOLD_MEM, HOLD_PARAMETERS, HOLD_ROWS, hold_constants, hold_measure, hold_track

#: Positions in the model's ``par``: σ of the velocity (m/s), zero rate on/off, σ of the rate (rad/s), the gyro
#: and the accelerometer bias bounds (rad/s, m/s²), the roll lever arm (m), then the stillness hold's constants
#: (:mod:`footzoo.corrections.stillness`); in ``mem``: the rows the bias guard added, then the hold's memory.
VELOCITY_STD, ZERO_RATE, RATE_STD, GYRO_BOUND, ACC_BOUND, ROLL_LEVER, HOLD = 0, 1, 2, 3, 4, 5, 6
GUARD_ROWS, HOLD_STATE = 0, 1


@measurement_function
def zero_velocity_measure(ctx, rows):
    """In stance: ``δv = v̂ − 0`` (eq. 29) and, with ``par[ZERO_RATE]``, ``δω = ω̂ − 0`` (eq. 30); while the
    foot is held, ``δp = p̂ − p_0`` (:mod:`footzoo.corrections.stillness`).

    The velocity rows' variance is ``σ_v² + (ℓ |ω̂|)²`` with ``ℓ = par[ROLL_LEVER]`` (m; 0: the
    paper's ``σ_v²``), ``ω̂`` the bias-corrected angular rate (rad/s).

    In any sample, a bias estimate beyond its bound ``par[GYRO_BOUND]`` (rad/s) or
    ``par[ACC_BOUND]`` (m/s²) is measured at the bound, with σ a tenth of the
    bound: ``δb = clip(b̂) − b̂`` (footzoo's bias guard; a bound of 0: none).
    """
    nav, w, idx, par, mem = ctx.nav, ctx.w, ctx.idx, ctx.par, ctx.mem
    z, H, R, m = rows
    for blk, off, bound in ((GYRO_BIAS, BG, par[GYRO_BOUND]), (ACC_BIAS, BA, par[ACC_BOUND])):
        if idx[blk] < 0 or bound <= 0.0:
            continue
        for i in range(3):
            b = nav[off + i]
            if b > bound or b < -bound:
                H[m, idx[blk] + i] = 1.0
                z[m] = (bound if b > 0.0 else -bound) - b
                R[m] = (0.1 * bound) * (0.1 * bound)
                mem[GUARD_ROWS] += 1.0
                m += 1
    if not ctx.stance:
        return m
    vel = idx[VEL]
    lever = par[ROLL_LEVER]
    r = par[VELOCITY_STD] * par[VELOCITY_STD] + lever * lever * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    for i in range(3):
        H[m, vel + i] = 1.0
        z[m] = nav[V + i]
        R[m] = r
        m += 1
    if par[ZERO_RATE] != 0.0:
        gb = idx[GYRO_BIAS]
        for i in range(3):
            H[m, gb + i] = 1.0
            z[m] = w[i]
            R[m] = par[RATE_STD] * par[RATE_STD]
            m += 1
    return hold_measure(ctx.stance, w, nav, idx, par, HOLD, mem, HOLD_STATE, z, H, R, m)


@after_function
def zero_velocity_after(ctx):
    """Follow the foot's still run for the stillness hold (:func:`footzoo.corrections.stillness.hold_track`)."""
    hold_track(ctx.t, ctx.stance, ctx.w, ctx.nav, ctx.par, HOLD, ctx.mem, HOLD_STATE)


def _bias_guard_report(mem: np.ndarray) -> dict[str, int]:
    """``bias_guard_rows``: how many bias-bound rows the guard added over the run (0: it never fired)."""
    return {"bias_guard_rows": int(mem[GUARD_ROWS])}


@register
class EKFZUPT(KalmanCorrection):
    """Error-state EKF zero-velocity update with optional bias states and zero-rate measurement.

    Nguyen & La 2016, IEEE THMS 46(6), Sec. IV, eqs. 28–52 and Algorithm 2: in
    every stance sample the measurement ``m = (δψ, δω, δv)`` — the velocity
    (true value zero, eq. 29), the bias-corrected angular rate (true value zero,
    eq. 30) and, with ``hdr``, the heading bias (eq. 23) — updates the 15-state
    error (attitude, gyro bias, position, velocity, accelerometer bias; eq. 31)
    with H of eq. 41. Switching off ``gyro_bias``, ``accel_bias`` and
    ``zero_rate`` gives the 9-state filter (attitude, position, velocity).

    The paper takes R and P⁰ from the IMU driver's covariances without giving
    numbers; footzoo's defaults: velocity 0.01 m/s and rate 0.05 rad/s
    measurement noise, initial bias uncertainties from the 3DM-GX3-25's initial
    bias specification (paper Table II: ±0.25 °/s, ±0.002 g). The bias process
    noise is zero by default, as in the paper's Q.

    Bias guard (footzoo's, ``bias_limit``): a bias estimate beyond ``bias_limit``
    times its initial standard deviation is measured at that bound in every
    sample until it is back inside (σ a tenth of the bound). Zero-velocity
    updates observe the biases only through the attitude and velocity errors;
    in a stance that is not still (a detector that takes a toe roll for
    stance, a missed stance closed by a guard) they absorb the motion: on
    PyShoe's 36 trials the ``nguyen2016`` filter without the guard estimated
    gyro biases up to 0.29 rad/s (17 °/s, the initial bias specification is
    0.25 °/s) and accelerometer biases up to 4.3 m/s² (0.44 g against 0.002 g).
    The default, 10 σ (2.5 °/s and 0.02 g with the defaults), is beyond any
    turn-on bias of the paper's sensor and leaves the simulator reproductions
    unchanged. 0: no guard (the paper's filter). How often it acted is in
    ``Result.diagnostics["bias_guard_rows"]``.

    Rolling stance (footzoo's, ``roll_lever``): a detected stance includes the
    heel rock after initial contact and the toe roll before toe-off, where the
    foot turns about its heel or its toes at the angular rate ``ω``. A sensor
    ``ℓ`` from that pivot then moves at ``ℓ |ω|`` (rigid body: ``v = ω × r``),
    so the zero-velocity measurement is known to ``σ² = σ_v² + (ℓ |ω|)²`` only:
    rolling samples weigh less than the still mid-stance, whatever the rate,
    the sensor or the motion. ``ℓ`` is the largest sensor-to-pivot distance,
    a fraction of the foot's length; 0 (the default) is the paper's constant
    ``σ_v``.

    Stillness hold (footzoo's, ``hold_after``, ``hold_std``, ``hold_rate``): once
    the foot has been still (stance and ``|ω̂| < hold_rate``) for ``hold_after``
    seconds, each further still sample also measures the position against its
    estimate at the start of the still run (σ ``hold_std``), so a foot that
    stands for minutes stays where it stood; see
    :mod:`footzoo.corrections.stillness` for why zero-velocity rows alone let it
    creep at ``a·dt/2`` for any unmodelled acceleration ``a``. 0 s: no hold (the
    paper's filter). The stances of walking and running are shorter than the
    default 2 s, so the hold acts only where a person stands.

    Parameters
    ----------
    gyro_bias, accel_bias : bool
        Include the bias states (need ``orientation: ins`` for the gyro bias).
    zero_rate : bool
        Include the zero-angular-rate measurement (needs ``gyro_bias``).
    velocity_std : float
        Zero-velocity measurement noise (m/s).
    rate_std : float
        Zero-rate measurement noise (rad/s).
    gyro_bias_std, accel_bias_std : float
        Initial bias uncertainty (rad/s, m/s²).
    gyro_bias_noise, accel_bias_noise : float
        Bias random-walk variance growth ((rad/s)²/s, (m/s²)²/s).
    bias_limit : float
        Bound of the bias estimates, in initial standard deviations (0: none).
    roll_lever : float
        Sensor-to-pivot distance ``ℓ`` of a rolling stance (m): the velocity
        rows' variance is ``velocity_std² + (ℓ |ω|)²`` (0: constant).
    hold_after : float
        Stillness (s) after which the foot's position is held; 0: no hold.
    hold_std : float
        σ of the position rows while held (m).
    hold_rate : float
        Largest ``|ω̂|`` of a still sample (rad/s).
    """

    name = "ekf_zupt"
    observes = ("velocity", "angular_rate")
    paper = "Nguyen & La 2016, IEEE THMS 46(6), eqs. 28-52, Algorithm 2, Sec. VI"
    parameters = {
        "gyro_bias": Boolean("estimate the gyro bias (needs orientation: ins)", source="Nguyen & La 2016, eq. 31"),
        "accel_bias": Boolean("estimate the accelerometer bias", source="Nguyen & La 2016, eq. 31"),
        "zero_rate": Boolean("measure the zero angular rate in stance (needs gyro_bias)",
                             source="Nguyen & La 2016, eq. 30"),
        "velocity_std": Real("m/s", "[1e-9, 1]", "σ of the zero-velocity measurement",
                             source="footzoo's (the paper takes R from the IMU driver)",
                             why="with σ of 1 m/s, a walking foot's speed, the update constrains nothing"),
        "rate_std": Real("rad/s", "[1e-9, 1]", "σ of the zero-rate measurement",
                         source="footzoo's (the paper takes R from the IMU driver)",
                         why="with σ of 1 rad/s (57 °/s) the update constrains nothing"),
        "gyro_bias_std": Real("rad/s", "[0, 1]", "initial σ of the gyro bias",
                              source="Nguyen & La 2016, Table II: the 3DM-GX3-25's ±0.25 °/s",
                              why="consumer MEMS gyros are specified to ±0.35 rad/s (20 °/s) at most"),
        "accel_bias_std": Real("m/s^2", "[0, 2]", "initial σ of the accelerometer bias",
                               source="Nguyen & La 2016, Table II: the 3DM-GX3-25's ±0.002 g",
                               why="consumer MEMS accelerometers are specified to ±0.1 g (1 m/s²) at most"),
        "gyro_bias_noise": Real("(rad/s)^2/s", "[0, 1]", "variance growth of the gyro bias (random walk)",
                                source="Nguyen & La 2016's Q (zero)"),
        "accel_bias_noise": Real("(m/s^2)^2/s", "[0, 10]", "variance growth of the accelerometer bias (random walk)",
                                 source="Nguyen & La 2016's Q (zero)"),
        "bias_limit": Real("1", "[0, 1000]", "bound of the bias estimates in initial σ; 0: none",
                           source="footzoo's guard: beyond any turn-on bias of the paper's sensor (see the docstring)"),
        "roll_lever": Real("m", "[0, 1]", "sensor-to-pivot distance of a rolling stance: σ² = σ_v² + (ℓ |ω|)²",
                           source="footzoo's (rigid-body roll about the heel or the toes; see the docstring)",
                           why="a foot is about 0.25 m long: beyond 1 m a turning foot's stance counts for nothing"),
        **HOLD_PARAMETERS,
    }

    def __init__(
        self,
        gyro_bias: bool = True,
        accel_bias: bool = True,
        zero_rate: bool = True,
        velocity_std: float = 0.01,
        rate_std: float = 0.05,
        gyro_bias_std: float = float(np.radians(0.25)),
        accel_bias_std: float = 0.002 * 9.81,
        gyro_bias_noise: float = 0.0,
        accel_bias_noise: float = 0.0,
        bias_limit: float = 10.0,
        roll_lever: float = 0.0,
        hold_after: float = HOLD_DEFAULTS["hold_after"],
        hold_std: float = HOLD_DEFAULTS["hold_std"],
        hold_rate: float = HOLD_DEFAULTS["hold_rate"],
    ):
        if zero_rate and not gyro_bias:
            raise ConfigError("zero_rate measures the gyro bias: it needs gyro_bias: true (or set zero_rate: false)")
        self.gyro_bias = gyro_bias
        self.accel_bias = accel_bias
        self.zero_rate = zero_rate
        self.velocity_std = velocity_std
        self.rate_std = rate_std
        self.gyro_bias_std = gyro_bias_std
        self.accel_bias_std = accel_bias_std
        self.gyro_bias_noise = gyro_bias_noise
        self.accel_bias_noise = accel_bias_noise
        self.bias_limit = bias_limit
        self.roll_lever = roll_lever
        self.hold_after = hold_after
        self.hold_std = hold_std
        self.hold_rate = hold_rate

    def state_blocks(self) -> list[StateBlock]:
        """The core bias blocks this correction switches on (initial variance, variance growth per s)."""
        out = []
        if self.gyro_bias:
            out.append(StateBlock("gyro_bias", 3, self.gyro_bias_std**2, self.gyro_bias_noise))
        if self.accel_bias:
            out.append(StateBlock("acc_bias", 3, self.accel_bias_std**2, self.accel_bias_noise))
        return out

    def requires_attitude_state(self) -> bool:
        """The gyro bias and the zero-rate measurement act through the attitude error."""
        return self.gyro_bias or self.zero_rate

    def model(self, samples: Samples) -> MeasurementModel:
        """Velocity rows (and angular-rate rows with ``zero_rate``) in every stance sample; position rows while
        the foot is held."""
        return MeasurementModel(
            measure=zero_velocity_measure, after=zero_velocity_after,
            max_rows=(6 if self.zero_rate else 3) + 6 + HOLD_ROWS,
            par=np.array([self.velocity_std, 1.0 if self.zero_rate else 0.0, self.rate_std,
                          self.bias_limit * self.gyro_bias_std, self.bias_limit * self.accel_bias_std,
                          self.roll_lever, *hold_constants(self.hold_after, self.hold_std, self.hold_rate)]),
            mem=np.zeros(1 + HOLD_MEM), diagnostics=_bias_guard_report,
        )


@register
class ZUPT(EKFZUPT):
    """Zero-velocity update of the error-state Kalman filter (Duong & Suh 2015, eq. 23).

    Duong & Suh 2015, Sensors 15, Sec. 4.2: in zero-velocity intervals the
    measurement ``z_v = 0 − v̂`` with ``H_v`` picking the velocity error and noise
    ``E{v_zero v_zero'} = 0.0001 I`` (Table 1, σ = 0.01 m/s). The same model as
    ``ekf_zupt`` without bias states or the zero-rate measurement: with the
    attitude, position and velocity errors of the INS it is the paper's
    9-state filter.

    Parameters
    ----------
    velocity_std : float
        Standard deviation of v_zero (m/s).
    roll_lever : float
        Sensor-to-pivot distance of a rolling stance (m; 0, the default, is the
        paper's constant noise): the variance is ``velocity_std² + (ℓ |ω|)²``,
        see ``ekf_zupt``.
    hold_after, hold_std, hold_rate : float
        The stillness hold (s, m, rad/s; ``hold_after`` 0: none, the paper's
        filter), see ``ekf_zupt``.
    """

    name = "zupt"
    observes = ("velocity",)
    paper = "Duong & Suh 2015, Sensors 15, eq. 23, Table 1"
    parameters = {"velocity_std": EKFZUPT.parameters["velocity_std"].replace(
        source="Duong & Suh 2015, Table 1 (variance 0.0001)"), "roll_lever": EKFZUPT.parameters["roll_lever"],
        **HOLD_PARAMETERS}

    def __init__(self, velocity_std: float = 0.01, roll_lever: float = 0.0,
                 hold_after: float = HOLD_DEFAULTS["hold_after"], hold_std: float = HOLD_DEFAULTS["hold_std"],
                 hold_rate: float = HOLD_DEFAULTS["hold_rate"]):
        super().__init__(gyro_bias=False, accel_bias=False, zero_rate=False, velocity_std=velocity_std,
                         roll_lever=roll_lever, hold_after=hold_after, hold_std=hold_std, hold_rate=hold_rate)
