"""The step-wise smoother's continuity: each stride's start pinned to the emitted estimate before it
(footzoo.filters.stepwise), by hand, on a simulated walk whose gyroscope clips, live, and on Köroğlu's walk."""

import dataclasses
import warnings

import numpy as np
import pytest

from footzoo import Pipeline, Stream
from footzoo.core.errors import SensorWarning
from footzoo.filters.structures import Offsets, Trajectory
from footzoo.sim import NoiseModel, simulate

from ..conftest import data_file

#: A 9-state filter: attitude, position, velocity.
NINE = Offsets(att=0, gyro_bias=-1, pos=3, vel=6, acc_bias=-1)


def _line(n_moving: int, n_standing: int, dt: float, speed: float) -> tuple[Trajectory, np.ndarray]:
    """A foot moving along x at ``speed`` (m/s) for ``n_moving`` samples, then standing ``n_standing`` samples."""
    n = n_moving + n_standing
    t = np.arange(n) * dt
    x = np.minimum(np.arange(n), n_moving - 1) * speed * dt
    pos = np.column_stack([x, np.zeros(n), np.zeros(n)])
    vel = np.zeros((n, 3))
    vel[:n_moving, 0] = speed
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    return Trajectory(quat, vel, pos, np.zeros((n, 3)), np.zeros((n, 3))), t


def test_a_pinned_stride_takes_its_first_correction_back_along_its_path():
    """Hand-derived (footzoo.filters.stepwise, eqs. 1–2): a foot moving at 10 m/s for 11 samples (1 m of path), then
    standing 4. The weight ``w_k = 1 − ℓ_k / ℓ`` falls by 0.1 per moving sample and is 0 while it stands."""
    from footzoo.filters.stepwise import pin_start

    traj, t = _line(11, 4, 0.01, 10.0)
    before = Trajectory(*(a.copy() for a in traj))
    u = np.zeros(9)
    u[NINE.pos:NINE.pos + 3] = [0.05, -0.02, 0.01]
    u[NINE.vel:NINE.vel + 3] = [0.1, 0.0, -0.1]
    u[NINE.att + 2] = 0.01  # heading (rad)
    hi = len(t) - 1
    pin_start(traj, t, 0, hi, u, NINE, False)

    w = np.r_[1.0 - np.arange(11) / 10.0, np.zeros(4)]
    k = np.arange(hi)  # the last sample stays as it is
    np.testing.assert_allclose(traj.pos[k], before.pos[k] + w[k, None] * u[3:6], atol=1e-12)
    np.testing.assert_allclose(traj.vel[k], before.vel[k] + w[k, None] * u[6:9], atol=1e-12)
    np.testing.assert_allclose(2 * np.arctan2(traj.quat[k, 3], traj.quat[k, 0]), w[k] * 0.01, atol=1e-12)
    for a, b in zip(traj, before, strict=True):
        np.testing.assert_array_equal(a[hi], b[hi])
    # the first sample is back at the forward estimate, the standing foot is not moved
    np.testing.assert_allclose(traj.pos[0], before.pos[0] + u[3:6], atol=1e-15)
    np.testing.assert_array_equal(np.diff(traj.pos[10:], axis=0), 0.0)


def test_a_foot_that_does_not_move_gets_the_correction_back_in_time():
    """No path (a stance split by MAX_SEGMENT): ``w_k = 1 − (t_k − t_lo) / (t_hi − t_lo)`` (eq. 3)."""
    from footzoo.filters.stepwise import pin_start

    traj, t = _line(1, 9, 0.01, 0.0)
    before = traj.pos.copy()
    u = np.zeros(9)
    u[NINE.pos] = 0.02
    pin_start(traj, t, 0, 9, u, NINE, False)
    np.testing.assert_allclose(traj.pos[:, 0], before[:, 0] + 0.02 * (1.0 - np.arange(10) / 9.0) * (np.arange(10) < 9),
                               atol=1e-15)


def _clipped_walk(**options) -> object:
    """A simulated walk whose gyroscope clips at 6 rad/s (as Köroğlu's sensor does near 8.7 rad/s): the filter
    takes a wrong swing for a heading error and corrects the position of everything walked before."""
    rec = simulate(path="rectangle", profile="physical", rate=100.0, noise=NoiseModel(seed=3), **options)
    with pytest.warns(SensorWarning, match="sensor saturated"):  # the recording's check says so, as it should
        return dataclasses.replace(rec, gyr=np.clip(rec.gyr, -6.0, 6.0))


