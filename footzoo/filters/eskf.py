"""The one error-state Kalman filter of footzoo, on filterpy's ``KalmanFilter``.

Error state (the enabled blocks, in this order; Nguyen & La 2016, eq. 31):
``att`` δφ (rad, NED), ``gyro_bias`` δω (rad/s, body), ``pos`` δp (m), ``vel``
δv (m/s), ``acc_bias`` δa (m/s², body), then any extra states a correction adds
(e.g. distance-sensor calibration, Duong & Suh 2015).

Conventions: ``δφ, δp, δv`` are estimate − truth; the attitude error is in NED,
``C_est = (I + [δφ×]) C_true``; ``δω, δa`` are the corrections to add to the bias
estimates. The first-order error dynamics are then (Nguyen & La eq. 33, read
with these signs)::

    δφ' = C δω,   δp' = δv,   δv' = −[f^n×] δφ + C δa,   biases constant

with ``f^n = C (f − b̂_a)`` the bias-corrected specific force in NED (eqs. 34–35).
After every measurement update the error is fed back (eqs. 49–52:
``q ← exp(−δφ) ⊗ q``, ``p ← p − δp``, ``v ← v − δv``, ``b̂ ← b̂ + δb``) and the error
state reset to zero — the closed-loop form. (The paper's Algorithm 2 keeps
propagating δX after the feedback, which would apply each correction again at
every later sample; footzoo resets it, as indirect-feedback filters do.)
The covariance update is filterpy's Joseph form (eq. 45).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass
class Layout:
    """Error-state blocks and their slices."""

    blocks: list[tuple[str, int]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.slices: dict[str, slice] = {}
        i = 0
        for name, size in self.blocks:
            if name in self.slices:
                raise ValueError(f"error-state block {name!r} declared twice")
            self.slices[name] = slice(i, i + size)
            i += size
        self.n = i

    def has(self, name: str) -> bool:
        """Whether the block is part of the state."""
        return name in self.slices

    def __getitem__(self, name: str) -> slice:
        return self.slices[name]

    def names(self) -> list[str]:
        """Block names in order."""
        return [b[0] for b in self.blocks]


def skew(v: np.ndarray) -> np.ndarray:
    """``[v×]``."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def transition(layout: Layout, c: np.ndarray, f_n: np.ndarray, dt: float) -> np.ndarray:
    """Φ = I + A dt for the enabled blocks (Nguyen & La eq. 33)."""
    F = np.eye(layout.n)
    i3 = np.eye(3)
    has = layout.has
    if has("att") and has("gyro_bias"):
        F[layout["att"], layout["gyro_bias"]] = dt * c
    F[layout["pos"], layout["vel"]] = dt * i3
    if has("att"):
        F[layout["vel"], layout["att"]] = -dt * skew(f_n)
    if has("acc_bias"):
        F[layout["vel"], layout["acc_bias"]] = dt * c
    return F


class ErrorStateFilter:
    """filterpy ``KalmanFilter`` holding the error state, with predict/update/take-and-reset.

    Parameters
    ----------
    layout : Layout
        State blocks.
    p0 : (n,) array
        Initial variances.
    noise : Noise
        The process noise (:mod:`footzoo.filters.process_noise`): ``Q = diag(q) dt`` plus the
        velocity variance the caller computes for the sample (:meth:`predict`).

    Attributes
    ----------
    y, S, K : ndarray
        filterpy's innovation (m,), its covariance (m, m) and the gain (n, m) of the last update.
    nis : float
        The last update's normalised innovation squared ``yᵀ S⁻¹ y``.
    """

    def __init__(self, layout: Layout, p0: np.ndarray, noise: Any):
        from filterpy.kalman import KalmanFilter  # imported here: the compiled engine does not need it

        self.layout = layout
        self.kf = KalmanFilter(dim_x=layout.n, dim_z=1)
        self.kf.P = np.diag(np.asarray(p0, dtype=float))
        self.noise = noise
        self.nis = 0.0

    def predict(self, F: np.ndarray, dt: float, velocity_variance: float = 0.0) -> None:
        """``P ← Φ P Φᵀ + Q`` (eq. 44), ``Q = diag(q) dt`` plus ``velocity_variance`` ((m/s)²) on each velocity
        axis (:func:`footzoo.filters.process_noise.velocity_variance`); the error state stays zero between
        updates."""
        q = np.asarray(self.noise.q, dtype=float) * dt
        q[self.layout["vel"]] += velocity_variance
        self.kf.predict(F=F, Q=np.diag(q))

    def update(self, z: np.ndarray, H: np.ndarray, R: np.ndarray) -> np.ndarray:
        """Measurement update (eqs. 40, 43, 45) and return of the error, which is then reset."""
        self.kf.dim_z = len(z)
        self.kf.update(np.asarray(z, dtype=float).reshape(-1, 1), R=R, H=H)
        dx = self.kf.x[:, 0].copy()
        self.kf.x[:] = 0.0
        y = self.kf.y[:, 0]
        self.nis = float(y @ np.linalg.solve(self.kf.S, y))  # the normalised innovation squared νᵀ S⁻¹ ν
        return dx

    @property
    def P(self) -> np.ndarray:
        """Current covariance."""
        return self.kf.P

    @property
    def y(self) -> np.ndarray:
        """The last update's innovation (m,)."""
        return self.kf.y[:, 0]

    @property
    def S(self) -> np.ndarray:
        """The last update's innovation covariance (m, m)."""
        return self.kf.S

    @property
    def K(self) -> np.ndarray:
        """The last update's gain (n, m)."""
        return self.kf.K
