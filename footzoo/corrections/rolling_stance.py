"""Rolling-foot stance update: the foot's contact point, not the sensor, is at rest in stance.

The zero-velocity update assumes the sensor itself is at rest during the detected stance. A foot is
not a point: after initial contact it rocks over its heel and before toe-off it rolls over its toes
(the metatarsal heads), so a sensor on the instep moves during the stance a detector reports.
Peruzzi, Della Croce & Cereatti 2011 (J. Biomech. 44(10), 1991–1994, doi:10.1016/j.jbiomech.2011.04.035)
measured the smallest velocity that foot and shank points reach in the stance of level walking:
below 0.011 m/s on average for foot points, growing with gait speed, so the zero-velocity assumption
holds for a foot sensor only at its quietest instant. Nilsson, Skog & Händel 2012 ("A note on the
limitations of ZUPTs and the implications on sensor error modeling", IPIN 2012) and Wahlström &
Skog 2021 ("Fifteen years of progress at zero velocity: a review", IEEE Sensors J. 21(2), 1139–1151)
discuss the zero-velocity pseudo-measurement as a model whose error, not the sensor's noise, limits
what it can tell the filter.

Model
-----
During the stance the foot turns about a contact point on the floor. In the body frame (FRD, origin at
the sensor) the contact point is ``c`` (m); it is at rest, so its velocity (NED)

    v_c = v + C(q) (ω × c) = 0

— the sensor moves at ``v = C(q)(ω × r)`` with ``r = −c`` the lever from the contact point to the
sensor. A foot has two: the heel, about which it rocks after initial contact, and the toes (the
metatarsal heads), over which it rolls before toe-off. Both are filter states (``contact_heel``,
``contact_toe``: 3 each, initial ``heel`` and ``toe`` with σ ``lever_std``, a random walk of
``lever_noise``), so the levers are learnt from the recording: the accelerometers see the rotation
about a fixed point (its tangential and centripetal acceleration) that the rows predict. Each stance
sample uses the contact whose rows leave the smaller residual: on the same rotation the two predict
opposite vertical velocities (a sensor above and between them sinks as the foot rocks over the heel
and rises as it rolls over the toes), so the choice is clear whenever it matters and immaterial when
the foot hardly turns. With ``c = 0`` the rows are the zero-velocity update.

A sample's rate ``ω̂`` is the mean over the interval before it (an integrating gyroscope, or the
simulator's interval sampling), so the rows hold at the interval's middle: ``v̄ = (v̂_{k−1}⁺ + v̂_k⁻)/2``
and ``C̄`` the normalised mean of the two attitudes, the strapdown's own interval; their errors are the
sample's to first order. At 100 Hz on the simulator's rolling foot (up to 14.5 rad/s), with the true
levers, rows at the sample time (the rate carried on by half an interval) left the strides 4.0 cm short,
rows at the interval's middle 1.5 cm.

Rows and their Jacobian (footzoo's error conventions: ``δx`` = estimate − truth, ``C = (I − [δφ×]) Ĉ``,
the gyro-bias error ``δb`` is the correction added to the bias, ``ω̂ = ω_m − b̂``). With ``u = Ĉ(ω̂ × ĉ)``
the residual is ``z = v̂ + u`` (measured value 0) and, to first order,

    z = δv − [u×] δφ − Ĉ [ĉ×] δb_g + Ĉ [ω̂×] δc

because ``(Ĉ − C) a = [δφ×] Ĉ a = −[u×] δφ`` for ``a = ω × c``, ``ω̂ − ω = δb_g`` (so
``C((ω̂ − ω) × c) = −C [c×] δb_g``) and ``ĉ − c = δc`` (``tests/corrections/test_rolling_stance.py`` checks
H against finite differences). Each of the three rows has the variance ``σ_r² + (ℓ_s |ω̂|)²``: ``σ_r``
(``velocity_std``) the model's error at rest, ``ℓ_s`` (``contact_spread``) how far the real contact
wanders from one point (a heel is round, a shoe bends).

Use it alone (it is then the stance update, and holds a standing foot like ``zupt``: the stillness
hold of :mod:`footzoo.corrections.stillness`) or after ``zupt`` (the zero-velocity rows then count for
the still mid-stance, these for the rolling; give ``zupt`` its ``roll_lever`` so the two do not
disagree while the foot turns, and ``hold_after: 0`` to one of the two).
"""