def _smoothed(rec, how: str):
    """The recommended filter's forward pass over ``rec`` with a record of every sample, then smoothed:
    ``rts`` (one segment), ``plain`` (each stride from the filter at its end, the start not pinned) or
    ``stepwise``; returns the trajectory, the forward one and the segments' ends."""
    from footzoo.filters.recorders import SAMPLE_KEYS, from_columns
    from footzoo.filters.smoother import smooth_segments
    from footzoo.filters.stepwise import segment_ends, smooth_strides
    from footzoo.runtime.chain import recorded_forward

    eng, stance, full = recorded_forward(Pipeline.from_yaml("recommended"), rec)
    rows = from_columns({k: full[k] for k in SAMPLE_KEYS}, full)
    traj = Trajectory(*(full[k].copy() for k in ("quat", "vel", "pos", "gyro_bias", "acc_bias")))
    ends = segment_ends(stance, rec.t, True)
    if how == "stepwise":
        smooth_strides(rows, ends, 0, 0, eng.setup.offsets, False, traj, np.asarray(rec.t, float))
    else:
        smooth_segments(rows, ends if how == "plain" else np.array([len(rec.t) - 1]), 0, 0, eng.setup.offsets, False,
                        traj)
    return traj, full["pos"], ends


def _largest_move(pos: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(pos, axis=0), axis=1).max())


def test_a_stride_whose_start_is_pinned_does_not_jump_where_the_plain_one_does():
    """On the clipped walk the strides smoothed alone jump at every toe-off (the correction the next stance
    makes to the past applied to the stride's first sample only); pinned, the largest per-sample move is
    within the issue's bound of twice the whole-recording smoother's, and the move from a stance's last
    sample to the next stride's first is the forward filter's own."""
    rec = _clipped_walk()
    rts, _, _ = _smoothed(rec, "rts")
    plain, _, ends = _smoothed(rec, "plain")
    pinned, forward, _ = _smoothed(rec, "stepwise")
    bound = 2.0 * _largest_move(rts.pos)
    assert _largest_move(plain.pos) > 2.0 * bound, (_largest_move(plain.pos), bound)  # the case jumps
    assert _largest_move(pinned.pos) <= bound, (_largest_move(pinned.pos), bound)
    starts = ends[:-1] + 1
    np.testing.assert_allclose(pinned.pos[starts] - pinned.pos[starts - 1], forward[starts] - forward[starts - 1],
                               atol=1e-12)
    # the segments still end at the filter's estimate, as before
    np.testing.assert_array_equal(pinned.pos[ends], plain.pos[ends])


def test_the_pinned_strides_stream_as_they_run():
    """Live (footzoo.Stream, packets of random length) the final estimates equal the batch run's."""
    rec = _clipped_walk(length=10.0, width=5.0)
    p = Pipeline.from_yaml("recommended_live")
    batch = p.run(rec)
    with pytest.warns(SensorWarning, match="sensor saturated"):  # the stream's own check of the clipped gyroscope
        final = Stream(p, rate=rec.rate).run(rec, chunk=np.random.default_rng(4).integers(1, 60, size=80))
    scale = max(float(np.abs(batch.pos).max()), 1.0)
    for key in ("pos", "vel", "quat"):
        assert np.abs(final[key] - getattr(batch, key)).max() <= 1e-9 * scale, key


@pytest.mark.slow
def test_koroglus_walk_is_smoothed_stride_by_stride_without_a_jump():
    """Köroğlu's experiment 33 (a gyroscope that clips near 8.7 rad/s): the strides smoothed alone jumped by
    up to 0.12 m at a toe-off (the RTS estimate's largest move: 0.023 m); pinned, the largest move is within
    twice the RTS estimate's."""
    import footzoo

    rec = footzoo.load(data_file("koroglu_gcp", "SensorConnectData_33.csv"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the reader's mounting and the detector's warnings, not this test's subject
        rts = Pipeline.from_yaml("recommended").run(rec)
        live = Pipeline.from_yaml("recommended_live").run(rec)
    assert _largest_move(live.pos) <= 2.0 * _largest_move(rts.pos), (_largest_move(live.pos), _largest_move(rts.pos))


def test_a_long_swing_closes_its_segment_only_once_the_stance_has_settled():
    """A segment longer than MAX_SEGMENT closes at a stance sample SETTLE s into the stance, not at its first: the
    stance's first updates (zero velocity, a level height) correct the swing, and the backward pass carries them
    into it only inside the swing's segment. A stand is still cut every MAX_SEGMENT s, and a stance that ends
    sooner than SETTLE ends its segment at its last sample."""
    from footzoo.filters.stepwise import MAX_SEGMENT, SETTLE, segment_ends

    t = np.arange(0.0, 9.0, 0.005)
    stand = (t < 0.5) | (t >= 4.0)  # the still start, a 3.5 s swing, a stand
    ends = t[segment_ends(stand, t, True)]
    np.testing.assert_allclose(ends, [0.495, 4.0 + SETTLE, 4.0 + SETTLE + MAX_SEGMENT, t[-1]], atol=0.006)
    step = (t < 0.5) | ((t >= 4.0) & (t < 4.1)) | (t >= 5.0)  # the same swing, a 0.1 s stance, a swing, a stand
    np.testing.assert_allclose(t[segment_ends(step, t, True)][:3], [0.495, 4.095, 4.1 + MAX_SEGMENT], atol=0.006)
    still = np.ones(t.size, bool)
    assert t[segment_ends(still, t, True)][0] == pytest.approx(MAX_SEGMENT)  # a stand from the start: as before
