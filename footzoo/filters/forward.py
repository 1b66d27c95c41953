"""The compiled forward loop of the error-state Kalman filter: one loop, whatever a smoother keeps of it.

The same equations as the reference engine (:mod:`footzoo.filters.reference`, on filterpy's
``KalmanFilter``), with every correction's measurement model called through its compiled
functions (the contract is in :mod:`footzoo.filters.measurement`); this module knows no correction
and no smoother. For each sample :func:`forward_span` runs the named steps below (each inlined by
numba into the loop): :func:`propagate` (the nominal state, Nguyen & La eqs. 37–40),
:func:`predict_covariance` (eq. 44, with :func:`footzoo.filters.process_noise.add_process_noise`),
:func:`measure` (the corrections' rows, stacked), :func:`correct` (eq. 45 one row at a time with
:func:`update_row`, then the feedback of eqs. 49–52) and :func:`store`.

What a smoother keeps of the pass is the ``recorder`` argument's business: the loop calls the
hooks of :mod:`footzoo.filters.recorders` (``begin``, ``before``, ``transition``, ``row``,
``updated``, ``end``), each chosen by the recorder's type when the loop is compiled (``None``:
nothing kept; a :class:`~footzoo.filters.structures.Record`, a
:class:`~footzoo.filters.structures.SegmentRecord`, a
:class:`~footzoo.filters.structures.CheckpointRecord`): one compiled variant of the loop per kind
of recorder, each without the others' code. ``out`` ``None`` writes no output (a smoother running
a piece again).

The covariance prediction works in place on the nonzero blocks of Φ = I + Δ (the rows of Φ P,
then the columns of the rows that move, mirrored: P stays exactly symmetric); the update is
filterpy's, in the Joseph form, taking the rows of H one at a time (R is diagonal) and touching
only their nonzero entries. Every array the models' functions get is a view that owns no
reference (:func:`footzoo.kernels.views.unowned`), so a call costs no reference counting. The loop
allocates nothing: its buffers (:func:`footzoo.filters.recorders.workspace`) and outputs are the
caller's. A test keeps both engines equal to 1e-9 relative.

Never trusting a model: each ``measure`` gets ``z``, ``H`` and ``R`` cut at the rows its model
declared (``max_rows``), and a plug-in's functions are compiled with bounds checks
(:mod:`footzoo.kernels.functions`), so no write lands outside them; a ``measure`` that returns a
row count outside ``[m, m + max_rows]`` stops the model, the count and the sample in the
workspace's :class:`~footzoo.filters.structures.Fault` (the engine raises it as the plug-in's
:class:`~footzoo.core.errors.PluginError`).
"""

from __future__ import annotations

from ..kernels.dispatch import by_type
from ..kernels.jit import njit
from ..kernels.views import unowned
from .measurement import BA, BG, P, Q, V, row_fault, row_problem
from .process_noise import add_process_noise, unowned_noise
from .recorders import before, begin, end, row, transition, updated, views
from .smoother import feed_back_attitude, unowned_trajectory
from .strapdown import mid_rotation, quat_product, rotvec_quat
from .structures import Fault, FilterState, ModelArrays, Outputs, Workspace


@njit
def run(signals, core, state, models, out, k0, work, recorder):
    """Run samples 1… of ``signals`` from ``state`` (updated in place); outputs into ``out``.

    ``signals`` (:class:`~footzoo.filters.structures.Signals`), ``core`` (:class:`~.structures.Core`),
    ``state`` (:class:`~.structures.FilterState`), ``models`` (:class:`~.structures.Models`), ``out``
    (:class:`~.structures.Outputs`), ``k0`` the index of sample 0 in the whole recording (a stream's
    running count), ``work`` (:class:`~.structures.Workspace`), ``recorder`` (module docstring). When a
    model's ``measure`` returns a row count it did not declare, ``work.fault`` says which, where and
    how many.
    """
    fault = work.fault
    fault.model[0], fault.rows[0], fault.sample[0] = -1, 0, 0
    forward_span(signals, core, state, models, output_views(out), k0, work, views(recorder), 0,
                 signals.t.shape[0] - 1)


