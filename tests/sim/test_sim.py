"""The simulator's truth is internally consistent and what was asked for."""

import numpy as np
import pytest

from footzoo.core.conventions import quat_conj, quat_mul, quat_rotate, quat_to_euler
from footzoo.filters.strapdown import integrate_position, integrate_velocity, motion_acceleration, sample_intervals
from footzoo.orientation import FQAComplementary
from footzoo.sim import DistanceSensors, MagneticDisturbance, NoiseModel, simulate, simulate_pendulum
from footzoo.sim.profiles import GaussianSwing


def strapdown(rec):
    """Exact footzoo strapdown from the true initial attitude: gyro-only attitude, no corrections."""
    n = rec.n
    q = FQAComplementary(0.0, 0.0).estimate(rec.t, rec.acc, rec.gyr, None, np.zeros(n, bool), rec.truth.quat[0]).quat_
    dt = sample_intervals(rec.t)
    vel = integrate_velocity(motion_acceleration(q, rec.acc), dt)
    return q, vel, integrate_position(vel, dt) + rec.truth.pos[0]


@pytest.mark.parametrize("profile", ["paper", "physical"])
def test_strapdown_of_noise_free_interval_data_reproduces_the_truth(profile):
    """Attitude and velocity to the rounding; the position's residual is the trapezoid rule's, not the truth's.

    It falls with the square of the period or faster: measured after 100 strides (120 m) 0.06 mm at
    50 Hz and 0.004 mm at 100 Hz (paper), 3.7 mm and 0.22 mm (physical: the sensor leaves the toe at
    1.3 m/s while the foot still turns at 9 rad/s).
    """
    end_error = {}
    for rate in (50.0, 100.0):
        rec = simulate(n_strides=100, profile=profile, rate=rate)
        q, vel, pos = strapdown(rec)
        assert np.abs(np.abs(np.sum(q * rec.truth.quat, axis=1)) - 1).max() < 1e-12
        assert np.abs(vel - rec.truth.vel).max() < 1e-9
        end_error[rate] = np.linalg.norm(pos[-1] - rec.truth.pos[-1])
    assert end_error[100.0] < 1e-3
    assert end_error[50.0] > 4 * end_error[100.0]  # second order (measured 16x): the sampling, not the truth


def test_instantaneous_sampling_is_offered_and_differs():
    inst = simulate(n_strides=5, sampling="instantaneous")
    avg = simulate(n_strides=5)
    assert inst.n == avg.n
    flat = avg.truth.stance & (np.linalg.norm(avg.gyr, axis=1) == 0)  # foot flat: nothing changes
    np.testing.assert_allclose(inst.acc[flat], avg.acc[flat], atol=1e-9)
    assert np.abs(inst.gyr - avg.gyr).max() > 0.1  # rates are sampled, not averaged


@pytest.mark.parametrize("profile", ["paper", "physical"])
def test_positions_integrate_from_velocities_and_accelerations(profile):
    rec = simulate(n_strides=4, profile=profile, rate=2000.0)
    dt = sample_intervals(rec.t)
    pos = integrate_position(rec.truth.vel, dt)
    assert np.abs(pos - rec.truth.pos).max() < 1e-5


@pytest.mark.parametrize("profile", ["paper", "physical"])
def test_foot_is_still_in_stance_and_stride_lengths_are_as_asked(profile):
    rec = simulate(n_strides=6, stride_length=1.3, profile=profile)
    tr = rec.truth
    assert np.all(tr.vel[tr.stance] == 0.0)
    assert not tr.stance[np.linalg.norm(tr.vel, axis=1) > 0].any()
    np.testing.assert_allclose(tr.steps["stride_length"], 1.3)
    np.testing.assert_allclose(tr.pos[-1], [6 * 1.3, 0, 0], atol=1e-12)
    # Table I: 60 % stance in the paper profile; only foot flat (40 %) in the physical one
    walking = (rec.t > 2.0) & (rec.t < rec.t[-1] - 1.0)
    assert tr.stance[walking].mean() == pytest.approx(0.6 if profile == "paper" else 0.4, abs=0.03)


def test_table_one_rates_and_clearance():
    rec = simulate(n_strides=3, rate=1000.0, sampling="instantaneous")
    wy = rec.gyr[:, 1]
    for rate in (-6.5, -7.5, 3.5):
        assert np.isclose(wy, rate, atol=1e-9).sum() > 50
    height = -rec.truth.pos[:, 2]
    assert height.max() == pytest.approx(0.25, abs=1e-3)