from __future__ import annotations

import math

import numpy as np

from ..filters.measurement import (
    ATT,
    GYRO_BIAS,
    OWN,
    VEL,
    MeasurementModel,
    Q,
    StateBlock,
    V,
    after_function,
    feedback_function,
    measurement_function,
)
from ..plugins.base import KalmanCorrection, Real, Samples, Vector
from ..plugins.registry import register
from .stillness import HOLD_DEFAULTS, HOLD_MEM, HOLD_PARAMETERS, HOLD_ROWS, hold_constants, hold_measure, hold_track

#: Positions in the model's ``par``: σ_r (m/s), ℓ_s (m), then the stillness hold's constants. In ``mem``: the
#: heel's and the toe's lever estimates (3 each, body frame, m), the contact of the last stance sample (0 heel,
#: 1 toe), the last sample's corrected attitude (4) and velocity (3, m/s), then the hold's memory.
VELOCITY_STD, CONTACT_SPREAD, HOLD = 0, 1, 2
HEEL, TOE, CONTACT, Q_LAST, V_LAST, HOLD_STATE = 0, 3, 6, 7, 11, 14
#: The own blocks, in ``idx`` order after the core ones.
BLOCKS = ("contact_heel", "contact_toe")


@measurement_function
def contact_measure(ctx, rows):
    """In stance: the contact point's velocity ``v̄ + C̄(ω̂ × ĉ)``, measured 0 (three rows); the stillness hold's rows.

    A sample's rate ``ω̂`` is the mean over its interval, so the rows hold at the interval's middle: ``v̄`` and
    ``C̄`` are the mean of the last corrected and this predicted velocity and attitude (the strapdown's own
    interval); their errors are this sample's to first order. ``ĉ`` is the heel's or the toe's lever, whichever
    leaves the smaller residual.
    """
    nav, w, idx, par, mem = ctx.nav, ctx.w, ctx.idx, ctx.par, ctx.mem
    z, H, R, m = rows
    if not ctx.stance:
        return m
    e0, e1, e2 = w[0], w[1], w[2]
    qw, qx, qy, qz = nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3]
    pw, px, py, pz = mem[Q_LAST], mem[Q_LAST + 1], mem[Q_LAST + 2], mem[Q_LAST + 3]
    if pw * qw + px * qx + py * qy + pz * qz < 0.0:
        pw, px, py, pz = -pw, -px, -py, -pz
    qw, qx, qy, qz = qw + pw, qx + px, qy + py, qz + pz
    norm = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    qw, qx, qy, qz = qw / norm, qx / norm, qy / norm, qz / norm
    v0 = 0.5 * (nav[V] + mem[V_LAST])
    v1 = 0.5 * (nav[V + 1] + mem[V_LAST + 1])
    v2 = 0.5 * (nav[V + 2] + mem[V_LAST + 2])
    C00, C01, C02 = 1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)
    C10, C11, C12 = 2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)
    C20, C21, C22 = 2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)
    # the residual v̂ + Ĉ(ω̂ × ĉ) of each contact; the smaller one's
    best, at = -1.0, HEEL
    for lever in (HEEL, TOE):
        c0, c1, c2 = mem[lever], mem[lever + 1], mem[lever + 2]
        b0, b1, b2 = e1 * c2 - e2 * c1, e2 * c0 - e0 * c2, e0 * c1 - e1 * c0
        r0 = v0 + C00 * b0 + C01 * b1 + C02 * b2
        r1 = v1 + C10 * b0 + C11 * b1 + C12 * b2
        r2 = v2 + C20 * b0 + C21 * b1 + C22 * b2
        size = r0 * r0 + r1 * r1 + r2 * r2
        if best < 0.0 or size < best:
            best, at = size, lever
    own = idx[OWN + 1] if at == TOE else idx[OWN]
    mem[CONTACT] = 1.0 if at == TOE else 0.0
    c0, c1, c2 = mem[at], mem[at + 1], mem[at + 2]
    b0, b1, b2 = e1 * c2 - e2 * c1, e2 * c0 - e0 * c2, e0 * c1 - e1 * c0
    u0 = C00 * b0 + C01 * b1 + C02 * b2
    u1 = C10 * b0 + C11 * b1 + C12 * b2
    u2 = C20 * b0 + C21 * b1 + C22 * b2
    w2 = e0 * e0 + e1 * e1 + e2 * e2
    r = par[VELOCITY_STD] * par[VELOCITY_STD] + par[CONTACT_SPREAD] * par[CONTACT_SPREAD] * w2
    vel, att, gb = idx[VEL], idx[ATT], idx[GYRO_BIAS]
    for i in range(3):
        Ci0, Ci1, Ci2 = (C00, C01, C02) if i == 0 else ((C10, C11, C12) if i == 1 else (C20, C21, C22))
        ui = u0 if i == 0 else (u1 if i == 1 else u2)
        H[m, vel + i] = 1.0
        if att >= 0:  # −[u×] δφ, row i
            if i == 0:
                H[m, att + 1], H[m, att + 2] = u2, -u1
            elif i == 1:
                H[m, att], H[m, att + 2] = -u2, u0
            else:
                H[m, att], H[m, att + 1] = u1, -u0
        if gb >= 0:  # −Ĉ [ĉ×] δb, row i
            H[m, gb] = Ci2 * c1 - Ci1 * c2
            H[m, gb + 1] = Ci0 * c2 - Ci2 * c0
            H[m, gb + 2] = Ci1 * c0 - Ci0 * c1
        # Ĉ [ω̂×] δc, row i
        H[m, own] = Ci1 * e2 - Ci2 * e1
        H[m, own + 1] = Ci2 * e0 - Ci0 * e2
        H[m, own + 2] = Ci0 * e1 - Ci1 * e0
        z[m] = (v0 if i == 0 else (v1 if i == 1 else v2)) + ui
        R[m] = r
        m += 1
    return hold_measure(ctx.stance, w, nav, idx, par, HOLD, mem, HOLD_STATE, z, H, R, m)


