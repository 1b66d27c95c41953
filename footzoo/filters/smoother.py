"""Rauch–Tung–Striebel smoothing of the error-state filter (offline, after the forward pass).

Forward pass unchanged. At every sample it keeps the smoother gain
``A_k = P_k⁺ Φ_{k+1}ᵀ (P_{k+1}⁻)⁻¹`` and the error ``δx̂_{k+1}`` its update fed back. Because the
closed-loop filter resets its error state to zero after every feedback, the backward pass of the
RTS smoother (Rauch, Tung & Striebel 1965) reduces to

    e_{N−1} = 0,    e_k = A_k (e_{k+1} + δx̂_{k+1}),

``e_k`` being the smoothed error of the forward estimate at sample k (``e_{k+1} + δx̂_{k+1}`` is
the smoothed error of the prediction at k+1, whose forward mean is zero). It is applied as the
feedback is (``p ← p − e_p``, ``v ← v − e_v``, ``q ← exp(−e_φ) ⊗ q``, ``b ← b + e_b``). This is
the error-state form of the smoother that gaitmap's ``RtsKalman`` and OpenShoe's smoothed ZUPT
filters run. States with zero variance (e.g. the position before the first step) are left out of
the inverse; a relative jitter of 1e-12 keeps the Cholesky factorisation of ``P⁻`` defined.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import njit
from .strapdown import quat_product, rotvec_quat

JITTER = 1e-12


@njit
def cholesky(S, m, L):
    """Lower Cholesky factor of the symmetric positive definite ``S[:m, :m]``, into ``L[:m, :m]``."""
    for i in range(m):
        for j in range(i + 1):
            acc_ = S[i, j]
            for k in range(j):
                acc_ -= L[i, k] * L[j, k]
            if i == j:
                L[i, i] = math.sqrt(acc_)
            else:
                L[i, j] = acc_ / L[j, j]


@njit
def smoother_gain(M, P_pred, A, sub, L, x, keep):
    """``A = Mᵀ (P⁻)⁻¹`` with ``M = Φ P⁺`` (so ``Mᵀ = P⁺ Φᵀ``), over the states with variance.

    Row i of A solves ``P⁻ aᵢ = M[:, i]`` (P⁻ symmetric) with the Cholesky factor of P⁻: one
    factorisation and two triangular solves per row, no explicit inverse. ``sub``, ``L``,
    ``x`` (n, n) and ``keep`` (n,) int are work arrays.
    """
    n = P_pred.shape[0]
    top = 0.0
    for i in range(n):
        top = max(top, P_pred[i, i])
    m = 0
    for i in range(n):
        if P_pred[i, i] > 0.0:
            keep[m] = i
            m += 1
    for a in range(m):
        for b in range(m):
            sub[a, b] = P_pred[keep[a], keep[b]]
        sub[a, a] += JITTER * top
    cholesky(sub, m, L)
    for i in range(n):
        for j in range(n):
            A[i, j] = 0.0
        y = x[i]
        for a in range(m):  # forward: L y = M[keep, i]
            acc_ = M[keep[a], i]
            for k in range(a):
                acc_ -= L[a, k] * y[k]
            y[a] = acc_ / L[a, a]
        for a in range(m - 1, -1, -1):  # backward: Lᵀ aᵢ = y
            acc_ = y[a]
            for k in range(a + 1, m):
                acc_ -= L[k, a] * y[k]
            y[a] = acc_ / L[a, a]
        for b in range(m):
            A[i, keep[b]] = y[b]


@njit(inline=True)
def feed_back_attitude(q, ex, ey, ez):
    """``q ← exp(−e) ⊗ q``, normalised, in place (the attitude feedback of Nguyen & La eqs. 51–52)."""
    aw, ax, ay, az = rotvec_quat(-ex, -ey, -ez)
    qw, qx, qy, qz = quat_product(aw, ax, ay, az, q[0], q[1], q[2], q[3])
    nq = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    q[0], q[1], q[2], q[3] = qw / nq, qx / nq, qy / nq, qz / nq


@njit
def correct_sample(k, e, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias):
    """Apply the smoothed error ``e`` of sample k as the feedback is (``p ← p − e_p``, ``q ← exp(−e_φ) ⊗ q``, ...)."""
    att, gb_i, pos_i, vel_i, ab_i = idx[0], idx[1], idx[2], idx[3], idx[4]
    for i in range(3):
        pos[k, i] -= e[pos_i + i]
        vel[k, i] -= e[vel_i + i]
        if gb_i >= 0:
            gyro_bias[k, i] += e[gb_i + i]
        if ab_i >= 0:
            acc_bias[k, i] += e[ab_i + i]
    if att >= 0 and not use_ext:
        feed_back_attitude(quat[k], e[att], e[att + 1], e[att + 2])


@njit
def rts_backward(A, dxs, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias):
    """Backward pass: correct the forward trajectories in place (see the module docstring)."""
    N, n = dxs.shape
    e = np.zeros(n)
    s = np.empty(n)
    for k in range(N - 2, -1, -1):
        for i in range(n):
            s[i] = e[i] + dxs[k + 1, i]
        for i in range(n):
            acc_ = 0.0
            for j in range(n):
                acc_ += A[k, i, j] * s[j]
            e[i] = acc_
        correct_sample(k, e, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias)