def output_views(out):
    """The outputs with every array a view that owns no reference (``None``: none), for :func:`forward_span`'s
    argument (the loop writes them at every sample; :mod:`footzoo.filters.recorders` says why an argument)."""


def _output_views(out):
    return Outputs(unowned_trajectory(out.trajectory), unowned(out.acc_nav), unowned(out.p_diag), unowned(out.nis),
                   unowned(out.nis_rows))


def _no_outputs(out):
    return None


output_views = by_type(output_views, {type(None): _no_outputs, Outputs: _output_views}, inline=False)


@njit(refcounts=False)
def forward_span(signals, core, state, models, out, k0, work, rec, lo, hi):
    """Samples ``lo + 1 … hi`` from ``state`` (the state after sample ``lo``); the loop of the module docstring.

    ``out`` and ``rec``: the outputs and the recorder as :func:`output_views` and
    :func:`footzoo.filters.recorders.views` made them (from those the caller keeps), passed as
    arguments (:mod:`footzoo.filters.recorders` says why). Compiled without reference counting: nothing
    in the loop allocates (the caller owns every array), so taking an array out of a named tuple costs no
    call to numba's runtime.
    """
    # every array as a view that owns no reference (they are the caller's, alive during the whole call):
    # handing them to the models' functions and to the inlined steps costs no reference counting
    t, acc, gyr, stance, quat_ext = signals.t, signals.acc, signals.gyr, signals.stance, signals.quat_ext
    offs, gravity = core.offsets, core.gravity
    noise = unowned_noise(core.noise)
    st8 = FilterState(unowned(state.nav), unowned(state.P), unowned(state.mems))
    functions, arrays = models.functions, unowned_arrays(models.arrays)
    w = unowned_workspace(work)
    keep_p = False
    if out is not None:
        keep_p = out.p_diag.shape[0] == t.shape[0]
    w.z[:core.m_max], w.R[:core.m_max], w.H[:core.m_max] = 0.0, 0.0, 0.0
    n_moving = moving_rows(offs, st8.P.shape[0], w.moving, w.still)
    if out is not None:
        store(lo, st8.nav, w.a_n, st8.P, offs, out, keep_p, True, 0.0, 0)
    use_ext = core.use_ext
    begin(rec, lo, st8.P)
    for k in range(lo + 1, hi + 1):
        before(rec, k, stance, t, offs, use_ext, out, st8)
        dt = t[k] - t[k - 1]
        propagate(st8.nav, acc, gyr, quat_ext, k, use_ext, dt, gravity, w)
        predict_covariance(st8.P, offs, noise, acc, k, dt, w, n_moving, rec)
        st = stance[k]
        data_k = arrays.data[k]
        m = measure(functions.measures, arrays, k0 + k, t[k], st8, w, st, data_k)
        nis = 0.0
        if m > 0:
            nis = correct(st8, m, offs, use_ext, functions.feedbacks, arrays, k0 + k, t[k], w, st, data_k, rec, k)
            updated(rec, k)
        after(functions.afters, arrays, k0 + k, t[k], st8, w, st, data_k)
        if out is not None:
            store(k, st8.nav, w.a_n, st8.P, offs, out, keep_p, False, nis, m)
        end(rec, k, st8.P)


@njit(inline=True)
def unowned_arrays(a):
    """The models' arrays (:class:`~.structures.ModelArrays`) as views that own no reference."""
    return ModelArrays(unowned(a.idx), unowned(a.par), unowned(a.par_off), unowned(a.mem_off), unowned(a.data),
                       unowned(a.data_off), unowned(a.has_feedback), unowned(a.has_after), unowned(a.rows))


