"""Smoothing of the Kalman pipelines (RTS over the whole recording, step-wise per stride): forward pass
unchanged, closer to the truth, the backward recursions equal to filterpy's RTS smoother."""

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.sim import NoiseModel, simulate


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=20, profile="physical", rate=100.0, noise=NoiseModel(seed=3), clearance=0.1)


def _pipeline(name, smoother):
    d = Pipeline.from_yaml(name).to_dict()
    return Pipeline.from_dict({**d, "smoother": smoother})


def _rmse(pos, truth):
    return float(np.sqrt(np.mean(np.sum((pos - truth) ** 2, axis=1))))


def test_the_smoother_leaves_the_forward_pass_unchanged_and_gets_closer_to_the_truth(walk):
    forward = _pipeline("duong2015_zupt", "none").run(walk)
    smoothed = _pipeline("duong2015_zupt", "rts").run(walk)
    np.testing.assert_array_equal(smoothed.diagnostics["pos_forward"], forward.pos)
    assert smoothed.config["smoother"] == "rts"
    # the heading (unobservable) dominates the position error; the velocity shows the smoothing
    before, after = _rmse(forward.vel, walk.truth.vel), _rmse(smoothed.vel, walk.truth.vel)
    assert after < 0.9 * before, (before, after)
    # the last sample has seen all data already: the smoother leaves it as it is
    np.testing.assert_allclose(smoothed.pos[-1], forward.pos[-1], atol=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["duong2015_zupt", "nguyen2016"])
def test_both_engines_smooth_alike(walk, name):
    p = _pipeline(name, "rts")
    fast, ref = p.run(walk, engine="fast"), p.run(walk, engine="reference")
    scale = np.abs(ref.pos).max()
    assert np.abs(fast.pos - ref.pos).max() <= 1e-9 * scale
    assert np.abs(fast.quat - ref.quat).max() <= 1e-9


def test_smoothing_needs_a_kalman_filter_and_a_known_name():
    with pytest.raises(ConfigError, match="smooths the Kalman filter, and this pipeline has none"):
        _pipeline("yun2012", "rts")
    with pytest.raises(ConfigError, match=r"smoother must be one of \['none', 'rts', 'stepwise'\]"):
        _pipeline("duong2015_zupt", "kalman")



