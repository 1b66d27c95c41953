"""Foot motion model: a timeline of gait phases with exact position, velocity and attitude.

Yun et al. 2012, Sec. III-B and Table I: a gait cycle is stance (initial
contact, foot flat, pre-swing) and swing (acceleration, deceleration). The
foot pitches about its y axis: −θ_ic during initial contact (Table I:
−6.5 rad/s × 0.1 s), nothing during foot flat, −θ_ps during pre-swing
(−7.5 rad/s × 0.1 s) and +(θ_ic + θ_ps) during swing (+3.5 rad/s × 0.4 s),
so the attitude returns to where it started. Phase durations scale with the
cycle time and the stance fraction (Table I: 1 s, 60 %).

Two profiles:

* ``"paper"`` — Table I as printed: constant angular rates, and the sensor does
  not move while the foot rolls over heel and toe (linear acceleration zero in
  stance). The truth's stance is the whole 60 %.
* ``"physical"`` — the foot rotates about its heel (initial contact) and toe
  (pre-swing) contact points, so the instep sensor moves; the heel rotation's
  rate follows a raised cosine with Table I's angle, so velocities have no
  jumps. The toe leaves the floor the way a real one does, while the foot
  still plantar-flexes fast (:class:`~footzoo.sim.profiles.FootPitch`): the
  push-off's rate rises to about 9.4 rad/s and holds it until toe-off, then
  turns in the air into the swing's dorsi-flexion (through zero 12.5 ms after
  toe-off at a 1 s cycle), which falls back to zero at heel strike; so the
  rate passes through zero at heel strike, and the sensor leaves the toe with
  its velocity and acceleration, which fade over the swing (velocity and
  acceleration continuous at toe-off and heel strike). The foot also rolls
  about its long axis through heel strike (:data:`HEEL_ROLL`): it lands
  inverting at 1.5 rad/s and everts flat in the loading response, as real feet
  do, so ``|ω|`` does not fall below 1 rad/s while the sagittal rate crosses
  zero; the sensor arrives on the heel with the velocity and acceleration of
  that rotation. Only foot flat (and standing) is stance.

In both, the swing carries the sensor along the straight horizontal line
between its positions at toe-off and heel strike with the corrected Gaussian
velocity profile (eq. 14) and lifts it by the clearance with the corrected
Gaussian of eq. 15 (see :mod:`footzoo.sim.profiles`; in the physical profile
plus the fading toe-off motion); the foot's yaw turns from one stance's yaw to
the next with the same progress profile. The truth's toe-off (``swing_start``)
is the instant the toe leaves the floor, its initial contact (``swing_end``)
the instant the heel touches it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.conventions import quat_from_euler, quat_mul, quat_to_matrix
from .profiles import FootPitch, GaussianSwing, SmoothRate, rotation_progress

#: Table I angles (rad): initial contact −6.5 rad/s × 0.1 s, pre-swing −7.5 rad/s × 0.1 s.
IC_ANGLE = 0.65
PS_ANGLE = 0.75
#: Physical profile (:class:`~footzoo.sim.profiles.FootPitch`): the push-off's plantar-flexion rate reaches its
#: peak over this share of the pre-swing and holds it until toe-off (Table I's pre-swing: 0.1 s of a 1 s cycle,
#: 0.75 rad); in the air it turns into the swing's dorsi-flexion over this share of the pre-swing (its zero
#: crossing then falls 12.5 % of the pre-swing after toe-off); it falls to zero at heel strike over this share of
#: the swing. On gaitmap's example walk (motion capture, 57 strides) the rate's minimum (about −9.5 rad/s) lies a
#: median 7 ms before the toe-off (1.5 samples at 204.8 Hz; the reference's own resolution is 10 ms), its zero
#: crossing 15 ms after it, and it falls from about 6 rad/s over the last 0.1 s before the initial contact.
PUSH_RISE = 0.4
PUSH_TURN = 0.2
SWING_DECLINE = 0.25
#: Physical profile: the foot's roll about its long axis through heel strike, as knots ``(time from IC s, rate
#: rad/s)`` of a :class:`~footzoo.sim.profiles.SmoothRate` at a 1 s cycle (times scale with the cycle, rates
#: inversely; positive: inversion, the sole turning inward). The foot lands inverting at 1.5 rad/s and everts
#: flat in the loading response; the eversion peak (``None``) makes the net roll zero (4.6 rad/s at +35 ms).
#: On gaitmap's example walk (57 motion-capture ICs, median over strides) the sensor's roll rate is 1.2–1.7 rad/s
#: from 30 ms before IC to 10 ms after it, inversion on both feet, then eversion peaking at 4.8 rad/s 30–50 ms
#: after IC and back to zero by +70 ms; the rate about the axes other than the sagittal one is 1.7 rad/s at IC
#: (PyShoe's walks 1.3, IPOL 1.7), so ``|ω|`` stays above 1 rad/s while the sagittal rate crosses zero
#: (benchmarks/heel_strike.md).
HEEL_ROLL = ((-0.10, 0.0), (-0.04, 1.5), (0.01, 1.5), (0.035, None), (0.07, 0.0))


def heel_strike_roll(cycle: float, swing: float, contact: float, side: int) -> SmoothRate:
    """The roll through heel strike (:data:`HEEL_ROLL`) of a stride: time 0 at IC, net roll zero.

    ``cycle`` (s) scales the knots; the part before IC is squeezed into the last half of the ``swing`` and
    the part after it into 90 % of the ``contact`` (heel rotation) phase when they are shorter. ``side``: +1
    right foot, −1 left (inversion is a positive roll of a right foot, a negative one of a left foot).
    """
    before = min(cycle, 0.5 * swing / -HEEL_ROLL[0][0])
    after = min(cycle, 0.9 * contact / HEEL_ROLL[-1][0])
    times = np.array([k[0] * (before if k[0] < 0 else after) for k in HEEL_ROLL])
    rates = np.array([0.0 if k[1] is None else k[1] / cycle for k in HEEL_ROLL])
    j = next(i for i, k in enumerate(HEEL_ROLL) if k[1] is None)
    # net roll zero: the rate x at knot j adds x (t_{j+1} − t_{j−1}) / 2 to the roll made with x = 0
    rates[j] = -2 * SmoothRate(times, rates).total / (times[j + 1] - times[j - 1])
    return SmoothRate(times, side * rates)


@dataclass
class StrideSpec:
    """Timing and height of one gait cycle.

    Parameters
    ----------
    cycle : float
        Gait cycle duration (s); Table I: 1.0.
    stance_fraction : float
        Stance share of the cycle; Table I: 0.6 (running: about 0.4).
    clearance : float
        Peak height of the swing above the straight toe-off-to-heel-strike line (m);
        Table II: 0.25.
    flat_fraction : float
        Foot-flat share of the stance; Table I: 0.4 s of 0.6 s = 2/3. Running has
        almost no flat foot (about 0.2).
    """

    cycle: float = 1.0
    stance_fraction: float = 0.6
    clearance: float = 0.25
    flat_fraction: float = 2.0 / 3.0

    def phases(self) -> dict[str, float]:
        """Durations (s) of initial contact, foot flat, pre-swing and swing."""
        stance = self.cycle * self.stance_fraction
        roll = stance * (1.0 - self.flat_fraction) / 2.0
        return {"ic": roll, "ff": stance * self.flat_fraction, "ps": roll, "swing": self.cycle - stance}


@dataclass
class Footstep:
    """Where and how the foot is flat on the floor: sensor position (NED, m), walking heading and FPA (rad)."""

    pos: np.ndarray
    heading: float
    fpa: float = 0.0


@dataclass
class FootGeometry:
    """Sensor mounting and contact points, in the foot frame (FRD, origin at the sensor, m / rad).

    ``heel`` and ``toe`` are the vectors from the sensor to the heel and toe
    contact points with the foot flat; ``mount_yaw`` and ``mount_pitch`` rotate
    the sensor on the foot; ``side`` is +1 for a right foot (toe-out = yaw to
    the right) and −1 for a left foot.
    """

    heel: np.ndarray = field(default_factory=lambda: np.array([-0.10, 0.0, 0.06]))
    toe: np.ndarray = field(default_factory=lambda: np.array([0.12, 0.0, 0.06]))
    mount_yaw: float = 0.0
    mount_pitch: float = 0.0
    side: int = 1

    def mount_quat(self) -> np.ndarray:
        """Sensor attitude in the foot frame (scalar first)."""
        return quat_from_euler(0.0, self.mount_pitch, self.mount_yaw)


def _rz(psi: np.ndarray) -> np.ndarray:
    c, s = np.cos(psi), np.sin(psi)
    z, o = np.zeros_like(psi), np.ones_like(psi)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def _ry(theta: np.ndarray, order: int = 0) -> np.ndarray:
    """Ry(θ) or its first/second derivative with respect to θ."""
    c, s = np.cos(theta), np.sin(theta)
    z = np.zeros_like(theta)
    if order == 0:
        rows = [[c, z, s], [z, z + 1, z], [-s, z, c]]
    elif order == 1:
        rows = [[-s, z, c], [z, z, z], [-c, z, -s]]
    else:
        rows = [[-c, z, -s], [z, z, z], [s, z, -c]]
    return np.stack([np.stack(r, -1) for r in rows], -2)


def _fading(x: np.ndarray) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    """Quintic Hermite functions on ``x ∈ [0, 1]`` and their first two derivatives in ``x``: ``f`` (slope 1 at 0)
    and ``g`` (curvature 1 at 0), both zero at 0 otherwise and zero with their first two derivatives at 1."""
    f = (x - 6 * x**3 + 8 * x**4 - 3 * x**5, 1 - 18 * x**2 + 32 * x**3 - 15 * x**4, -36 * x + 96 * x**2 - 60 * x**3)
    g = (x**2 / 2 - 1.5 * x**3 + 1.5 * x**4 - x**5 / 2, x - 4.5 * x**2 + 6 * x**3 - 2.5 * x**4,
         1 - 9 * x + 18 * x**2 - 10 * x**3)
    return f, g


def _rx(phi: np.ndarray, order: int = 0) -> np.ndarray:
    """Rx(φ) or its first/second derivative with respect to φ."""
    c, s = np.cos(phi), np.sin(phi)
    z = np.zeros_like(phi)
    if order == 0:
        rows = [[z + 1, z, z], [z, c, -s], [z, s, c]]
    elif order == 1:
        rows = [[z, z, z], [z, -s, -c], [z, c, -s]]
    else:
        rows = [[z, z, z], [z, -c, s], [z, -s, -c]]
    return np.stack([np.stack(r, -1) for r in rows], -2)


def _pitch_roll(th, thd, thdd, ph, phd, phdd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``R = Ry(θ) Rx(φ)`` and its first and second time derivatives, (n, 3, 3) each."""
    y0, y1, y2 = _ry(th), _ry(th, 1), _ry(th, 2)
    x0, x1, x2 = _rx(ph), _rx(ph, 1), _rx(ph, 2)
    a, b = thd[:, None, None], phd[:, None, None]
    r = y0 @ x0
    r1 = y1 @ x0 * a + y0 @ x1 * b
    r2 = (y2 @ x0 * a**2 + 2 * (y1 @ x1) * a * b + y0 @ x2 * b**2
          + y1 @ x0 * thdd[:, None, None] + y0 @ x1 * phdd[:, None, None])
    return r, r1, r2


