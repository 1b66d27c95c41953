"""Compiled sample loop of the error-state Kalman filter: the same equations as
:func:`footzoo.filters.navigation.run_error_state_filter` (the reference, on
filterpy's ``KalmanFilter``), for the corrections that ship with footzoo.

The measurement models are those of ``ekf_zupt``/``zupt`` (velocity, angular
rate), ``height_flat_floor``, ``height_distance`` (with its calibration states,
constraints and baseline) and ``hdr``, evaluated in the order the reference
stacks them. The covariance prediction uses the sparsity of Φ = I + Δ
(``P ← P + ΔP + (P + ΔP)Δᵀ + Q``), the update filterpy's formulas with the
Joseph form, expanded so that only the nonzero entries of H are touched.
A test keeps both paths equal to 1e-9 relative on the simulator.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit

ZERO_VELOCITY, ZERO_RATE, FLAT_FLOOR, DISTANCE, HEADING = 1, 2, 3, 4, 5


@njit
def _qmul(a, b):
    return np.array([
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ])


@njit
def _rotvec(rx, ry, rz):
    angle = math.sqrt(rx * rx + ry * ry + rz * rz)
    half = 0.5 * angle
    k = math.sin(half) / angle if angle > 1e-12 else 0.5 - angle * angle / 48.0
    return np.array([math.cos(half), k * rx, k * ry, k * rz])


@njit
def _matrix(q):
    w, x, y, z = q[0], q[1], q[2], q[3]
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


@njit
def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


@njit
def _yaw(q):
    w, x, y, z = q[0], q[1], q[2], q[3]
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@njit
def _wrap(a):
    return -((-a + math.pi) % (2 * math.pi) - math.pi)


@njit
def _add_block_rows(out, src, r0, c0, b):
    """out[r0:r0+3, :] += b @ src[c0:c0+3, :]"""
    n = src.shape[1]
    for i in range(3):
        for j in range(n):
            s = 0.0
            for m in range(3):
                s += b[i, m] * src[c0 + m, j]
            out[r0 + i, j] += s


@njit
def _add_block_cols(out, src, r0, c0, b):
    """out[:, r0:r0+3] += src[:, c0:c0+3] @ b.T"""
    n = src.shape[0]
    for i in range(n):
        for j in range(3):
            s = 0.0
            for m in range(3):
                s += src[i, c0 + m] * b[j, m]
            out[i, r0 + j] += s


@njit
def _spd_inverse(S, m, L, out):
    """Inverse of the symmetric positive definite ``S[:m, :m]`` by Cholesky, into ``out``."""
    for i in range(m):
        for j in range(i + 1):
            acc_ = S[i, j]
            for k in range(j):
                acc_ -= L[i, k] * L[j, k]
            if i == j:
                L[i, i] = math.sqrt(acc_)
            else:
                L[i, j] = acc_ / L[j, j]
    # solve L Lᵀ X = I column by column
    for col in range(m):
        for i in range(m):  # forward: L y = e_col
            acc_ = 1.0 if i == col else 0.0
            for k in range(i):
                acc_ -= L[i, k] * out[k, col]
            out[i, col] = acc_ / L[i, i]
        for i in range(m - 1, -1, -1):  # backward: Lᵀ x = y
            acc_ = out[i, col]
            for k in range(i + 1, m):
                acc_ -= L[k, i] * out[k, col]
            out[i, col] = acc_ / L[i, i]


@njit
def _add_identity_rows(out, src, r0, c0, s):
    """out[r0:r0+3, :] += s * src[c0:c0+3, :]"""
    for i in range(3):
        for j in range(src.shape[1]):
            out[r0 + i, j] += s * src[c0 + i, j]


@njit
def _add_identity_cols(out, src, r0, c0, s):
    """out[:, r0:r0+3] += s * src[:, c0:c0+3]"""
    for i in range(src.shape[0]):
        for j in range(3):
            out[i, r0 + j] += s * src[i, c0 + j]


def initial_state(q0: np.ndarray, p0: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fresh loop state: ``nav`` (q, p, v, b_g, b_a), covariance, and the bookkeeping scalars.

    ``scal`` = (was stance, last yaw, floor, have floor, stance ends, latest end yaw, previous end yaw).
    """
    nav = np.zeros(16)
    nav[:4] = q0
    return nav, np.array(p0, dtype=float, copy=True), np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])