def test_swing_profile_ends_at_rest():
    sw = GaussianSwing(0.4)
    s, s1, s2 = sw.progress(np.array([0.0, 0.2, 0.4]))
    np.testing.assert_allclose(s, [0, 0.5, 1], atol=1e-12)
    np.testing.assert_allclose(s1[[0, 2]], 0, atol=1e-12)
    np.testing.assert_allclose(s2[[0, 2]], 0, atol=1e-9)
    b, b1, b2 = sw.bump(np.array([0.0, 0.2, 0.4]))
    np.testing.assert_allclose(b, [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose([b1[0], b1[2], b2[0], b2[2]], 0, atol=1e-9)


def test_toe_out_and_sensor_mounting_set_the_attitude():
    fpa, mount = np.radians(12.0), np.radians(-20.0)
    rec = simulate(n_strides=4, fpa=fpa, mount_yaw=mount, foot="right")
    yaw = quat_to_euler(rec.truth.quat)[:, 2]
    flat = rec.truth.stance & (np.linalg.norm(rec.gyr, axis=1) == 0)
    np.testing.assert_allclose(yaw[flat], fpa + mount, atol=1e-9)
    np.testing.assert_allclose(rec.truth.steps["fpa"], fpa)
    left = simulate(n_strides=4, fpa=fpa, foot="left")
    flat = left.truth.stance & (np.linalg.norm(left.gyr, axis=1) == 0)
    np.testing.assert_allclose(quat_to_euler(left.truth.quat[flat])[:, 2], -fpa, atol=1e-9)


@pytest.mark.parametrize("path, length", [("rectangle", 120.0), ("track", 437.5), ("figure_eight", 2 * np.pi * 10)])
def test_closed_paths_return_to_the_start(path, length):
    rec = simulate(path=path, stride_length=1.2)
    tr = rec.truth
    assert tr.closed_loop
    np.testing.assert_allclose(tr.pos[-1], tr.pos[0], atol=1e-9)
    assert tr.steps["stride_length"].sum() == pytest.approx(length, rel=0.01)
    assert tr.steps["stride_length"].between(1.0, 1.4).all()
    if path == "track":  # counter-clockwise: the heading turns left (decreasing) overall
        yaw = np.unwrap(quat_to_euler(rec.truth.quat)[:, 2])
        # one lap; the last stride's direction differs from the first by less than a stride's turn
        assert yaw[-1] - yaw[0] == pytest.approx(-2 * np.pi, abs=2 * np.pi * 1.2 / 437.5)


def test_mixed_speeds_cover_walking_and_running():
    rec = simulate(path="mixed_speed")
    steps = rec.truth.steps
    speed = steps["stride_length"] / (steps["end"].diff().fillna(steps["end"].iloc[0] - steps["start"].iloc[0]))
    assert steps.shape[0] == 36
    assert speed.iloc[1:9].mean() == pytest.approx(0.85, abs=0.03)
    assert speed.iloc[28:].mean() == pytest.approx(3.2, abs=0.1)


def test_noise_model_is_eq_18_and_seeded():
    clean = simulate(n_strides=2)
    noise = NoiseModel(scale=1.0, biases=("gyr",), seed=3)
    a = simulate(n_strides=2, noise=noise)
    b = simulate(n_strides=2, noise=NoiseModel(scale=1.0, biases=("gyr",), seed=3))
    np.testing.assert_array_equal(a.acc, b.acc)
    e_acc, e_gyr = a.acc - clean.acc, a.gyr - clean.gyr
    assert e_acc.std() == pytest.approx(0.033, rel=0.05) and abs(e_acc.mean()) < 0.005
    assert e_gyr.mean() == pytest.approx(7.25e-6, abs=3e-4)
    assert e_gyr.std() == pytest.approx(0.0076, rel=0.05)
    biased = simulate(n_strides=2, noise=NoiseModel(scale=0.0, biases=("acc",)))
    np.testing.assert_allclose(biased.acc - clean.acc, 0.001 * 5 * 9.81)
    with pytest.raises(ValueError, match="unknown bias"):
        NoiseModel(biases=("accel",))


def test_magnetometer_and_disturbance():
    rec = simulate(n_strides=3, disturbance=MagneticDisturbance(north=(1.0, 3.0), east=(-1, 1)))
    field_n = quat_rotate(rec.truth.quat, rec.mag)
    inside = (rec.truth.pos[:, 0] >= 1.0) & (rec.truth.pos[:, 0] <= 3.0)
    incl = np.degrees(np.arctan2(field_n[~inside, 2], field_n[~inside, 0]))
    np.testing.assert_allclose(incl, 61.0, atol=1e-9)
    np.testing.assert_allclose(field_n[inside, 1], 0.25, atol=1e-9)


def test_distance_sensors_read_the_height_along_the_beam():
    ds = DistanceSensors(noise_var=0.0)
    rec = simulate(n_strides=3, profile="physical", distance_sensors=ds, rate=100.0)
    dist, true = rec.dist, rec.truth.dist
    has = ~np.isnan(dist[:, 0])
    assert has.sum() == pytest.approx(rec.t[-1] * 33.33, abs=2)
    # foot flat and level: each sensor sees the floor 6 cm below the IMU plus its own offset
    flat = rec.truth.stance & has
    np.testing.assert_allclose(true[flat, 0], 0.06 + 0.008, atol=1e-12)
    np.testing.assert_allclose(true[flat, 1], 0.06 + 0.006, atol=1e-12)
    # geometric check elsewhere: the beam's end point lies on the floor
    k = np.flatnonzero(has & np.isfinite(true[:, 0]))
    origin = rec.truth.pos[k] + quat_rotate(rec.truth.quat[k], ds.positions[0])
    end = origin + true[k, :1] * quat_rotate(rec.truth.quat[k], ds.directions[0])
    np.testing.assert_allclose(end[:, 2], 0.06, atol=1e-12)
    # beyond 20 cm the sensor reports its no-target value
    far = has & (true[:, 0] > 0.2)
    assert far.any() and np.all(dist[far, 0] == 0.255)


def test_pendulum_matches_eqs_11_to_13():
    rec = simulate_pendulum(period=2.0, sampling="instantaneous", rate=200.0, duration=10.0)
    q = rec.truth.quat
    th = quat_to_euler(q)[:, 1]
    L = rec.meta["length_m"]
    thd = rec.gyr[:, 1]
    thdd = np.gradient(thd, rec.t)
    ok = rec.t > 1.1
    np.testing.assert_allclose(rec.acc[ok, 0], L * thdd[ok] + 9.81 * np.sin(th[ok]), atol=0.05)
    np.testing.assert_allclose(rec.acc[:, 2], -L * thd**2 - 9.81 * np.cos(th), atol=1e-9)
    np.testing.assert_allclose(rec.gyr[:, [0, 2]], 0.0)
    beta = np.radians(61.0)
    np.testing.assert_allclose(rec.mag[:, 0], 0.48 * np.cos(beta + th), atol=1e-12)
    np.testing.assert_allclose(rec.mag[:, 2], 0.48 * np.sin(beta + th), atol=1e-12)
    # period about 2 s (small-angle; 30° amplitude lengthens it by ~1.7 %)
    crossings = np.flatnonzero(np.diff(np.sign(th[ok])) != 0)
    period = 2 * np.mean(np.diff(rec.t[ok][crossings]))
    assert period == pytest.approx(2.0 * 1.017, rel=0.01)


def test_quaternion_helpers_used_here():
    q = simulate(n_strides=1).truth.quat
    np.testing.assert_allclose(quat_mul(q, quat_conj(q))[:, 0], 1.0)


def test_cli_simulate_then_run_prints_metrics_against_the_truth(tmp_path, capsys):
    from footzoo.apps.cli import main
    from footzoo.io import load

    out = tmp_path / "walk.csv"
    assert main(["simulate", "rectangle", "--out", str(out), "--distance-sensors"]) == 0
    rec = load(out)
    assert rec.truth.closed_loop and rec.truth.steps is not None and rec.dist.shape[1] == 2
    assert rec.truth.dist is not None
    capsys.readouterr()
    assert main(["run", "yun2012", "--data", str(out)]) == 0
    text = capsys.readouterr().out
    assert "loop_closure_xy_m" in text and "armse_3d_m" in text


@pytest.mark.slow
def test_yun_reproduction_claims_hold_with_few_runs():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "reproduce_yun2012.py"
    spec = importlib.util.spec_from_file_location("reproduce_yun2012", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    tables = mod.reproduce(runs=3)
    pend = tables["pendulum"].set_index(["amplitude_deg", "k"])
    assert pend.loc[(2.5, 1.0), "pitch_err_max_deg"] < 1.0
    assert pend.loc[(2.5, 1.0), "roll_err_end_deg"] == pytest.approx(0.1, abs=0.02)  # b/k with b = 0.1 °/s
    assert pend.loc[(2.5, 0.0), "roll_err_end_deg"] > 3.0  # k = 0: drifts without bound
    assert pend.loc[(30.0, 50.0), "pitch_err_max_deg"] > 20.0  # k = 50: cannot follow the swing
    fig12 = tables["fig12"].set_index("noise_scale")
    assert fig12.loc[0.0, "end_err_max_pct"] < 1e-3  # an exact straight line
    assert fig12.loc[1.0, "end_err_max_pct"] < 0.1
    assert fig12.loc[0.1, "east_std_m"] < fig12.loc[1.0, "east_std_m"] < fig12.loc[10.0, "east_std_m"]
    fig13 = tables["fig13"].set_index("biases")
    assert abs(fig13.loc["acc+gyr+mag", "east_mean_m"]) > 5 * fig13.loc["acc+gyr+mag", "east_std_m"]  # one side
    assert tables["constant_gain"]["end_err_mean_pct"].iloc[0] == pytest.approx(13.6, abs=2.0)
