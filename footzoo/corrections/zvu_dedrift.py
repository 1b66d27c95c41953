"""Zero-velocity update with linear velocity dedrift (Yun et al. 2012, Sec. II-B)."""

from __future__ import annotations

import numpy as np

from ..filters.strapdown import integrate_position
from ..plugin import VelocityCorrection
from ..registry import register


def swing_segments(stance: np.ndarray) -> list[tuple[int, int]]:
    """``(first, stop)`` sample ranges of each swing: ``stance[first:stop]`` is all False.

    Only swings with a stance sample before them are returned; ``stop == N`` marks
    a swing still open at the end of the recording.
    """
    s = np.asarray(stance, dtype=bool)
    edges = np.flatnonzero(s[1:] != s[:-1]) + 1
    bounds = np.concatenate([[0], edges, [s.shape[0]]])
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if not s[a] and a > 0]


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
    n = t.shape[0]
    vel = np.zeros((n, 3))
    dt = np.empty(n)
    dt[1:] = np.diff(t)
    dt[0] = 0.0
    biases = []
    for i0, stop in swing_segments(stance):
        end = min(stop + 1, n)  # include the first stance sample, where v(T) is known to be 0
        v = np.cumsum(acc_nav[i0:end] * dt[i0:end, None], axis=0)
        if stop < n:
            elapsed = t[i0:end] - t[i0 - 1]
            eps = v[-1] / elapsed[-1]
            v = v - eps[None, :] * elapsed[:, None]
            biases.append(eps)
        vel[i0:stop] = v[: stop - i0]
    pos = integrate_position(vel, dt)
    return vel, pos, np.array(biases).reshape(-1, 3)


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
    units: dict[str, str] = {}

    def __init__(self) -> None:
        pass

    def apply(self, t: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> ZVUDedrift:
        """Correct velocity and position over a recording (see :func:`zvu_dedrift`)."""
        self.vel_, self.pos_, self.bias_ = zvu_dedrift(t, acc_nav, stance)
        return self