@njit
def eskf_kernel(t, acc, gyr, stance, quat_ext, use_ext, idx, n, qn, gravity, order,
                vel_std, rate_std, floor_std, hdr_threshold, hdr_std,
                dist, valid, in_init, init_dist, init_valid, r_d, n_d, range_std, calibrate, cal_r, cal_n,
                constraint_std, baseline, baseline_std, nav, P, scal, k0):
    """Run samples 1… of the given arrays from the state (``nav``, ``P``, ``scal``, ``r_d``, ``n_d``,
    updated in place); sample 0 is the one the state belongs to.

    ``k0`` is the index of sample 0 in the whole recording. ``idx`` = (att, gyro_bias, pos, vel,
    acc_bias) offsets, −1 if absent. Row 0 of the outputs
    is the incoming state. A batch run passes the whole recording from the initial state; a
    live stream passes its last two samples, and gets the same numbers.
    """
    N = t.shape[0]
    att, gb_i, pos_i, vel_i, ab_i = idx[0], idx[1], idx[2], idx[3], idx[4]
    k_sensors = r_d.shape[0]
    quat = np.zeros((N, 4))
    vel = np.zeros((N, 3))
    pos = np.zeros((N, 3))
    acc_nav = np.zeros((N, 3))
    gb_out = np.zeros((N, 3))
    ab_out = np.zeros((N, 3))
    pdiag = np.zeros((N, n))
    q = nav[0:4].copy()
    p = nav[4:7].copy()
    v = nav[7:10].copy()
    bg = nav[10:13].copy()
    ba = nav[13:16].copy()
    quat[0] = q
    pos[0] = p
    vel[0] = v
    gb_out[0] = bg
    ab_out[0] = ba
    for i in range(n):
        pdiag[0, i] = P[i, i]
    m_max = 8 + 2 * k_sensors
    z = np.zeros(m_max)
    H = np.zeros((m_max, n))
    rdiag = np.zeros(m_max)
    M = np.empty((n, n))
    T = np.empty((n, n))
    S = np.empty((m_max, m_max))
    SI = np.empty((m_max, m_max))
    L = np.empty((m_max, m_max))
    PHT = np.empty((n, m_max))
    THT = np.empty((n, m_max))
    nzc = np.zeros((m_max, n), dtype=np.int64)
    nnz = np.zeros(m_max, dtype=np.int64)
    K = np.empty((n, m_max))
    dx = np.empty(n)
    was_stance = scal[0] != 0.0
    last_yaw = scal[1]
    floor = scal[2]
    have_floor = scal[3] != 0.0
    n_ends = int(scal[4])
    end1 = scal[5]
    end2 = scal[6]
    c = np.empty((3, 3))
    cdt = np.empty((3, 3))
    sdt = np.empty((3, 3))
    w = np.empty(3)
    f_n = np.empty(3)
    a_n = np.empty(3)
    for k in range(1, N):
        dt = t[k] - t[k - 1]
        for i in range(3):
            w[i] = gyr[k, i] - bg[i]
        f0, f1, f2 = acc[k, 0] - ba[0], acc[k, 1] - ba[1], acc[k, 2] - ba[2]
        pw, px, py, pz = q[0], q[1], q[2], q[3]
        if use_ext:
            q[:] = quat_ext[k]
        else:
            # q ⊗ exp(w dt), the exact form of eq. 37
            rx, ry, rz = w[0] * dt, w[1] * dt, w[2] * dt
            angle = math.sqrt(rx * rx + ry * ry + rz * rz)
            half = 0.5 * angle
            kk = math.sin(half) / angle if angle > 1e-12 else 0.5 - angle * angle / 48.0
            dw, dx_, dy, dz = math.cos(half), kk * rx, kk * ry, kk * rz
            q[0] = pw * dw - px * dx_ - py * dy - pz * dz
            q[1] = pw * dx_ + px * dw + py * dz - pz * dy
            q[2] = pw * dy - px * dz + py * dw + pz * dx_
            q[3] = pw * dz + px * dy - py * dx_ + pz * dw
        dot = pw * q[0] + px * q[1] + py * q[2] + pz * q[3]
        sg = 1.0 if dot >= 0 else -1.0
        mw, mx, my, mz = q[0] + sg * pw, q[1] + sg * px, q[2] + sg * py, q[3] + sg * pz
        nm = math.sqrt(mw * mw + mx * mx + my * my + mz * mz)
        mw, mx, my, mz = mw / nm, mx / nm, my / nm, mz / nm
        c[0, 0] = 1 - 2 * (my * my + mz * mz)
        c[0, 1] = 2 * (mx * my - mw * mz)
        c[0, 2] = 2 * (mx * mz + mw * my)
        c[1, 0] = 2 * (mx * my + mw * mz)
        c[1, 1] = 1 - 2 * (mx * mx + mz * mz)
        c[1, 2] = 2 * (my * mz - mw * mx)
        c[2, 0] = 2 * (mx * mz - mw * my)
        c[2, 1] = 2 * (my * mz + mw * mx)
        c[2, 2] = 1 - 2 * (mx * mx + my * my)
        for i in range(3):
            f_n[i] = c[i, 0] * f0 + c[i, 1] * f1 + c[i, 2] * f2
            a_n[i] = f_n[i]
        a_n[2] += gravity
        for i in range(3):
            v_old = v[i]
            v[i] = v_old + a_n[i] * dt
            p[i] = p[i] + 0.5 * (v_old + v[i]) * dt
        # covariance prediction, eq. 44: P <- (I + Δ) P (I + Δ)ᵀ + Q
        for i in range(3):
            for j in range(3):
                cdt[i, j] = dt * c[i, j]
        sdt[0, 0], sdt[0, 1], sdt[0, 2] = 0.0, dt * f_n[2], -dt * f_n[1]
        sdt[1, 0], sdt[1, 1], sdt[1, 2] = -dt * f_n[2], 0.0, dt * f_n[0]
        sdt[2, 0], sdt[2, 1], sdt[2, 2] = dt * f_n[1], -dt * f_n[0], 0.0
        M[:, :] = P
        if att >= 0 and gb_i >= 0:
            _add_block_rows(M, P, att, gb_i, cdt)
        _add_identity_rows(M, P, pos_i, vel_i, dt)
        if att >= 0:
            _add_block_rows(M, P, vel_i, att, sdt)
        if ab_i >= 0:
            _add_block_rows(M, P, vel_i, ab_i, cdt)
        P[:, :] = M
        if att >= 0 and gb_i >= 0:
            _add_block_cols(P, M, att, gb_i, cdt)
        _add_identity_cols(P, M, pos_i, vel_i, dt)
        if att >= 0:
            _add_block_cols(P, M, vel_i, att, sdt)
        if ab_i >= 0:
            _add_block_cols(P, M, vel_i, ab_i, cdt)
        for i in range(n):
            P[i, i] += qn[i] * dt
        # measurement rows, in the reference's order
        m = 0
        st = stance[k]
        for code in order:
            if code == ZERO_VELOCITY and st:
                for i in range(3):
                    H[m, :] = 0.0
                    H[m, vel_i + i] = 1.0
                    z[m] = v[i]
                    rdiag[m] = vel_std * vel_std
                    m += 1
            elif code == ZERO_RATE and st:
                for i in range(3):
                    H[m, :] = 0.0
                    H[m, gb_i + i] = 1.0
                    z[m] = w[i]
                    rdiag[m] = rate_std * rate_std
                    m += 1
            elif code == FLAT_FLOOR and st:
                H[m, :] = 0.0
                H[m, pos_i + 2] = 1.0
                z[m] = p[2]
                rdiag[m] = floor_std * floor_std
                m += 1
            elif code == DISTANCE:
                if not have_floor:
                    if in_init[k]:
                        continue
                    cq = _matrix(q)
                    total = 0.0
                    count = 0
                    for j in range(k_sensors):
                        for s in range(init_dist.shape[0]):
                            if init_valid[s, j]:
                                u = cq @ (r_d[j] + n_d[j] * init_dist[s, j])
                                total += u[2]
                                count += 1
                    floor = total / count
                    have_floor = True
                cq = _matrix(q)
                rows = 0
                for j in range(k_sensors):
                    if not valid[k, j]:
                        continue
                    reading = dist[k, j]
                    u = cq @ (r_d[j] + n_d[j] * reading)
                    H[m, :] = 0.0
                    if att >= 0:
                        sk = _skew(u)
                        for i in range(3):
                            H[m, att + i] = sk[2, i]
                    H[m, pos_i + 2] = -1.0
                    if calibrate:
                        for i in range(3):
                            H[m, cal_r[j] + i] = cq[2, i]
                            H[m, cal_n[j] + i] = reading * cq[2, i]
                    z[m] = floor - (p[2] + u[2])
                    scale = (cq @ n_d[j])[2]
                    rdiag[m] = (scale * range_std) ** 2
                    m += 1
                    rows += 1
                if rows > 0 and calibrate:
                    for j in range(k_sensors):
                        H[m, :] = 0.0
                        for i in range(3):
                            H[m, cal_n[j] + i] = n_d[j, i]
                        z[m] = 0.0
                        rdiag[m] = constraint_std * constraint_std
                        m += 1
                    d = r_d[0] - r_d[1]
                    norm = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
                    H[m, :] = 0.0
                    for i in range(3):
                        H[m, cal_r[0] + i] = d[i] / norm
                        H[m, cal_r[1] + i] = -d[i] / norm
                    z[m] = baseline - norm
                    rdiag[m] = baseline_std * baseline_std
                    m += 1
            elif code == HEADING and st and n_ends >= 2:
                a = end1
                b = end2
                mean = math.atan2(math.sin(a) + math.sin(b), math.cos(a) + math.cos(b))
                dpsi = _wrap(_yaw(q) - mean)
                if abs(dpsi) <= hdr_threshold:
                    H[m, :] = 0.0
                    H[m, att + 2] = 1.0
                    z[m] = dpsi
                    rdiag[m] = hdr_std * hdr_std
                    m += 1
        if m > 0:
            # filterpy's update: K = P Hᵀ (H P Hᵀ + R)⁻¹ and the Joseph form (eq. 45),
            # (I − KH) P (I − KH)ᵀ + K R Kᵀ, evaluated as T = P − K(HP), P = T − (THᵀ)Kᵀ + K R Kᵀ
            # with the nonzero columns of each row of H
            for a in range(m):
                cnt = 0
                for b in range(n):
                    if H[a, b] != 0.0:
                        nzc[a, cnt] = b
                        cnt += 1
                nnz[a] = cnt
            for i in range(n):
                for a in range(m):
                    acc_ = 0.0
                    for e in range(nnz[a]):
                        b = nzc[a, e]
                        acc_ += P[i, b] * H[a, b]
                    PHT[i, a] = acc_
            for a in range(m):
                for b2 in range(m):
                    acc_ = 0.0
                    for e in range(nnz[a]):
                        i = nzc[a, e]
                        acc_ += H[a, i] * PHT[i, b2]
                    S[a, b2] = acc_
                S[a, a] += rdiag[a]
            _spd_inverse(S, m, L, SI)
            for i in range(n):
                for a in range(m):
                    acc_ = 0.0
                    for b2 in range(m):
                        acc_ += PHT[i, b2] * SI[b2, a]
                    K[i, a] = acc_
                acc_ = 0.0
                for a in range(m):
                    acc_ += K[i, a] * z[a]
                dx[i] = acc_
            for i in range(n):  # T = P − K (H P), with H P = (P Hᵀ)ᵀ
                for j in range(n):
                    acc_ = P[i, j]
                    for a in range(m):
                        acc_ -= K[i, a] * PHT[j, a]
                    T[i, j] = acc_
            for i in range(n):  # T Hᵀ
                for a in range(m):
                    acc_ = 0.0
                    for e in range(nnz[a]):
                        b = nzc[a, e]
                        acc_ += T[i, b] * H[a, b]
                    THT[i, a] = acc_
            for i in range(n):
                for j in range(i, n):
                    acc_ = T[i, j]
                    for a in range(m):
                        acc_ += K[j, a] * (K[i, a] * rdiag[a] - THT[i, a])
                    P[i, j] = acc_
                    P[j, i] = acc_
            if att >= 0 and not use_ext:
                q = _qmul(_rotvec(-dx[att], -dx[att + 1], -dx[att + 2]), q)
                q = q / math.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2 + q[3] ** 2)
            p = p - dx[pos_i:pos_i + 3]
            v = v - dx[vel_i:vel_i + 3]
            if gb_i >= 0:
                bg = bg + dx[gb_i:gb_i + 3]
            if ab_i >= 0:
                ba = ba + dx[ab_i:ab_i + 3]
            if calibrate:
                for j in range(k_sensors):
                    r_d[j] = r_d[j] + dx[cal_r[j]:cal_r[j] + 3]
                    n_d[j] = n_d[j] + dx[cal_n[j]:cal_n[j] + 3]
        # HDR bookkeeping (after the update, as the reference's after())
        if was_stance and not st and k0 + k > 1:
            end2 = end1
            end1 = last_yaw
            n_ends += 1
        was_stance = st
        last_yaw = _yaw(q)
        quat[k] = q
        vel[k] = v
        pos[k] = p
        acc_nav[k] = a_n
        gb_out[k] = bg
        ab_out[k] = ba
        for i in range(n):
            pdiag[k, i] = P[i, i]
    nav[0:4] = q
    nav[4:7] = p
    nav[7:10] = v
    nav[10:13] = bg
    nav[13:16] = ba
    scal[0] = 1.0 if was_stance else 0.0
    scal[1] = last_yaw
    scal[2] = floor
    scal[3] = 1.0 if have_floor else 0.0
    scal[4] = n_ends
    scal[5] = end1
    scal[6] = end2
    return quat, vel, pos, acc_nav, gb_out, ab_out, pdiag
