"""Zero-velocity update with linear velocity dedrift (Yun et al. 2012, Sec. II-B)."""

from __future__ import annotations

import numpy as np

from ..core.context import RunContext
from ..filters.strapdown import Integrator, integrate_position, sample_intervals
from ..kernels.jit import njit
from ..plugins.base import VelocityCorrection, run_context
from ..plugins.incremental import Chunk, Latency, OverlapSave, after_stance, run_starts
from ..plugins.registry import register


def swing_segments(stance: np.ndarray) -> list[tuple[int, int]]:
    """``(first, stop)`` sample ranges of each swing: ``stance[first:stop]`` is all False.

    Only swings with a stance sample before them are returned; ``stop == N`` marks
    a swing still open at the end of the recording.
    """
    s = np.asarray(stance, dtype=bool)
    edges = np.flatnonzero(s[1:] != s[:-1]) + 1
    bounds = np.concatenate([[0], edges, [s.shape[0]]])
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if not s[a] and a > 0]


def dedrifted_velocity(t: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The velocity of :func:`zvu_dedrift` (m/s, (N, 3)) and the ε of each closed swing (m/s², (M, 3))."""
    t = np.ascontiguousarray(t, dtype=float)
    a = np.ascontiguousarray(acc_nav, dtype=float)
    s = np.ascontiguousarray(stance, dtype=np.bool_)
    vel = np.empty((t.shape[0], 3))
    bias = np.empty((int(np.count_nonzero(s[1:] & ~s[:-1])) + 1, 3))
    m = _dedrift_kernel(t, sample_intervals(t), a, s, vel, bias)
    return vel, bias[:m].copy()


def zvu_dedrift(t: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Velocity and position with Yun's zero-velocity update and linear dedrift.

    For each swing that starts after stance sample ``i0 - 1`` and ends at stance
    sample ``i1``: integrate ``v(t) = ∫ a_m dt`` from zero (eq. 9), estimate the
    constant bias ``ε = v(T)/T`` with ``T = t[i1] − t[i0-1]`` (eq. 10), and use
    ``v̂(t) = v(t) − ε (t − t[i0-1])``. In stance ``v̂ = 0`` and the position is held;
    position integrates ``v̂`` (trapezoidal). A swing still open at the end of the
    recording cannot be dedrifted and is integrated as measured.

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    acc_nav : (N, 3) ndarray
        Motion acceleration in NED (m/s²), gravity removed (eq. 6).
    stance : (N,) bool ndarray
        Gait phase with switches dated back.

    Returns
    -------
    vel : (N, 3) ndarray
        Corrected velocity (m/s).
    pos : (N, 3) ndarray
        Position (m), starting at 0.
    bias : (M, 3) ndarray
        ε of each closed swing (m/s²).
    """
    vel, bias = dedrifted_velocity(t, acc_nav, stance)
    return vel, integrate_position(vel, sample_intervals(np.asarray(t, dtype=float))), bias


@njit
def _dedrift_kernel(t: np.ndarray, dt: np.ndarray, a: np.ndarray, stance: np.ndarray, vel: np.ndarray,
                    bias: np.ndarray) -> int:
    """One pass: zero in stance, eqs. 9–10 over each swing; ``bias[:m]`` gets the ε of the m closed swings."""
    n = t.shape[0]
    m = 0
    k = 0
    while k < n:
        if stance[k] or k == 0:  # stance, or a swing with no stance before it: not a swing of eq. 9
            if stance[k]:
                vel[k, 0], vel[k, 1], vel[k, 2] = 0.0, 0.0, 0.0
                k += 1
                continue
            while k < n and not stance[k]:
                vel[k, 0], vel[k, 1], vel[k, 2] = 0.0, 0.0, 0.0
                k += 1
            continue
        i0 = k
        stop = i0
        while stop < n and not stance[stop]:
            stop += 1
        vx, vy, vz = 0.0, 0.0, 0.0  # eq. 9: v(t) = ∫ a_m dt from the last stance sample
        for j in range(i0, stop):
            vx += a[j, 0] * dt[j]
            vy += a[j, 1] * dt[j]
            vz += a[j, 2] * dt[j]
            vel[j, 0], vel[j, 1], vel[j, 2] = vx, vy, vz
        if stop < n:  # closed by stance sample `stop`, where the true velocity is 0
            vx += a[stop, 0] * dt[stop]
            vy += a[stop, 1] * dt[stop]
            vz += a[stop, 2] * dt[stop]
            span = t[stop] - t[i0 - 1]
            ex, ey, ez = vx / span, vy / span, vz / span  # eq. 10: ε = v(T) / T
            for j in range(i0, stop):
                e = t[j] - t[i0 - 1]
                vel[j, 0] -= ex * e
                vel[j, 1] -= ey * e
                vel[j, 2] -= ez * e
            bias[m, 0], bias[m, 1], bias[m, 2] = ex, ey, ez
            m += 1
        k = stop
    return m


@register
class ZVUDedrift(VelocityCorrection):
    """Zero-velocity update with linear dedrift of each swing's velocity.

    Yun et al. 2012, IEEE TIM 61(7), Sec. II-B, eqs. 5–10: the motion
    acceleration is integrated over each swing, the drift ``ε = v(T)/T`` removed
    linearly, the velocity set to zero in stance and the corrected velocity
    integrated to position (held during stance). No parameters. This is also
    the ZVU of Nguyen & La 2016, eqs. 16–22 (the bias ``a_mbe = v_m(T_i)/δT_i``
    subtracted from the swing's acceleration), used by their INS/ZVU systems.

    Attributes
    ----------
    vel_ : (N, 3) ndarray
        Velocity in NED (m/s).
    pos_ : (N, 3) ndarray
        Position in NED (m).
    bias_ : (M, 3) ndarray
        Estimated acceleration drift ε of each swing (m/s²).
    """

    name = "zvu_dedrift"
    paper = "Yun et al. 2012, IEEE TIM 61(7), Sec. II-B, eqs. 5-10"

    def __init__(self) -> None:
        pass

    def apply(self, t: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray,
              ctx: RunContext | None = None) -> ZVUDedrift:
        """Correct velocity and position over a recording (see :func:`zvu_dedrift`)."""
        self.begin(run_context(ctx, t))
        self.vel_, self.pos_, self.bias_ = zvu_dedrift(t, acc_nav, stance)
        return self

    # ------------------------------------------------------------------ live
    def latency(self, ctx: RunContext) -> Latency:
        """A swing is corrected once the stance that ends it has been seen."""
        return Latency(until=("the end of the swing",))

    def begin(self, ctx: RunContext) -> ZVUDedrift:
        """Fresh state: the open swing's samples, and the position integration."""
        super().begin(ctx)

        def ready(inp: Chunk, start: int) -> int:
            s = inp["stance"]
            return start + (s.size if s[-1] else int(run_starts(s)[-1]))  # up to the open swing

        self._velocity = OverlapSave(lambda t, acc_nav, stance: {"vel": dedrifted_velocity(t, acc_nav, stance)[0],
                                                                 "t": t},
                                     lookahead=ready,
                                     restart=lambda out, inp, start, final: after_stance(inp["stance"], start, final))
        self._integrator = Integrator()
        return self

    def step(self, t: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> Chunk:
        """Velocity and position of the samples up to the last stance sample."""
        return self._positions(self._velocity.step(t=np.asarray(t, float), acc_nav=np.asarray(acc_nav, float),
                                                   stance=np.asarray(stance, bool)))

    def finish(self) -> Chunk:
        """The open swing at the end, integrated as measured (it cannot be dedrifted)."""
        return self._positions(self._velocity.finish())

    def provisional(self) -> Chunk:
        """The open swing's velocity and position as measured so far (not dedrifted yet)."""
        out = self._velocity.provisional()
        if not out:
            return {}
        live = Integrator()
        live.t_prev, live.v_last, live.p_last = self._integrator.t_prev, self._integrator.v_last, \
            self._integrator.p_last
        return {"vel": out["vel"], "pos": live.position(out["vel"], out["t"])}

    def _positions(self, out: Chunk) -> Chunk:
        if not out:
            return {}
        return {"vel": out["vel"], "pos": self._integrator.position(out["vel"], out["t"])}