@njit(inline=True)
def unowned_workspace(w):
    """The loop's buffers (:class:`~.structures.Workspace`) as views that own no reference."""
    fault = Fault(unowned(w.fault.model), unowned(w.fault.rows), unowned(w.fault.sample))
    return Workspace(unowned(w.z), unowned(w.H), unowned(w.R), unowned(w.dx), unowned(w.w), unowned(w.f),
                     unowned(w.u), unowned(w.gain), unowned(w.g), unowned(w.nonzero), unowned(w.moving),
                     unowned(w.still), unowned(w.c), unowned(w.c_dt), unowned(w.skew_dt), unowned(w.a_n),
                     unowned(w.f_n), fault)


@njit(inline=True)
def moving_rows(offs, n, moving, still):
    """The rows of Φ − I that are not zero into ``moving``, the others into ``still``; returns their count.

    pos; vel with att or acc_bias; att with gyro_bias — in the order the in-place products need;
    the other rows and columns of P keep their values.
    """
    vel_moves = offs.att >= 0 or offs.acc_bias >= 0
    att_moves = offs.att >= 0 and offs.gyro_bias >= 0
    n_moving = 3 + (3 if vel_moves else 0) + (3 if att_moves else 0)
    for i in range(3):
        moving[i] = offs.pos + i
        if vel_moves:
            moving[3 + i] = offs.vel + i
        if att_moves:
            moving[n_moving - 3 + i] = offs.att + i
    e = 0
    for i in range(n):
        moves = False
        for e2 in range(n_moving):
            if moving[e2] == i:
                moves = True
        if not moves:
            still[e] = i
            e += 1
    return n_moving


@njit(inline=True)
def propagate(nav, acc, gyr, quat_ext, k, use_ext, dt, gravity, w):
    """The nominal state over sample ``k``, in place (Nguyen & La eqs. 37–40).

    Into the workspace ``w``: ``w``, ``f`` the bias-corrected rate and specific force; ``c`` the
    body → NED rotation at the middle of the interval; ``f_n`` the specific force in NED; ``a_n`` the
    motion acceleration.
    """
    rate, force, c, a_n, f_n = w.w, w.f, w.c, w.a_n, w.f_n
    for i in range(3):
        rate[i] = gyr[k, i] - nav[BG + i]
        force[i] = acc[k, i] - nav[BA + i]
    pw, px, py, pz = nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3]
    if use_ext:
        for i in range(4):
            nav[Q + i] = quat_ext[k, i]
    else:
        # q ⊗ exp(w dt), the exact form of Nguyen & La eq. 37
        dw, dx_, dy, dz = rotvec_quat(rate[0] * dt, rate[1] * dt, rate[2] * dt)
        nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3] = quat_product(pw, px, py, pz, dw, dx_, dy, dz)
    mid_rotation(pw, px, py, pz, nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3], c)
    for i in range(3):
        a_n[i] = c[i, 0] * force[0] + c[i, 1] * force[1] + c[i, 2] * force[2]
        f_n[i] = a_n[i]
    a_n[2] += gravity
    for i in range(3):
        v_old = nav[V + i]
        nav[V + i] = v_old + a_n[i] * dt
        nav[P + i] = nav[P + i] + 0.5 * (v_old + nav[V + i]) * dt


@njit(inline=True)
def predict_covariance(Pk, offs, noise, acc, k, dt, w, n_moving, rec):
    """``P ← Φ P Φᵀ + Q_k`` (eq. 44), Φ's blocks from the workspace's ``c`` and ``f_n`` (kept by ``rec``)."""
    c, c_dt, skew_dt, f_n = w.c, w.c_dt, w.skew_dt, w.f_n
    for i in range(3):
        for j in range(3):
            c_dt[i, j] = dt * c[i, j]
    skew_dt[0, 0], skew_dt[0, 1], skew_dt[0, 2] = 0.0, dt * f_n[2], -dt * f_n[1]
    skew_dt[1, 0], skew_dt[1, 1], skew_dt[1, 2] = -dt * f_n[2], 0.0, dt * f_n[0]
    skew_dt[2, 0], skew_dt[2, 1], skew_dt[2, 2] = dt * f_n[1], -dt * f_n[0], 0.0
    transition(rec, k, dt, skew_dt, c_dt)
    propagate_rows(Pk, offs, dt, skew_dt, c_dt)
    propagate_columns(Pk, offs, dt, skew_dt, c_dt, w.moving, w.still, n_moving)
    add_process_noise(Pk, offs.vel, noise, w.a_n, acc, k, dt)


