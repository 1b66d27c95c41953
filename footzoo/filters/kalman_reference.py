"""Reference sample loop of the Kalman-filter pipelines: strapdown INS + filterpy's ``KalmanFilter``.

Readable and slow: numpy for the mechanisation, :class:`~footzoo.filters.eskf.ErrorStateFilter`
(filterpy) for the covariance, and every correction's measurement model called through the same
functions the compiled loop (:mod:`footzoo.filters.kalman_fast`) calls. A test keeps the two equal.
"""

from __future__ import annotations

import numpy as np

from ..core.conventions import quat_from_rotvec, quat_mul, quat_to_matrix
from .eskf import ErrorStateFilter, Layout, transition
from .measurement import BA, BG, MeasurementModel, P, Q, V, calling
from .smoother import packed


class ModelFault(Exception):
    """Model ``j`` broke its contract at sample ``k``: a row count ``rows`` it did not declare, or ``error``."""

    def __init__(self, j: int, rows: int, k: int, error: BaseException | None = None):
        super().__init__(j, rows, k, error)
        self.j, self.rows, self.k, self.error = j, rows, k, error


def _call(j: int, k: int, fn, *args):
    """``fn(*args)``; an exception raised in it becomes a :class:`ModelFault` of model ``j``."""
    try:
        return fn(*args)
    except Exception as err:
        raise ModelFault(j, 0, k, err) from err


def run_reference(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, stance: np.ndarray, quat_ext: np.ndarray | None,
                  layout: Layout, kf: ErrorStateFilter, models: list[MeasurementModel], idx: list[np.ndarray],
                  nav0: np.ndarray, gravity: float, data: list[np.ndarray] | None = None, k0: int = 0,
                  record: tuple | None = None) -> dict[str, np.ndarray]:
    """Strapdown mechanisation with error-state Kalman corrections (Nguyen & La 2016, eqs. 37–52).

    Attitude: with an ``att`` block, ``q_k = q_{k-1} ⊗ exp((ω_k − b̂_g) dt)`` (the exact form
    of eq. 37 for a rate constant over the interval); otherwise ``quat_ext[k]``. Velocity and
    position: mid-interval rotation, trapezoidal position (eqs. 46–48). Every sample the
    covariance is predicted (eq. 44); the models' rows are stacked into one update, the error
    fed back (eqs. 49–52) and reset.

    Parameters
    ----------
    t, acc, gyr, stance : arrays
        Time (s), specific force (m/s²), angular rate (rad/s), gait phase.
    quat_ext : (N, 4) ndarray or None
        External attitude (body → NED) when the filter carries none.
    layout, kf : Layout, ErrorStateFilter
        State blocks and the filter (initial covariance and process noise set).
    models : list of MeasurementModel
        The corrections' models, in stacking order (their ``mem`` is updated in place).
    idx : list of (5 + b,) int arrays
        Block offsets for each model (see :mod:`footzoo.filters.measurement`).
    nav0 : (16,) ndarray
        Nominal state at sample 0 (updated in place to the last sample's).
    gravity : float
        g (m/s²).
    data : list of (N, d) arrays, optional
        Each model's per-sample inputs for these samples (default: the models' ``data``).
    k0 : int
        Index of sample 0 in the whole recording (a stream's running count).
    record : tuple, optional
        A smoother's record (:func:`footzoo.filters.smoother.record_arrays`, a row per
        sample), filled as the compiled loop fills it (:func:`record_update` gives filterpy's stacked
        update as the compiled loop's scalar rows).

    Returns
    -------
    dict
        ``quat`` (N, 4), ``vel``, ``pos``, ``acc_nav`` (motion acceleration), ``gyro_bias``,
        ``acc_bias`` (N, 3), ``P_diag`` (N, n), ``nis`` (N, 2): each sample's normalised innovation
        squared ``νᵀ S⁻¹ ν`` (filterpy's ``y`` and ``S``) and its number of rows.
    """
    n = t.shape[0]
    ins = layout.has("att")
    g_n = np.array([0.0, 0.0, gravity])
    nav = nav0
    data = data if data is not None else [m.data for m in models]
    m_max = sum(m.max_rows for m in models)
    # each model's functions as the engine calls them (compiled where they compile, else in Python)
    measures = [calling(m.measure, "measure") for m in models]
    feedbacks, afters = [calling(m.feedback, "feedback") for m in models], [calling(m.after, "after") for m in models]
    out = _outputs(n, layout.n)
    _store(out, 0, nav, np.zeros(3), kf.P)
    if record is not None:
        record[0][0] = packed(kf.P)
    for k in range(1, n):
        dt = t[k] - t[k - 1]
        w, f, c, f_n, a_n = _propagate(nav, acc[k], gyr[k], quat_ext[k] if not ins else None, g_n, dt)
        F = transition(layout, c, f_n, dt)
        change = acc[k] - acc[k - 1]
        kf.predict(F, dt, float(a_n @ a_n), float(change @ change))
        if record is not None:
            record_transition(record, k, F, layout, c, dt)
        st = bool(stance[k])
        z, H, R = _measure(models, measures, idx, data, k, k0, float(t[k]), nav, w, f, st, m_max, layout.n)
        if len(z):
            if record is not None:
                record_update(record, k, kf.P, z, H, R)
            dx = kf.update(z, H, np.diag(R))
            out["nis"][k] = kf.nis, len(z)
            _feed_back(nav, dx, layout, ins)
            for j, (model, ix) in enumerate(zip(models, idx, strict=True)):
                _call(j, k0 + k, feedbacks[j], k0 + k, float(t[k]), nav, w, f, st, ix,
                      model.par, model.mem, _row(data[j], k), dx)
        for j, (model, ix) in enumerate(zip(models, idx, strict=True)):
            _call(j, k0 + k, afters[j], k0 + k, float(t[k]), nav, w, f, st, ix, model.par,
                  model.mem, _row(data[j], k))
        _store(out, k, nav, a_n, kf.P)
        if record is not None:
            record[0][k] = packed(kf.P)
    return out


