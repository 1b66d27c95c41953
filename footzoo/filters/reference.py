"""The reference implementation of the Kalman engine: strapdown INS + filterpy's ``KalmanFilter``, in Python.

Readable and slow: numpy for the mechanisation, :class:`~footzoo.filters.eskf.ErrorStateFilter`
(filterpy) for the covariance, and every correction's measurement model called through the same
functions the compiled loop (:mod:`footzoo.filters.forward`) calls. A test keeps the two equal.
Each update's filterpy quantities (``z``, ``H``, ``R``, the innovation ``y``, its covariance
``S``, the gain ``K`` and the error ``dx``) are kept in :attr:`ReferenceState.updates` when it is
a list (``state.updates = []`` before :meth:`ReferenceEngine.advance`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ..core.conventions import quat_from_rotvec, quat_mul, quat_to_matrix
from .eskf import ErrorStateFilter, Layout, transition
from .implementation import TRAJECTORY, Implementation, RowCountError, model_fault
from .measurement import BA, BG, MeasurementModel, P, Q, V, calling, row_fault, row_problem
from .process_noise import velocity_variance
from .recorders import ROW_KEYS, SAMPLE_KEYS, columns, packed, record
from .smoothing import Smoothing
from .structures import Record


class ModelFault(Exception):
    """Model ``j`` broke its contract at sample ``k``: a row count ``rows`` it did not declare, or ``error``."""

    def __init__(self, j: int, rows: int, k: int, error: BaseException | None = None):
        super().__init__(j, rows, k, error)
        self.j, self.rows, self.k, self.error = j, rows, k, error


class Update(NamedTuple):
    """One update of the reference engine, as filterpy saw it: sample ``k`` (in the whole recording), the
    stacked ``z`` (m,), ``H`` (m, n), ``R`` (m,), innovation ``y`` (m,), its covariance ``S`` (m, m), the gain
    ``K`` (n, m) and the error ``dx`` (n,) fed back."""

    k: int
    z: np.ndarray
    H: np.ndarray
    R: np.ndarray
    y: np.ndarray
    S: np.ndarray
    K: np.ndarray
    dx: np.ndarray


@dataclass
class ReferenceState:
    """The reference engine's state between chunks: filterpy's filter, the models (their memory), the nominal
    state (16,), and the updates kept (a list to keep them, None not to)."""

    kf: ErrorStateFilter
    models: list[MeasurementModel]
    nav: np.ndarray
    updates: list[Update] | None = field(default=None)


class ReferenceEngine(Implementation):
    """The filterpy loop (module docstring)."""

    name = "reference"

    def start(self, nav0: np.ndarray) -> ReferenceState:
        s = self.setup
        models = [MeasurementModel(**{**m.__dict__, "mem": np.array(m.mem, dtype=float)}) for m in s.models]
        return ReferenceState(ErrorStateFilter(s.layout, s.p0, s.noise), models, np.array(nav0, dtype=float))

    def fork(self, state: ReferenceState) -> ReferenceState:
        return copy.deepcopy(state)

    def memories(self, state: ReferenceState) -> list[np.ndarray]:
        return [m.mem for m in state.models]

    def advance(self, state: ReferenceState, t, acc, gyr, stance, quat_ext, data, k0: int, covariance: bool,
                record_rows: bool) -> dict[str, np.ndarray]:
        n, s = len(t), self.setup
        rec = record(n, s.layout.n, sum(m.max_rows for m in state.models)) if record_rows else None
        try:
            out = Loop(s.layout, state, s.idx, s.gravity, data, k0, rec).run(t, acc, gyr, stance, quat_ext)
        except ModelFault as err:
            raise model_fault(s, err.j, err.rows, err.k, [err.error] if err.error else [],
                              "the reference Kalman loop") from err.error
        if rec is not None:
            per_sample, per_row = columns(rec, n, int(rec.first[-1] + rec.count[-1]))
            out.update(per_sample, **per_row)
        return out

    def run(self, t, acc, gyr, stance, q0, quat_ext, covariance: bool, smoothing: Smoothing) -> dict[str, Any]:
        state = self.start(self.initial_nav(q0, quat_ext))
        out = self.advance(state, t, acc, gyr, stance, quat_ext, [m.data for m in self.setup.models], 0, covariance,
                           bool(smoothing))
        if smoothing:
            for key in ("quat", "vel", "pos"):
                out[f"{key}_forward"] = out[key].copy()
            self.smooth({**out, "t": np.asarray(t, float)},
                        smoothing.ends(np.asarray(stance, bool), np.asarray(t, float), True), smoothing)
        for key in (*SAMPLE_KEYS, *ROW_KEYS):
            out.pop(key, None)
        out["diagnostics"] = self.diagnostics(state)
        return out


class Loop:
    """Strapdown mechanisation with error-state Kalman corrections (Nguyen & La 2016, eqs. 37–52), in Python.

    Attitude: with an ``att`` block, ``q_k = q_{k-1} ⊗ exp((ω_k − b̂_g) dt)`` (the exact form of eq. 37
    for a rate constant over the interval); otherwise ``quat_ext[k]``. Velocity and position:
    mid-interval rotation, trapezoidal position (eqs. 46–48). Every sample the covariance is predicted
    (eq. 44); the models' rows are stacked into one update, the error fed back (eqs. 49–52) and reset.
    ``record``: a smoother's :class:`~footzoo.filters.structures.Record`, filled as the compiled loop
    fills it (:meth:`record_update` gives filterpy's stacked update as the compiled loop's scalar rows).
    """

    def __init__(self, layout: Layout, state: ReferenceState, idx: list[np.ndarray], gravity: float,
                 data: list[np.ndarray | None] | None, k0: int, rec: Record | None):
        self.layout, self.state, self.idx, self.k0, self.rec = layout, state, idx, k0, rec
        self.g_n = np.array([0.0, 0.0, gravity])
        models = state.models
        self.data = data if data is not None else [m.data for m in models]
        self.m_max = sum(m.max_rows for m in models)
        # each model's functions as the engine calls them (compiled where they compile, else in Python)
        self.measures = [calling(m.measure, "measure") for m in models]
        self.feedbacks = [calling(m.feedback, "feedback") for m in models]
        self.afters = [calling(m.after, "after") for m in models]

    def run(self, t, acc, gyr, stance, quat_ext) -> dict[str, np.ndarray]:
        """Samples 1… from the state; the outputs of :meth:`Implementation.advance` (row 0: the incoming state)."""
        kf, nav, ins = self.state.kf, self.state.nav, self.layout.has("att")
        out = outputs(len(t), self.layout.n)
        store(out, 0, nav, np.zeros(3), kf.P)
        if self.rec is not None:
            self.rec.cov[0] = packed(kf.P)
        for k in range(1, len(t)):
            dt = t[k] - t[k - 1]
            w, f, c, f_n, a_n = propagate(nav, acc[k], gyr[k], quat_ext[k] if not ins else None, self.g_n, dt)
            F = transition(self.layout, c, f_n, dt)
            kf.predict(F, dt, velocity_variance(kf.noise, a_n, acc, k, dt))
            if self.rec is not None:
                self.record_transition(k, F, c, dt)
            self.correct(k, float(t[k]), w, f, bool(stance[k]), out)
            store(out, k, nav, a_n, kf.P)
            if self.rec is not None:
                self.rec.cov[k] = packed(kf.P)
        return out

    def correct(self, k: int, t_k: float, w: np.ndarray, f: np.ndarray, st: bool, out: dict[str, np.ndarray]) -> None:
        """Sample ``k``'s update with the models' stacked rows, its feedback and the models' ``after``."""
        kf, nav, models = self.state.kf, self.state.nav, self.state.models
        args = [(self.k0 + k, t_k, nav, w, f, st, ix, m.par, m.mem, row_of(d, k))
                for m, ix, d in zip(models, self.idx, self.data, strict=True)]
        z, H, R = self.measure(k, args)
        if len(z):
            if self.rec is not None:
                self.record_update(k, kf.P, z, H, R)
            dx = kf.update(z, H, np.diag(R))
            out["nis"][k], out["nis_rows"][k] = kf.nis, len(z)
            if self.state.updates is not None:
                self.state.updates.append(Update(self.k0 + k, z, H, R, kf.y.copy(), kf.S.copy(), kf.K.copy(), dx))
            feed_back(nav, dx, self.layout)
            for j, a in enumerate(args):
                call(j, self.k0 + k, self.feedbacks[j], *a, dx)
        for j, a in enumerate(args):
            call(j, self.k0 + k, self.afters[j], *a)

    def measure(self, k: int, args: list[tuple]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The models' rows of sample ``k``, stacked: ``z`` (m,), ``H`` (m, n), ``R`` (m,).

        Each model gets the buffers cut at the rows it declared, as in the compiled loop; a row count
        outside them is a :class:`ModelFault`.
        """
        z, H, R = np.zeros(self.m_max), np.zeros((self.m_max, self.layout.n)), np.zeros(self.m_max)
        m = 0
        for j, (model, a) in enumerate(zip(self.state.models, args, strict=True)):
            top = m + model.max_rows
            m_new = row_count(j, self.k0 + k, call(j, self.k0 + k, self.measures[j], *a, z[:top], H[:top], R[:top], m))
            if m_new < m or m_new > top:
                raise ModelFault(j, m_new - m, self.k0 + k)
            problem, row = row_problem(z, H, R, m, m_new)
            if problem:
                raise ModelFault(j, row_fault(problem, row - m), self.k0 + k)
            m = m_new
        return z[:m], H[:m], R[:m]

    def record_transition(self, k: int, F: np.ndarray, c: np.ndarray, dt: float) -> None:
        """Φ_k's blocks into the record (as :func:`footzoo.filters.recorders.record_transition`)."""
        rec, layout = self.rec, self.layout
        tr = rec.transitions
        tr.dt[k] = dt
        if layout.has("att"):
            tr.skew_dt[k] = F[layout["vel"], layout["att"]]
        tr.c_dt[k] = dt * c
        rec.first[k] = rec.first[k - 1] + rec.count[k - 1]
        rec.count[k] = 0

    def record_update(self, k: int, prior: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray) -> None:
        """The update of sample k as scalar rows (h, gain, ν / s, ν, s) from the ``prior`` covariance, into the record.

        filterpy updates with the stacked rows; one row at a time (R diagonal) gives the same estimate
        and covariance, and the rows the compiled loop records.
        """
        rec = self.rec
        rows = rec.rows
        Pa, dx = prior.copy(), np.zeros(prior.shape[0])
        for a in range(len(z)):
            u = Pa @ H[a]
            s = float(H[a] @ u + R[a])
            gain = u / s
            nu = float(z[a] - H[a] @ dx)
            dx += gain * nu
            Pa -= np.outer(gain, u)
            r = rec.first[k] + a
            rows.h[r], rows.gain[r], rows.scaled[r], rows.nu[r], rows.s[r] = H[a], gain, nu / s, nu, s
        rec.count[k] = len(z)


def call(j: int, k: int, fn, *args):
    """``fn(*args)``; an exception raised in it becomes a :class:`ModelFault` of model ``j`` at sample ``k``."""
    try:
        return fn(*args)
    except Exception as err:
        raise ModelFault(j, 0, k, err) from err


def row_count(j: int, k: int, got: Any) -> int:
    """What model ``j``'s ``measure`` returned at sample ``k`` as a row count; anything but a whole number is a
    :class:`ModelFault` (the compiled loop's signature refuses it when the function compiles)."""
    if isinstance(got, (int, np.integer)) and not isinstance(got, (bool, np.bool_)):
        return int(got)
    raise ModelFault(j, 0, k, RowCountError(
        f"returned {got!r} ({type(got).__name__}), not a row count: return m plus the number of rows it "
        "wrote (an int; m itself when it writes none)"))


def outputs(n: int, nx: int) -> dict[str, np.ndarray]:
    """The outputs of :meth:`Loop.run` for ``n`` samples of an ``nx``-state filter, zeroed."""
    out = {k: np.zeros((n, 3)) for k in ("vel", "pos", "acc_nav", "gyro_bias", "acc_bias")}
    out["quat"] = np.zeros((n, 4))
    out["P_diag"] = np.zeros((n, nx))
    out["nis"] = np.zeros(n)
    out["nis_rows"] = np.zeros(n, np.int64)
    return out


def propagate(nav: np.ndarray, acc_k: np.ndarray, gyr_k: np.ndarray, quat_ext_k: np.ndarray | None,
              g_n: np.ndarray, dt: float) -> tuple[np.ndarray, ...]:
    """The nominal state over one sample, in place (eqs. 37–40); returns ``w``, ``f``, ``C``, ``f^n``, ``a^n``.

    The attitude from the rate, or ``quat_ext_k`` when the filter carries none; the velocity and
    the position with the rotation at the middle of the interval.
    """
    w = gyr_k - nav[BG:BG + 3]
    f = acc_k - nav[BA:BA + 3]
    q_prev = nav[Q:Q + 4].copy()
    nav[Q:Q + 4] = quat_mul(q_prev, quat_from_rotvec(w * dt)) if quat_ext_k is None else quat_ext_k
    q = nav[Q:Q + 4]
    q_mid = q_prev + q if np.dot(q_prev, q) >= 0 else q - q_prev
    c = quat_to_matrix(q_mid / np.linalg.norm(q_mid))
    f_n = c @ f
    a_n = f_n + g_n
    v_prev = nav[V:V + 3].copy()
    nav[V:V + 3] = v_prev + a_n * dt
    nav[P:P + 3] = nav[P:P + 3] + 0.5 * (v_prev + nav[V:V + 3]) * dt
    return w, f, c, f_n, a_n


def row_of(d: np.ndarray | None, k: int) -> np.ndarray:
    """Sample ``k``'s row of a model's per-sample inputs (empty without any)."""
    return d[k] if d is not None and d.shape[1] else np.zeros(0)


def feed_back(nav: np.ndarray, dx: np.ndarray, layout: Layout) -> None:
    """The estimated error into the nominal state (eqs. 49–52): q ← exp(−δφ) ⊗ q, p ← p − δp, v ← v − δv, b ← b + δb."""
    if layout.has("att"):
        qn = quat_mul(quat_from_rotvec(-dx[layout["att"]]), nav[Q:Q + 4])
        nav[Q:Q + 4] = qn / np.linalg.norm(qn)
    nav[P:P + 3] -= dx[layout["pos"]]
    nav[V:V + 3] -= dx[layout["vel"]]
    if layout.has("gyro_bias"):
        nav[BG:BG + 3] += dx[layout["gyro_bias"]]
    if layout.has("acc_bias"):
        nav[BA:BA + 3] += dx[layout["acc_bias"]]


def store(out: dict[str, np.ndarray], k: int, nav: np.ndarray, a_n: np.ndarray, cov: np.ndarray) -> None:
    """Sample ``k``'s estimates into the outputs."""
    for key, at, width in zip(TRAJECTORY, (Q, V, P, BG, BA), (4, 3, 3, 3, 3), strict=True):
        out[key][k] = nav[at:at + width]
    out["acc_nav"][k] = a_n
    out["P_diag"][k] = np.diag(cov)