@njit(inline=True)
def phi_block(offs, skew_dt, c_dt, which):
    """Block ``which`` (0, 1, 2) of Δ = Φ − I as (its row offset, its column offset, its 3×3 matrix).

    Δ[vel, att] = −[f^n×] dt, Δ[vel, acc_bias] = C dt, Δ[att, gyro_bias] = C dt (Nguyen & La eq. 33;
    Δ[pos, vel] = I dt is applied on its own).
    """
    if which == 0:
        return offs.vel, offs.att, skew_dt
    if which == 1:
        return offs.vel, offs.acc_bias, c_dt
    return offs.att, offs.gyro_bias, c_dt


@njit(inline=True)
def propagate_rows(Pk, offs, dt, skew_dt, c_dt):
    """``P ← Φ P`` in place (the first half of eq. 44), on the rows of Φ − I that are not zero.

    Rows in the order pos (reads vel), vel (reads att, acc_bias), att (reads gyro_bias).
    """
    n = Pk.shape[0]
    for i in range(3):
        for j in range(n):
            Pk[offs.pos + i, j] += dt * Pk[offs.vel + i, j]
    for blk in range(3):  # P[r0:r0+3, :] += B P[c0:c0+3, :] for the 3×3 blocks B of Δ
        r0, c0, bm = phi_block(offs, skew_dt, c_dt, blk)
        if r0 < 0 or c0 < 0:
            continue
        for i in range(3):
            b0, b1, b2 = bm[i, 0], bm[i, 1], bm[i, 2]
            for j in range(n):
                Pk[r0 + i, j] += b0 * Pk[c0, j] + b1 * Pk[c0 + 1, j] + b2 * Pk[c0 + 2, j]


@njit(inline=True)
def propagate_columns(Pk, offs, dt, skew_dt, c_dt, moving, still, n_moving):
    """``(Φ P) Φᵀ`` in place, columns in the order of :func:`propagate_rows`, on the moving rows.

    Φ P Φᵀ is symmetric: of its moving block only the entries (moving[e], moving[e2]) with e ≤ e2
    are computed (the columns of the block moving[b:b+3] on the rows moving[:b+3]), then mirrored,
    as are the other rows, which are those of Φ P.
    """
    n = Pk.shape[0]
    for e in range(3):
        i = moving[e]
        for j in range(3):
            Pk[i, offs.pos + j] += dt * Pk[i, offs.vel + j]
    for blk in range(3):  # P[i, r0:r0+3] += P[i, c0:c0+3] Bᵀ
        r0, c0, bm = phi_block(offs, skew_dt, c_dt, blk)
        if r0 < 0 or c0 < 0:
            continue
        for e in range(6 if blk < 2 else n_moving):
            i = moving[e]
            x0, x1, x2 = Pk[i, c0], Pk[i, c0 + 1], Pk[i, c0 + 2]
            for j in range(3):
                Pk[i, r0 + j] += x0 * bm[j, 0] + x1 * bm[j, 1] + x2 * bm[j, 2]
    for e in range(n_moving):
        i = moving[e]
        for e2 in range(n - n_moving):
            j = still[e2]
            Pk[j, i] = Pk[i, j]
        for e2 in range(e + 1, n_moving):
            j = moving[e2]
            Pk[j, i] = Pk[i, j]