def _linear_system(measured_every: int = 40):
    """A closed-loop error-state filter on x' = F x + w, z = H x + v (position, velocity; velocity measured
    every other ``measured_every`` samples, as in stance), and filterpy's standard RTS smoother on it."""
    from filterpy.kalman import KalmanFilter

    from footzoo.filters.recorders import packed, record

    rng = np.random.default_rng(0)
    dt, n_steps = 0.01, 300
    F = np.eye(6)
    F[:3, 3:] = dt * np.eye(3)
    Q = np.diag([1e-4] * 3 + [1e-2] * 3) * dt
    H = np.hstack([np.zeros((3, 3)), np.eye(3)])
    R = np.eye(3) * 0.01**2
    x = np.zeros(6)
    zs, measured = [], []
    for k in range(n_steps):
        x = F @ x + rng.multivariate_normal(np.zeros(6), Q)
        zs.append(H @ x + rng.normal(0, 0.01, 3))
        measured.append((k // measured_every) % 2 == 0)  # "stance" every other 40 samples
    p0 = np.diag([1e-6] * 3 + [1e-4] * 3)
    # filterpy, standard form
    kf = KalmanFilter(dim_x=6, dim_z=3)
    kf.F, kf.Q, kf.H, kf.R, kf.P = F, Q, H, R, p0.copy()
    means, covs = [kf.x[:, 0].copy()], [kf.P.copy()]
    for k in range(1, n_steps):
        kf.predict()
        if measured[k]:
            kf.update(zs[k])
        means.append(kf.x[:, 0].copy())
        covs.append(kf.P.copy())
    expected, *_ = kf.rts_smoother(np.array(means)[:, :, None], np.array(covs), Fs=[F] * n_steps, Qs=[Q] * n_steps)
    # closed-loop error-state form: nominal estimate, error estimate fed back and reset
    nominal = np.zeros((n_steps, 6))
    P = p0.copy()
    # the step-wise smoother's record, filled as the compiled loop fills it: P⁺, Φ's blocks (here only
    # Δ[pos, vel] = I dt), the scalar update rows one at a time (h, k, ν / s)
    rec = record(n_steps, 6, 3)
    cov, rows, first, count = rec.cov, rec.rows, rec.first, rec.count
    cov[0] = packed(P)
    for k in range(1, n_steps):
        nominal[k] = F @ nominal[k - 1]
        P = F @ P @ F.T + Q
        rec.transitions.dt[k] = dt
        first[k] = first[k - 1] + count[k - 1]
        if measured[k]:
            S = H @ P @ H.T + R
            K = P @ H.T @ np.linalg.inv(S)
            dx = K @ (H @ nominal[k] - zs[k])  # residual: predicted − measured = H δ
            seq, Pa = np.zeros(6), P.copy()  # the same update one row at a time
            for a in range(3):
                u = Pa @ H[a]
                s_ = H[a] @ u + R[a, a]
                nu = (H[a] @ nominal[k] - zs[k][a]) - H[a] @ seq
                r = first[k] + a
                rows.h[r], rows.gain[r], rows.scaled[r], rows.nu[r], rows.s[r] = H[a], u / s_, nu / s_, nu, s_
                seq += u / s_ * nu
                Pa = Pa - np.outer(u, u) / s_
            count[k] = 3
            np.testing.assert_allclose(seq, dx, atol=1e-12)
            nominal[k] -= dx
            P = (np.eye(6) - K @ H) @ P @ (np.eye(6) - K @ H).T + K @ R @ K.T
        cov[k] = packed(P)
    np.testing.assert_allclose(nominal, np.array(means), atol=1e-12)
    return nominal, rec, np.array(measured), expected[:, :, 0]


def _offsets():
    """INS core offsets of the linear system: no attitude, no biases, position at 0, velocity at 3."""
    from footzoo.filters.structures import Offsets

    return Offsets(att=-1, gyro_bias=-1, pos=0, vel=3, acc_bias=-1)


def _trajectory(nominal):
    from footzoo.filters.structures import Trajectory

    n = len(nominal)
    return Trajectory(np.zeros((n, 4)), nominal[:, 3:].copy(), nominal[:, :3].copy(), np.zeros((n, 3)),
                      np.zeros((n, 3)))


def test_the_backward_recursion_over_the_whole_run_and_over_each_segment_is_filterpys_rts_smoother():
    """Without a gain or an inverse, footzoo's closed-loop backward recursion over the whole run (the
    ``rts`` smoother) equals filterpy's standard RTS smoother; over the segments between measured
    instants (``stepwise``) it is filterpy's RTS smoother run on each segment alone, from the filtered
    estimate at its end."""
    from footzoo.filters.smoother import smooth_segments
    from footzoo.filters.stepwise import segment_ends

    nominal, rec, measured, expected = _linear_system()
    traj = _trajectory(nominal)
    smooth_segments(rec, np.array([len(nominal) - 1]), 0, 0, _offsets(), True, traj)
    np.testing.assert_allclose(np.hstack([traj.pos, traj.vel]), expected, atol=1e-9)

    ends = segment_ends(measured, np.arange(len(measured)) * 0.01, closed=True)  # each run's last measured sample
    np.testing.assert_array_equal(ends[:3], [39, 119, 199])
    traj = _trajectory(nominal)
    smooth_segments(rec, ends, 0, 0, _offsets(), True, traj)
    smoothed = np.hstack([traj.pos, traj.vel])
    lo = 0
    for hi in ends:  # the RTS smoother of filterpy on the filtered means and covariances of one segment
        alone = _filterpy_rts_on(nominal[lo:hi + 1], _unpacked(rec.cov[lo:hi + 1], 6))
        np.testing.assert_allclose(smoothed[lo:hi + 1], alone, atol=1e-9)
        lo = hi + 1


def _unpacked(cov, n):
    """The record's upper triangles (N, n(n+1)/2) as full symmetric matrices (N, n, n)."""
    full = np.zeros((len(cov), n, n))
    i, j = np.triu_indices(n)
    full[:, i, j] = cov
    full[:, j, i] = cov
    return full


def test_the_record_keeps_the_upper_triangle_row_by_row():
    from footzoo.filters.recorders import packed

    P = np.arange(9.0).reshape(3, 3)
    P = P + P.T  # [[0, 4, 8], [4, 8, 12], [8, 12, 16]]
    np.testing.assert_array_equal(packed(P), [0, 4, 8, 8, 12, 16])
    np.testing.assert_array_equal(_unpacked(packed(P)[None], 3)[0], P)


def _filterpy_rts_on(means, covs):
    from filterpy.kalman import KalmanFilter

    dt = 0.01
    F = np.eye(6)
    F[:3, 3:] = dt * np.eye(3)
    Q = np.diag([1e-4] * 3 + [1e-2] * 3) * dt
    out, *_ = KalmanFilter(dim_x=6, dim_z=3).rts_smoother(means[:, :, None], covs, Fs=[F] * len(means),
                                                           Qs=[Q] * len(means))
    return out[:, :, 0]


# slow: compiles the forward loop for a signature no shipped config has (about 12 s on a fresh install)
@pytest.mark.slow
def test_stepwise_smoothing_improves_on_the_filter_and_comes_close_to_rts(walk):
    """Against the simulator's truth: every stride smoothed alone is better than the forward filter
    and about as good as the whole-recording smoother."""
    errors = {}
    for name in ("duong2015_zupt", "nguyen2016", "recommended"):
        runs = {s: _pipeline(name, s).run(walk) for s in ("none", "rts", "stepwise")}
        np.testing.assert_array_equal(runs["stepwise"].diagnostics["pos_forward"], runs["none"].pos)
        errors[name] = {s: _rmse(r.vel, walk.truth.vel) for s, r in runs.items()}
        e = errors[name]
        assert e["stepwise"] < e["none"], (name, e)
        assert e["stepwise"] < e["rts"] + 0.5 * (e["none"] - e["rts"]), (name, e)  # most of the RTS gain
        # the end of the last stance is the end of the recording: both smoothers leave it as it is
        np.testing.assert_allclose(runs["stepwise"].pos[-1], runs["none"].pos[-1], atol=1e-12)


# nguyen2016 (the bias states) is slow: its step-wise loop is one no shipped config has (about 14 s to compile)
@pytest.mark.parametrize("name", ["duong2015_zupt", pytest.param("nguyen2016", marks=pytest.mark.slow)])
def test_both_engines_smooth_stride_by_stride_alike(walk, name):
    """The compiled loop smooths each stride as it closes; the reference (filterpy) after the loop."""
    p = _pipeline(name, "stepwise")
    fast, ref = p.run(walk, engine="fast"), p.run(walk, engine="reference")
    scale = np.abs(ref.pos).max()
    assert np.abs(fast.pos - ref.pos).max() <= 1e-9 * scale
    assert np.abs(fast.quat - ref.quat).max() <= 1e-9
    np.testing.assert_allclose(ref.diagnostics["pos_forward"], fast.diagnostics["pos_forward"], atol=1e-9 * scale)


def _engine_inputs(p, rec):
    """A fresh engine of pipeline ``p`` for ``rec`` and what its run takes (stance, initial and external attitude)."""
    from footzoo.plugins.base import Samples
    from footzoo.runtime.alignment import initial_attitude

    stance = p.detect(rec).stance_
    q0 = initial_attitude(rec.t, rec.acc, rec.gyr, None, **p.init)
    quat = p.orient(rec, stance, q0)
    samples = Samples(rec.t, rec.acc, rec.gyr, rec.mag, rec.dist, rec.t <= rec.t[0] + p.init["duration"])
    return (lambda: p.kalman_engine([c.clone() for c in p.filter_corrections], samples, "fast")), stance, q0, quat


def _smoothed_over_one_record(make, t, acc, gyr, stance, q0, quat):
    """The forward pass with the record of every sample, then the backward pass over it (no checkpoint)."""
    ref = make()
    nav0 = np.zeros(16)
    nav0[:4] = quat[0] if quat is not None else q0
    state = ref.start(nav0)
    full = ref.advance(state, t, acc, gyr, stance, quat, [m.data for m in ref.setup.models], 0, True, record=True)
    forward = {k: full[k].copy() for k in ("quat", "vel", "pos", "acc_nav", "P_diag", "nis")}
    ref.smooth({**full, "t": t}, np.array([len(t) - 1]), "rts")
    return full, forward, ref.diagnostics(state)


# slow: compiles the forward loop for a signature no shipped config has (about 12 s on a fresh install)
@pytest.mark.slow
@pytest.mark.parametrize(("block", "min_gap"), [(1, 32), (7, 32), (1024, 32), (10**6, 1), (10**6, 10**6)])
@pytest.mark.parametrize("name", ["nguyen2016", "duong2015_zupt_height", "madgwick+zupt"])
def test_the_checkpointed_rts_smoother_is_the_one_over_a_record_of_every_sample(walk, name, block, min_gap,
                                                                                monkeypatch):
    """``smoother: rts`` keeps checkpoints, runs the filter again over the updates piece by piece and
    smooths the swings in closed form: the same smoothed trajectory as one record of every sample (to
    rounding: 1e-12 of the largest value), whatever the pieces (a piece per sample, pieces of 7 samples,
    the last shorter, a piece per stance, one piece), with biases and memory-keeping models (nguyen2016:
    15 states and the heading reduction; the height update) and with an external attitude; the forward
    pass's outputs bit for bit."""
    from footzoo.filters import checkpointed

    if name == "madgwick+zupt":
        p = Pipeline.from_dict({"name": name, "orientation": {"type": "madgwick", "use_magnetometer": False},
                                "detector": {"type": "windowed"}, "corrections": [{"type": "zupt"}]})
    else:
        p = Pipeline.from_yaml(name)
    make, stance, q0, quat = _engine_inputs(p, walk)
    t, acc, gyr, n = walk.t, walk.acc, walk.gyr, len(walk.t)
    assert n > 2 * 1024 + 1 and n % 7 != 1  # several blocks of 1024, the last shorter
    monkeypatch.setattr(checkpointed, "BLOCK", block)
    monkeypatch.setattr(checkpointed, "MIN_GAP", min_gap)
    got = make().run(t, acc, gyr, stance, q0, quat, covariance=True, smoother="rts")
    full, forward, diagnostics = _smoothed_over_one_record(make, t, acc, gyr, stance, q0, quat)
    for key in ("quat", "vel", "pos", "gyro_bias", "acc_bias"):
        np.testing.assert_allclose(got[key], full[key], rtol=0, atol=1e-12 * max(1.0, np.abs(full[key]).max()),
                                   err_msg=key)
    for key in ("quat", "vel", "pos"):
        np.testing.assert_array_equal(got[f"{key}_forward"], forward[key], err_msg=key)
    for key in ("acc_nav", "P_diag", "nis"):  # the forward pass's, every block's first row included
        np.testing.assert_array_equal(got[key], forward[key], err_msg=key)
    assert got["diagnostics"].keys() == diagnostics.keys()
    assert np.abs(got["vel"] - got["vel_forward"]).max() > 1e-4  # it did smooth


# slow: its reference, the smoother over one record, is a kernel no shipped config uses (12 s to compile on CI)
@pytest.mark.slow
@pytest.mark.parametrize("stance_kind", ["flickering", "never", "always", "ends_in_swing"])
def test_the_checkpointed_rts_smoother_holds_whatever_the_stance(walk, stance_kind):
    """Pieces start at the stance's starts: a detector's stance that flickers sample by sample, that never
    starts (no update at all: every sample in closed form), that never ends (no swing) or a recording that
    ends in a swing give the smoother over one record of every sample too."""
    p = Pipeline.from_yaml("duong2015_zupt")
    make, stance, q0, quat = _engine_inputs(p, walk)
    t, acc, gyr, n = walk.t, walk.acc, walk.gyr, len(walk.t)
    if stance_kind == "flickering":
        stance = stance & (np.random.default_rng(0).random(n) < 0.7)
    elif stance_kind == "never":
        stance = np.zeros(n, bool)
    elif stance_kind == "always":
        stance = np.ones(n, bool)
    else:
        stance = stance.copy()
        stance[-150:] = False
    got = make().run(t, acc, gyr, stance, q0, quat, covariance=True, smoother="rts")
    full, _, _ = _smoothed_over_one_record(make, t, acc, gyr, stance, q0, quat)
    for key in ("quat", "vel", "pos"):
        np.testing.assert_allclose(got[key], full[key], rtol=0, atol=1e-12 * max(1.0, np.abs(full[key]).max()),
                                   err_msg=key)
    if stance_kind != "never":
        assert np.abs(got["vel"] - got["vel_forward"]).max() > 1e-4  # it did smooth


def test_a_flickering_stance_costs_the_checkpoints_no_more_room_than_one_per_min_gap():
    """The forward pass's checkpoints are allocated before the loop: sample 0, one per stance start and one per
    block, but never more than one per min(min_gap, block) samples, since no piece starts closer to the last."""
    from footzoo.filters.checkpointed import checkpoint_record

    flicker = np.arange(10_001) % 2 == 0  # 5000 stance starts
    cp = checkpoint_record(flicker, 21, 4, 4096, 32).checkpoints
    assert len(cp.nav) == len(cp.P) == len(cp.mems) == len(cp.first) == len(cp.last_update) == 1 + 10_000 // 32
    walk_like = np.arange(10_001) % 100 < 40  # 100 stance starts, one per 100 samples
    assert len(checkpoint_record(walk_like, 9, 0, 4096, 32).checkpoints.nav) == 1 + 100 + 10_000 // 4096