@dataclass
class Segment:
    """One phase of the timeline, evaluated in closed form."""

    t0: float
    t1: float
    kind: str  # "still", "ic", "ps", "swing"
    still: bool
    psi: tuple[float, float]
    theta: tuple[float, float]
    contact: np.ndarray | None = None  # world contact point (ic/ps, physical)
    r_contact: np.ndarray | None = None  # foot-frame vector sensor -> contact
    a: np.ndarray | None = None  # swing start / still position
    b: np.ndarray | None = None  # swing end
    clearance: float = 0.0
    smooth: bool = False
    swing: GaussianSwing | None = None
    cycles: int = 0  # flex: number of dorsi-/plantar-flexion cycles (theta[0] is the amplitude)
    foot_pitch: FootPitch | None = None  # physical ps and swing: the pitch from heel-off to heel strike
    v0: np.ndarray | None = None  # physical swing: the sensor's velocity at toe-off (NED, m/s)
    a0: np.ndarray | None = None  # physical swing: the sensor's acceleration at toe-off (NED, m/s²)
    roll: SmoothRate | None = None  # physical swing and ic: the roll through heel strike (time 0 at t_contact)
    t_contact: float = 0.0  # the heel strike's time (s)
    v1: np.ndarray | None = None  # physical swing: the sensor's velocity at heel strike (NED, m/s)
    a1: np.ndarray | None = None  # physical swing: the sensor's acceleration at heel strike (NED, m/s²)

    def evaluate(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Position, velocity, acceleration (NED), yaw ψ, pitch θ, roll φ and their rates at absolute times ``t``."""
        tl = np.asarray(t, dtype=float) - self.t0
        n = tl.shape[0]
        T = self.t1 - self.t0
        out = {k: np.zeros((n, 3)) for k in ("p", "v", "a")}
        if self.roll is not None:
            out["phi"], out["phi_dot"], phi_ddot = self.roll.angle(tl + self.t0 - self.t_contact)
        else:
            out["phi"], out["phi_dot"], phi_ddot = np.zeros(n), np.zeros(n), np.zeros(n)
        if self.kind == "swing":
            s, s1, s2 = self.swing.progress(tl)
            u, u1, u2 = rotation_progress(tl, T, self.smooth)
            d = self.b - self.a
            bb, b1, b2 = self.swing.bump(tl)
            up = np.array([0.0, 0.0, -self.clearance])
            out["p"] = self.a + s[:, None] * d + bb[:, None] * up
            out["v"] = s1[:, None] * d + b1[:, None] * up
            out["a"] = s2[:, None] * d + b2[:, None] * up
            dpsi, dth = self.psi[1] - self.psi[0], self.theta[1] - self.theta[0]
            out["psi"], out["psi_dot"] = self.psi[0] + dpsi * s, dpsi * s1
            out["theta"], out["theta_dot"] = self.theta[0] + dth * u, dth * u1
            if self.foot_pitch is not None:
                self._push_through_toe_off(tl, T, out)
            if self.v1 is not None:
                self._land_on_heel(tl, T, out)
            return out
        if self.kind == "still":
            out["p"] = np.tile(self.a, (n, 1))
            out["psi"], out["psi_dot"] = np.full(n, self.psi[0]), np.zeros(n)
            out["theta"], out["theta_dot"] = np.full(n, self.theta[0]), np.zeros(n)
            return out
        # rotation about a contact point (ic, ps) or the ankle (flex)
        if self.kind == "flex":
            th, thd, thdd = flexion_angle(tl, T, self.theta[0], self.cycles)
        elif self.foot_pitch is not None:  # pre-swing: the push-off, rotating fast when the toe leaves
            th, thd, thdd = self.foot_pitch.pitch(tl)
        else:
            u, u1, u2 = rotation_progress(tl, T, self.smooth)
            dth = self.theta[1] - self.theta[0]
            th, thd, thdd = self.theta[0] + dth * u, dth * u1, dth * u2
        out["psi"], out["psi_dot"] = np.full(n, self.psi[0]), np.zeros(n)
        out["theta"], out["theta_dot"] = th, thd
        if self.contact is None:  # paper profile: the sensor only rotates
            out["p"] = np.tile(self.a, (n, 1))
            return out
        rz = _rz(np.array(self.psi[0]))
        r = self.r_contact
        rot, rot1, rot2 = _pitch_roll(th, thd, thdd, out["phi"], out["phi_dot"], phi_ddot)
        out["p"] = self.contact - np.einsum("ij,njk,k->ni", rz, rot, r)
        out["v"] = -np.einsum("ij,njk,k->ni", rz, rot1, r)
        out["a"] = -np.einsum("ij,njk,k->ni", rz, rot2, r)
        return out


    def _push_through_toe_off(self, tl: np.ndarray, T: float, out: dict[str, np.ndarray]) -> None:
        """Physical swing: the push-off's rotation and the sensor's motion go on through toe-off.

        Pitch: :class:`~footzoo.sim.profiles.FootPitch` from toe-off to heel strike. Position: the
        sensor leaves with its velocity ``v0`` and acceleration ``a0`` at toe-off, which fade over
        the swing: ``v0 T f(x) + a0 T² g(x)`` (``x = τ/T``) is added to the path, with the quintic
        Hermite functions ``f`` (slope 1 at 0) and ``g`` (curvature 1 at 0) that vanish with their
        first two derivatives at heel strike, so position, velocity and acceleration are
        continuous at both ends.
        """
        out["theta"], out["theta_dot"], _ = self.foot_pitch.pitch(self.foot_pitch.ps + tl)
        x = (tl / T)[:, None]
        f, g = _fading(x)
        out["p"] = out["p"] + T * f[0] * self.v0 + T**2 * g[0] * self.a0
        out["v"] = out["v"] + f[1] * self.v0 + T * g[1] * self.a0
        out["a"] = out["a"] + f[2] / T * self.v0 + g[2] * self.a0

    def _land_on_heel(self, tl: np.ndarray, T: float, out: dict[str, np.ndarray]) -> None:
        """Physical swing: the sensor arrives with the velocity ``v1`` and acceleration ``a1`` of the rotation about
        the heel at heel strike (the roll, and the pitch's angular deceleration, go on through it).

        The mirror image of :meth:`_push_through_toe_off`: ``−T f(1 − x) v1 + T² g(1 − x) a1`` is added to the
        path, which vanishes with its first two derivatives at toe-off and has slope ``v1`` and curvature ``a1``
        at heel strike.
        """
        x = (1.0 - tl / T)[:, None]
        f, g = _fading(x)
        out["p"] = out["p"] - T * f[0] * self.v1 + T**2 * g[0] * self.a1
        out["v"] = out["v"] + f[1] * self.v1 - T * g[1] * self.a1
        out["a"] = out["a"] - f[2] / T * self.v1 + g[2] * self.a1


def flexion_angle(t: np.ndarray, duration: float, amplitude: float, cycles: int):
    """Slow dorsi-/plantar-flexions: ``θ = A sin³(2π n t/T)`` with rate and acceleration, zero at both ends."""
    phi = 2 * np.pi * cycles * np.asarray(t, dtype=float) / duration
    w = 2 * np.pi * cycles / duration
    s, c = np.sin(phi), np.cos(phi)
    return amplitude * s**3, amplitude * 3 * s**2 * c * w, amplitude * (6 * s * c**2 - 3 * s**3) * w**2


def calibration_timeline(
    geometry: FootGeometry,
    heading: float = 0.0,
    stand: float = 3.0,
    cycles: int = 3,
    period: float = 2.0,
    amplitude: float = float(np.radians(20.0)),
    ankle: np.ndarray | None = None,
) -> GaitTimeline:
    """Huang et al.'s calibration trial: standing still, then slow flexions about the ankle, standing again.

    The foot pitches about its own y axis through the ankle (``ankle``: vector
    from the sensor to the ankle in the foot frame, m).
    """
    ankle = np.array([-0.08, 0.0, -0.02]) if ankle is None else np.asarray(ankle, float)
    tl = GaitTimeline.__new__(GaitTimeline)
    tl.footsteps, tl.strides, tl.geometry, tl.profile = [], [], geometry, "physical"
    psi = float(heading)
    origin = np.zeros(3)
    pivot = origin + _rz(np.array(psi)) @ ankle
    flex_t0 = stand
    flex_t1 = stand + cycles * period
    tl.segments = [
        Segment(0.0, stand, "still", True, (psi, psi), (0.0, 0.0), a=origin),
        Segment(flex_t0, flex_t1, "flex", False, (psi, psi), (amplitude, 0.0), contact=pivot, r_contact=ankle,
                a=origin, cycles=cycles),
        Segment(flex_t1, flex_t1 + stand, "still", True, (psi, psi), (0.0, 0.0), a=origin),
    ]
    tl.steps = []
    tl.t_end = tl.segments[-1].t1
    tl._starts = np.array([seg.t0 for seg in tl.segments])
    tl.phases = {"still": (0.0, stand), "flex": (flex_t0, flex_t1)}
    return tl


class GaitTimeline:
    """The whole walk: standing, strides between footsteps, standing.

    Parameters
    ----------
    footsteps : list of Footstep
        Where the foot is flat, in order (N + 1 footsteps make N strides).
    strides : list of StrideSpec
        One per stride.
    geometry : FootGeometry
        Contact points and sensor mounting.
    profile : {"paper", "physical"}
        See the module docstring.
    stand_start, stand_end : float
        Standing still before the first and after the last stride (s).
    """

    def __init__(
        self,
        footsteps: list[Footstep],
        strides: list[StrideSpec],
        geometry: FootGeometry,
        profile: str = "paper",
        stand_start: float = 2.0,
        stand_end: float = 1.0,
    ):
        if profile not in ("paper", "physical"):
            raise ValueError(f"profile must be 'paper' or 'physical', got {profile!r}")
        if len(strides) != len(footsteps) - 1:
            raise ValueError(f"{len(footsteps)} footsteps need {len(footsteps) - 1} stride specs, got {len(strides)}")
        self.footsteps, self.strides, self.geometry, self.profile = footsteps, strides, geometry, profile
        self.segments: list[Segment] = []
        self.steps: list[dict[str, float]] = []
        self._build(stand_start, stand_end)
        self.t_end = self.segments[-1].t1
        self._starts = np.array([s.t0 for s in self.segments])

    def foot_yaw(self, step: Footstep) -> float:
        """Yaw of the foot (rad) while flat at ``step``: heading + side · FPA."""
        return float(step.heading + self.geometry.side * step.fpa)

    def _build(self, stand_start: float, stand_end: float) -> None:
        geo, physical = self.geometry, self.profile == "physical"
        t = 0.0
        fs = self.footsteps
        # unwrapped, so that a turn through ±π is not made the long way round
        yaws = np.unwrap([self.foot_yaw(f) for f in fs])
        psi0 = float(yaws[0])
        seg = self.segments
        seg.append(Segment(t, t + stand_start, "still", True, (psi0, psi0), (0.0, 0.0), a=np.asarray(fs[0].pos, float)))
        t += stand_start
        for i, spec in enumerate(self.strides):
            ph = spec.phases()
            a_step, b_step = fs[i], fs[i + 1]
            psi_a, psi_b = float(yaws[i]), float(yaws[i + 1])
            pa, pb = np.asarray(a_step.pos, float), np.asarray(b_step.pos, float)
            rz_a, rz_b = _rz(np.array(psi_a)), _rz(np.array(psi_b))
            toe_a = pa + rz_a @ geo.toe
            heel_b = pb + rz_b @ geo.heel
            start = t
            # pre-swing: rotate about the toe, 0 -> -θ_ps (physical: still rotating fast at toe-off)
            pitch = FootPitch(ph["ps"], ph["swing"], PS_ANGLE, IC_ANGLE, PUSH_RISE * ph["ps"], PUSH_TURN * ph["ps"],
                              SWING_DECLINE * ph["swing"]) if physical else None
            ps = Segment(t, t + ph["ps"], "ps", not physical, (psi_a, psi_a), (0.0, -PS_ANGLE),
                         contact=toe_a if physical else None, r_contact=geo.toe, a=pa, smooth=physical,
                         foot_pitch=pitch)
            t += ph["ps"]
            # initial contact of the next stance: rotate about the heel, θ_ic -> 0
            # (physical: the foot lands rolling, :data:`HEEL_ROLL`)
            ic_t0 = t + ph["swing"]
            roll = heel_strike_roll(spec.cycle, ph["swing"], ph["ic"], geo.side) if physical else None
            ic = Segment(ic_t0, ic_t0 + ph["ic"], "ic", not physical, (psi_b, psi_b), (IC_ANGLE, 0.0),
                         contact=heel_b if physical else None, r_contact=geo.heel, a=pb, smooth=physical,
                         roll=roll, t_contact=ic_t0)
            at_to = ps.evaluate(np.array([ps.t1]))
            at_ic = ic.evaluate(np.array([ic.t0]))
            a_sw = at_to["p"][0]
            b_sw = at_ic["p"][0]
            sw = Segment(t, t + ph["swing"], "swing", False, (psi_a, psi_b), (-PS_ANGLE, IC_ANGLE), a=a_sw, b=b_sw,
                         clearance=spec.clearance, smooth=False,
                         swing=GaussianSwing(ph["swing"]), foot_pitch=pitch,
                         v0=at_to["v"][0] if physical else None, a0=at_to["a"][0] if physical else None,
                         roll=roll, t_contact=ic_t0,
                         v1=at_ic["v"][0] if physical else None, a1=at_ic["a"][0] if physical else None)
            t = ic.t1
            ff = Segment(t, t + ph["ff"], "still", True, (psi_b, psi_b), (0.0, 0.0), a=pb)
            t += ph["ff"]
            seg.extend([ps, sw, ic, ff])
            d = pb - pa
            self.steps.append({
                "start": start, "end": ff.t0, "stride_length": float(np.hypot(d[0], d[1])),
                "heading": float(np.arctan2(d[1], d[0])), "fpa": float(b_step.fpa), "foot_yaw": psi_b,
                "swing_start": sw.t0, "swing_end": sw.t1,
            })
        psi_n = float(yaws[-1])
        end = np.asarray(fs[-1].pos, float)
        seg.append(Segment(t, t + stand_end, "still", True, (psi_n, psi_n), (0.0, 0.0), a=end))

    def evaluate(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Exact state at times ``t`` (s): ``p, v, a`` (NED), ``q`` (body->NED), ``w`` (body rate, rad/s), ``still``."""
        t = np.asarray(t, dtype=float)
        idx = np.clip(np.searchsorted(self._starts, t, side="right") - 1, 0, len(self.segments) - 1)
        n = t.shape[0]
        out = {"p": np.zeros((n, 3)), "v": np.zeros((n, 3)), "a": np.zeros((n, 3)),
               "psi": np.zeros(n), "psi_dot": np.zeros(n), "theta": np.zeros(n), "theta_dot": np.zeros(n),
               "phi": np.zeros(n), "phi_dot": np.zeros(n), "still": np.zeros(n, bool)}
        # group the samples by segment in one sort (a mask per segment costs N × segments: hours for a
        # one-hour walk evaluated at sub-sample times)
        order = np.argsort(idx, kind="stable")
        segs, first = np.unique(idx[order], return_index=True)
        bounds = np.append(first, n)
        for j, a, b in zip(segs, bounds[:-1], bounds[1:], strict=True):
            m = order[a:b]
            res = self.segments[j].evaluate(t[m])
            for k, v in res.items():
                out[k][m] = v
            out["still"][m] = self.segments[j].still
        q_foot = quat_from_euler(out["phi"], out["theta"], out["psi"])  # Rz(ψ) Ry(θ) Rx(φ)
        q_mount = self.geometry.mount_quat()
        out["q"] = quat_mul(q_foot, np.broadcast_to(q_mount, q_foot.shape))
        # body rate: ω_foot = Rx(φ)^T (Ry(θ)^T [0, 0, ψ̇] + [0, θ̇, 0]) + [φ̇, 0, 0]; ω_body = R_mount^T ω_foot
        w_pitch = np.einsum("nji,j->ni", _ry(out["theta"]), np.array([0.0, 0.0, 1.0])) * out["psi_dot"][:, None]
        w_pitch[:, 1] += out["theta_dot"]
        w_foot = np.einsum("nji,nj->ni", _rx(out["phi"]), w_pitch)
        w_foot[:, 0] += out["phi_dot"]

        out["w"] = w_foot @ quat_to_matrix(q_mount)
        return out