@njit(inline=True)
def measure(measures, arrays, k, t_k, state, w, st, data_k):
    """The corrections' measurement rows of sample ``k`` (``data_k``: its row of inputs), stacked; returns their count.

    Each model gets ``z``, ``H`` and ``R`` cut at the rows it declared. A model whose ``measure``
    returns fewer rows than it was given or more than it declared, or writes a row no update can use
    (:func:`~footzoo.filters.measurement.row_problem`), is refused: the rows before it
    are kept, the first such fault is written to ``w.fault`` (the loop runs on, cheaper than a loop
    that can stop early; the engine then raises it).
    """
    a = arrays
    z, H, R, fault, mems = w.z, w.H, w.R, w.fault, state.mems
    m = 0
    for j in range(a.rows.shape[0]):  # the models' own: ``measures`` may have no-op functions after them
        top = m + a.rows[j]
        m_new = measures[j](k, t_k, state.nav, w.w, w.f, st, a.idx[j], a.par[a.par_off[j]:a.par_off[j + 1]],
                            mems[a.mem_off[j]:a.mem_off[j + 1]], data_k[a.data_off[j]:a.data_off[j + 1]], z[:top],
                            H[:top], R[:top], m)
        if m_new < m or m_new > top:  # refused; the first such fault is kept for the engine to raise
            if fault.model[0] < 0:
                fault.model[0], fault.rows[0], fault.sample[0] = j, m_new - m, k
            return m
        problem, row = row_problem(z, H, R, m, m_new)
        if problem:  # a row no update can use (R not positive, NaN): refused the same way
            if fault.model[0] < 0:
                fault.model[0], fault.rows[0], fault.sample[0] = j, row_fault(problem, row - m), k
            return m
        m = m_new
    return m


@njit(inline=True)
def correct(state, m, offs, use_ext, feedbacks, arrays, k, t_k, w, st, data_k, rec, sample):
    """The update with the ``m`` stacked rows, one at a time (eq. 45), and its feedback; returns the NIS.

    ``k``: the sample's index in the whole recording (the models'), ``sample``: in the chunk (``rec``'s).
    """
    Pk, dx, H, nonzero = state.P, w.dx, w.H, w.nonzero
    n = Pk.shape[0]
    nis = 0.0
    for i in range(n):
        dx[i] = 0.0
    for a in range(m):
        cnt, scaled, innov, s_ = update_row(Pk, w.z, H, w.R, a, dx, w.u, w.gain, w.g, nonzero)
        nis += innov * scaled
        row(rec, sample, H[a], w.gain, scaled, innov, s_)
        for e in range(cnt):
            H[a, nonzero[e]] = 0.0  # leave H all zero for the next sample
    for i in range(n):
        for j in range(i + 1, n):
            Pk[j, i] = Pk[i, j]
    feed_back(state, dx, offs, use_ext, feedbacks, arrays, k, t_k, w, st, data_k)
    return nis


@njit(inline=True)
def update_row(Pk, z, H, R, a, dx, u, gain, g, nonzero):
    """filterpy's update with row ``a`` of the stacked measurement; returns its nonzero count, ν / s, ν and s.

    K = P Hᵀ (H P Hᵀ + R)⁻¹ and the Joseph form (eq. 45), (I − KH) P (I − KH)ᵀ + K R Kᵀ, one row
    of H at a time: R is diagonal, so the rows are independent measurements and updating with
    each in turn gives the same estimate and covariance as the stacked update. For a row h with
    variance r: u = P hᵀ, s = h u + r, k = u / s, dx ← dx + k (z − h dx) and
    P ← P − k uᵀ − g kᵀ with g = u − k s, on the nonzero entries of h (their columns in ``nonzero``;
    whole rows are computed, the upper triangle is mirrored by the caller after the last row).
    """
    n = Pk.shape[0]
    cnt = 0
    for b in range(n):
        if H[a, b] != 0.0:
            nonzero[cnt] = b
            cnt += 1
    innov = z[a]
    for i in range(n):
        u[i] = 0.0
    for e in range(cnt):
        b = nonzero[e]
        h = H[a, b]
        innov -= h * dx[b]
        for i in range(n):  # P is symmetric up to rounding
            u[i] += Pk[b, i] * h
    hu = 0.0
    for e in range(cnt):
        b = nonzero[e]
        hu += H[a, b] * u[b]
    s_ = hu + R[a]
    for i in range(n):
        gain[i] = u[i] / s_
    for i in range(n):
        g[i] = u[i] - gain[i] * s_
        dx[i] += gain[i] * innov
    for i in range(n):
        ki, gi = gain[i], g[i]
        for j in range(n):  # whole rows (faster than the triangle: full vectors)
            Pk[i, j] -= ki * u[j] + gi * gain[j]
    return cnt, innov / s_, innov, s_