@feedback_function
def contact_feedback(ctx, dx):
    """Apply the lever errors: ``ĉ ← ĉ − δc`` for the heel and the toe."""
    idx, mem = ctx.idx, ctx.mem
    for i in range(3):
        mem[HEEL + i] -= dx[idx[OWN] + i]
        mem[TOE + i] -= dx[idx[OWN + 1] + i]


@after_function
def contact_after(ctx):
    """Keep the sample's corrected attitude and velocity; follow the still run of the stillness hold."""
    for i in range(4):
        ctx.mem[Q_LAST + i] = ctx.nav[Q + i]
    for i in range(3):
        ctx.mem[V_LAST + i] = ctx.nav[V + i]
    hold_track(ctx.t, ctx.stance, ctx.w, ctx.nav, ctx.par, HOLD, ctx.mem, HOLD_STATE)


def _levers(mem: np.ndarray) -> dict[str, list[float]]:
    """``contact_levers``: the heel's and the toe's contact point at the end of the run (body frame, m)."""
    return {"contact_levers": {"heel": mem[HEEL:HEEL + 3].tolist(), "toe": mem[TOE:TOE + 3].tolist()}}


@register
class RollingStance(KalmanCorrection):
    """Stance update of a foot that rolls over its heel and toes: its contact point is at rest.

    In every stance sample the velocity of the contact point, ``v + C(q)(ω × c)``, is measured zero
    (three rows; ``c`` from the sensor to the heel or to the toes, whichever explains the sample's
    velocity better). The heel's and the toe's lever are filter states learnt from the recording. The
    footzoo conventions, the Jacobian and the references (Peruzzi, Della Croce & Cereatti 2011;
    Nilsson, Skog & Händel 2012; Wahlström & Skog 2021) are in the module docstring
    (:mod:`footzoo.corrections.rolling_stance`). With the stillness hold of ``zupt``
    (:mod:`footzoo.corrections.stillness`).

    The levers at the end of a run are in ``Result.diagnostics["contact_levers"]``.

    Parameters
    ----------
    heel, toe : list of 3 float
        Initial sensor-to-contact vectors (m, body frame FRD): a sensor on the instep is about 0.1 m
        ahead of the heel and 0.1 m behind the metatarsal heads, 0.07 m above the sole.
    lever_std : float
        Initial σ of each lever component (m).
    lever_noise : float
        Random-walk variance growth of each lever component (m²/s).
    velocity_std : float
        σ_r: the rows' noise while the foot does not turn (m/s).
    contact_spread : float
        ℓ_s: how far the real contact wanders from one point (m); the rows' variance is
        ``velocity_std² + (ℓ_s |ω̂|)²``.
    hold_after, hold_std, hold_rate : float
        The stillness hold (s, m, rad/s; ``hold_after`` 0: none), as ``zupt``'s.
    """

    name = "rolling_stance"
    observes = ("contact_velocity",)
    paper = ("footzoo's rolling-foot model after Peruzzi, Della Croce & Cereatti 2011 (J. Biomech. 44(10)); "
             "Nilsson, Skog & Händel 2012 (IPIN); Wahlström & Skog 2021 (IEEE Sensors J. 21(2))")
    parameters = {
        "heel": Vector(3, "m", "initial sensor-to-heel contact vector (body frame, FRD)", range="[-0.5, 0.5]",
                       source="footzoo's: an instep sensor 0.1 m ahead of the heel, 0.07 m above the sole",
                       why="a contact point more than 0.5 m from a foot sensor is not on that foot"),
        "toe": Vector(3, "m", "initial sensor-to-toe contact vector (body frame, FRD)", range="[-0.5, 0.5]",
                      source="footzoo's: the metatarsal heads 0.1 m ahead of an instep sensor, 0.07 m below it",
                      why="a contact point more than 0.5 m from a foot sensor is not on that foot"),
        "lever_std": Real("m", "[0, 0.5]", "initial σ of each lever component",
                          source="footzoo's: 0.05 m, where a sensor sits on a shoe"),
        "lever_noise": Real("m^2/s", "[0, 1]", "random-walk variance growth of each lever component",
                            source="footzoo's: (1 mm)²/s, a shoe that bends a little"),
        "velocity_std": Real("m/s", "[1e-9, 1]", "σ_r of the contact-velocity rows while the foot does not turn",
                             source="recommended's zero-velocity σ (0.03 m/s)",
                             why="with σ of 1 m/s, a walking foot's speed, the rows constrain nothing"),
        "contact_spread": Real("m", "[0, 1]", "how far the real contact wanders from one point: σ² = σ_r² + (ℓ_s |ω|)²",
                               source="footzoo's: 2 cm, the radius of a heel's curve", why="a foot is 0.25 m long"),
        **HOLD_PARAMETERS,
    }

    def __init__(
        self,
        heel: list | tuple = (-0.10, 0.0, 0.07),
        toe: list | tuple = (0.10, 0.0, 0.07),
        lever_std: float = 0.05,
        lever_noise: float = 1e-6,
        velocity_std: float = 0.03,
        contact_spread: float = 0.02,
        hold_after: float = HOLD_DEFAULTS["hold_after"],
        hold_std: float = HOLD_DEFAULTS["hold_std"],
        hold_rate: float = HOLD_DEFAULTS["hold_rate"],
    ):
        self.heel = heel
        self.toe = toe
        self.lever_std = lever_std
        self.lever_noise = lever_noise
        self.velocity_std = velocity_std
        self.contact_spread = contact_spread
        self.hold_after = hold_after
        self.hold_std = hold_std
        self.hold_rate = hold_rate

    def state_blocks(self) -> list[StateBlock]:
        """The heel's and the toe's lever (3 states each, m)."""
        return [StateBlock(name, 3, self.lever_std**2, self.lever_noise) for name in BLOCKS]

    def model(self, samples: Samples) -> MeasurementModel:
        """Three contact-velocity rows in every stance sample; the hold's rows while the foot is held."""
        mem = np.zeros(HOLD_STATE + HOLD_MEM)
        mem[HEEL:HEEL + 3] = np.asarray(self.heel, float)
        mem[TOE:TOE + 3] = np.asarray(self.toe, float)
        return MeasurementModel(
            measure=contact_measure, feedback=contact_feedback, after=contact_after, max_rows=3 + HOLD_ROWS,
            par=np.array([self.velocity_std, self.contact_spread,
                          *hold_constants(self.hold_after, self.hold_std, self.hold_rate)]),
            mem=mem, block_names=list(BLOCKS), diagnostics=_levers,
        )