def _outputs(n: int, nx: int) -> dict[str, np.ndarray]:
    """The outputs of :func:`run_reference` for ``n`` samples of an ``nx``-state filter, zeroed."""
    out = {k: np.zeros((n, 3)) for k in ("vel", "pos", "acc_nav", "gyro_bias", "acc_bias")}
    out["quat"] = np.zeros((n, 4))
    out["P_diag"] = np.zeros((n, nx))
    out["nis"] = np.zeros((n, 2))
    return out


def _propagate(nav: np.ndarray, acc_k: np.ndarray, gyr_k: np.ndarray, quat_ext_k: np.ndarray | None,
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


def _measure(models: list[MeasurementModel], measures: list, idx: list[np.ndarray], data: list[np.ndarray | None],
             k: int, k0: int, t_k: float, nav: np.ndarray, w: np.ndarray, f: np.ndarray, st: bool, m_max: int,
             n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The models' rows of sample ``k``, stacked: ``z`` (m,), ``H`` (m, n), ``R`` (m,).

    ``measures``: the models' ``measure`` as the engine calls it (:func:`~footzoo.filters.measurement.calling`).
    Each model gets the buffers cut at the rows it declared, as in the compiled loop; a row count
    outside them is a :class:`ModelFault`.
    """
    z, H, R = np.zeros(m_max), np.zeros((m_max, n)), np.zeros(m_max)
    m = 0
    for j, (model, ix, d) in enumerate(zip(models, idx, data, strict=True)):
        top = m + model.max_rows
        m_new = int(_call(j, k0 + k, measures[j], k0 + k, t_k, nav, w, f, st, ix, model.par,
                          model.mem, _row(d, k), z[:top], H[:top], R[:top], m))
        if m_new < m or m_new > top:
            raise ModelFault(j, m_new - m, k0 + k)
        m = m_new
    return z[:m], H[:m], R[:m]


def _row(d: np.ndarray | None, k: int) -> np.ndarray:
    """Sample ``k``'s row of a model's per-sample inputs (empty without any)."""
    return d[k] if d is not None and d.shape[1] else np.zeros(0)


def _feed_back(nav: np.ndarray, dx: np.ndarray, layout: Layout, ins: bool) -> None:
    """The estimated error into the nominal state (eqs. 49–52): q ← exp(−δφ) ⊗ q, p ← p − δp, v ← v − δv, b ← b + δb."""
    if ins:
        qn = quat_mul(quat_from_rotvec(-dx[layout["att"]]), nav[Q:Q + 4])
        nav[Q:Q + 4] = qn / np.linalg.norm(qn)
    nav[P:P + 3] -= dx[layout["pos"]]
    nav[V:V + 3] -= dx[layout["vel"]]
    if layout.has("gyro_bias"):
        nav[BG:BG + 3] += dx[layout["gyro_bias"]]
    if layout.has("acc_bias"):
        nav[BA:BA + 3] += dx[layout["acc_bias"]]


def record_transition(record: tuple, k: int, F: np.ndarray, layout: Layout, c: np.ndarray, dt: float) -> None:
    """Φ_k's blocks into a smoother's record (as :func:`footzoo.filters.smoother.record_transition`)."""
    phi, first, count = record[1], record[3], record[4]
    phi[k, 0] = dt
    if layout.has("att"):
        phi[k, 1:10] = F[layout["vel"], layout["att"]].ravel()
    phi[k, 10:19] = (dt * c).ravel()
    first[k] = first[k - 1] + count[k - 1]
    count[k] = 0


def record_update(record: tuple, k: int, prior: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray) -> None:
    """The update of sample k as scalar rows (h, gain, ν / s) from the ``prior`` covariance, into the record.

    filterpy updates with the stacked rows; one row at a time (R diagonal) gives the same estimate
    and covariance, and the rows the compiled loop records.
    """
    rows, first, count = record[2], record[3], record[4]
    n = prior.shape[0]
    Pa, dx = prior.copy(), np.zeros(n)
    for a in range(len(z)):
        u = Pa @ H[a]
        s = float(H[a] @ u + R[a])
        gain = u / s
        nu = float(z[a] - H[a] @ dx)
        dx += gain * nu
        Pa -= np.outer(gain, u)
        rows[first[k] + a] = np.concatenate([H[a], gain, [nu / s]])
    count[k] = len(z)


def _store(out: dict[str, np.ndarray], k: int, nav: np.ndarray, a_n: np.ndarray, cov: np.ndarray) -> None:
    out["quat"][k] = nav[Q:Q + 4]
    out["pos"][k] = nav[P:P + 3]
    out["vel"][k] = nav[V:V + 3]
    out["gyro_bias"][k] = nav[BG:BG + 3]
    out["acc_bias"][k] = nav[BA:BA + 3]
    out["acc_nav"][k] = a_n
    out["P_diag"][k] = np.diag(cov)