@njit(inline=True)
def feed_back(state, dx, offs, use_ext, feedbacks, arrays, k, t_k, w, st, data_k):
    """The estimated error into the nominal state, eqs. 49–52, then into each model's memory.

    q ← exp(−δφ) ⊗ q, p ← p − δp, v ← v − δv, b ← b + δb. The models' ``feedback`` get sample ``k``
    (its corrected state; ``w`` and ``f`` as their ``measure`` got them).
    """
    a, nav, mems = arrays, state.nav, state.mems
    if offs.att >= 0 and not use_ext:
        feed_back_attitude(nav, dx[offs.att], dx[offs.att + 1], dx[offs.att + 2])
    for i in range(3):
        nav[P + i] -= dx[offs.pos + i]
        nav[V + i] -= dx[offs.vel + i]
        if offs.gyro_bias >= 0:
            nav[BG + i] += dx[offs.gyro_bias + i]
        if offs.acc_bias >= 0:
            nav[BA + i] += dx[offs.acc_bias + i]
    for j in range(a.has_feedback.shape[0]):
        if a.has_feedback[j]:
            feedbacks[j](k, t_k, nav, w.w, w.f, st, a.idx[j], a.par[a.par_off[j]:a.par_off[j + 1]],
                         mems[a.mem_off[j]:a.mem_off[j + 1]], data_k[a.data_off[j]:a.data_off[j + 1]], dx)


@njit(inline=True)
def after(afters, arrays, k, t_k, state, w, st, data_k):
    """Each model's ``after`` function, once per sample after the update (bookkeeping on the corrected state)."""
    a, mems = arrays, state.mems
    for j in range(a.has_after.shape[0]):
        if a.has_after[j]:
            afters[j](k, t_k, state.nav, w.w, w.f, st, a.idx[j], a.par[a.par_off[j]:a.par_off[j + 1]],
                      mems[a.mem_off[j]:a.mem_off[j + 1]], data_k[a.data_off[j]:a.data_off[j + 1]])


@njit(inline=True)
def store(k, nav, a_n, Pk, offs, out, keep_p, first, nis_k, rows_k):
    """Sample ``k``'s estimates into the outputs (the motion acceleration of the incoming state: 0).

    With the covariance kept, also its diagonal and the update's NIS and rows.
    """
    traj = out.trajectory
    for i in range(4):
        traj.quat[k, i] = nav[Q + i]
    for i in range(3):
        traj.pos[k, i] = nav[P + i]
        traj.vel[k, i] = nav[V + i]
        if offs.gyro_bias >= 0:  # without the block the estimate stays 0 (the caller's zeros)
            traj.gyro_bias[k, i] = nav[BG + i]
        if offs.acc_bias >= 0:
            traj.acc_bias[k, i] = nav[BA + i]
        out.acc_nav[k, i] = 0.0 if first else a_n[i]
    if keep_p:
        for i in range(Pk.shape[0]):
            out.p_diag[k, i] = Pk[i, i]
        out.nis[k] = nis_k
        out.nis_rows[k] = rows_k
