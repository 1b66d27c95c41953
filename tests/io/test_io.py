"""Readers convert every format once to FRD/SI (real files; skipped when ../shared/data is absent)."""

import numpy as np
import pytest

from footzoo import FormatError, Pipeline, RecordingError
from footzoo.evaluation.metrics import armse, rotate_about_vertical
from footzoo.io import builtin_sample, detect_format, load
from footzoo.io.canonical import write

from ..conftest import GAPS_BRIDGED, data_file

G = 9.81


def still_mean(rec, seconds=0.5):
    w = rec.t < rec.t[0] + seconds
    return rec.acc[w].mean(axis=0), np.abs(rec.gyr[w]).max()


def assert_still_foot(rec, max_tilt_deg):
    f, w = still_mean(rec)
    assert np.linalg.norm(f) == pytest.approx(G, rel=0.03)
    assert w < 0.05  # rad/s
    # z is down: gravity's reading points along -z within the sensor's mounting tilt
    tilt = np.degrees(np.arccos(-f[2] / np.linalg.norm(f)))
    assert tilt < max_tilt_deg


def test_pyshoe_reads_frd_si_and_a_mirrored_reference():
    rec = load(data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat"))
    assert detect_format(data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat")) == "pyshoe"
    assert_still_foot(rec, max_tilt_deg=20)
    assert rec.rate == pytest.approx(200.0, rel=0.01)
    assert rec.meta["pyshoe_trial_error"]["shoe"] == pytest.approx(0.032)


def test_pyshoe_reference_and_estimate_agree_in_handedness():
    rec = load(data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat"))
    res = Pipeline.from_yaml("yun2012").run(rec)
    est, ref = res.pos[:, :2], rec.truth.pos[:, :2]
    z = np.zeros((len(est), 1))
    proper = armse(np.hstack([est, z]), np.hstack([ref, z]))
    # the same reference mirrored (east negated), as if the reader had not converted it
    mirrored = armse(np.hstack([est, z]), np.hstack([ref * [1, -1], z]))
    assert proper < 0.15 < 3 * proper < mirrored


# x-io's walk has gaps in its time stamps, which the reader bridges (expected warning)
@pytest.mark.filterwarnings(GAPS_BRIDGED)
def test_xio_reads_g_and_deg_s_with_duplicates_dropped():
    path = data_file("xio_gait_tracking", "short_walk.csv")
    assert detect_format(path) == "xio"
    with pytest.warns(UserWarning, match=r"dropped \d+ row\(s\)"):
        rec = load(path)
    assert_still_foot(rec, max_tilt_deg=35)  # the NGIMU sits about 30° tilted on the foot
    assert rec.truth.closed_loop
    with pytest.raises(RecordingError, match="duplicate time stamp"):
        load(path, duplicates="error")


@pytest.mark.parametrize("foot", ["left", "right"])
def test_gaitmap_feet_convert_to_frd(foot):
    path = data_file("gaitmap_example", "imu_sample.csv")
    assert detect_format(path) == "gaitmap"
    rec = load(path, foot=foot)
    assert_still_foot(rec, max_tilt_deg=20)
    assert rec.rate == pytest.approx(204.8)


@pytest.mark.parametrize("foot", ["left", "right"])
def test_gaitmap_feet_turn_like_the_markers(foot):
    """Handedness: the estimated walk turns the same way as the motion-capture heel marker."""
    from footzoo.evaluation.metrics import match_strides
    from footzoo.io.gaitmap_reference import reference_strides

    folder = data_file("gaitmap_example", "imu_sample.csv").parent
    rec = load(folder / "imu_sample.csv", foot=foot)
    res = Pipeline.from_yaml("yun2012").run(rec)
    m = match_strides(res.steps, reference_strides(folder, foot))
    ref_turn = np.unwrap(m["heading_rad"].to_numpy())  # lab frame, z up: counter-clockwise positive
    est_turn = np.unwrap(m["est_heading_rad"].to_numpy())  # NED: clockwise seen from above positive
    assert abs(ref_turn[-1] - ref_turn[0]) > np.radians(150)
    assert np.sign(est_turn[-1] - est_turn[0]) == -np.sign(ref_turn[-1] - ref_turn[0])


def test_gaitmap_needs_a_foot():
    with pytest.raises(FormatError, match="choose one with foot='left' or foot='right'"):
        load(data_file("gaitmap_example", "imu_sample.csv"))


def test_sensorconnect_reads_g_rad_s_and_gauss():
    path = data_file("koroglu_gcp", "SensorConnectData_31.csv")
    assert detect_format(path) == "sensorconnect"
    rec = load(path)
    f, _ = still_mean(rec)
    assert np.linalg.norm(f) == pytest.approx(G, rel=0.03)
    assert f[2] < 0
    assert rec.mag is not None and 0.2 < np.linalg.norm(rec.mag[0]) < 0.7  # Gauss


def test_builtin_sample_is_the_xio_walk():
    rec = builtin_sample()
    assert rec.n > 16000 and rec.truth.closed_loop
    assert_still_foot(rec, max_tilt_deg=35)


# x-io's walk has gaps in its time stamps, which the reader bridges (expected warning)
@pytest.mark.filterwarnings(GAPS_BRIDGED)
def test_canonical_round_trip_csv_and_parquet(tmp_path):
    rec = builtin_sample()
    for name in ("walk.csv", "walk.parquet"):
        p = write(rec, tmp_path / name, closed_loop=True)
        back = load(p)
        np.testing.assert_allclose(back.acc, rec.acc, rtol=1e-8)
        np.testing.assert_allclose(back.gyr, rec.gyr, rtol=1e-8)
        assert back.truth is None or back.truth.closed_loop


def test_unreadable_inputs(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    with pytest.raises(FormatError, match="empty"):
        load(empty)
    odd = tmp_path / "odd.csv"
    odd.write_text("a,b,c\n1,2,3\n")
    with pytest.raises(FormatError, match="cannot tell the format"):
        load(odd)
    with pytest.raises(FormatError, match="no such file"):
        load(tmp_path / "missing.csv")
    with pytest.raises(FormatError, match=r"unknown format 'xoi' \(did you mean 'xio'\?\)"):
        load(odd, format="xoi")


# x-io's walk has gaps in its time stamps, which the reader bridges (expected warning)
@pytest.mark.filterwarnings(GAPS_BRIDGED)
def test_canonical_in_g_needs_a_declared_unit(tmp_path):
    rec = builtin_sample()
    df = rec.to_dataframe()
    df[["acc_x", "acc_y", "acc_z"]] /= G
    p = tmp_path / "g.csv"
    df.to_csv(p, index=False)
    with pytest.raises(RecordingError, match="acc_unit: g"):
        load(p)
    assert load(p, acc_unit="g").n == rec.n


def test_rotation_helper_used_by_the_handedness_test():
    p = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    np.testing.assert_allclose(rotate_about_vertical(p, np.pi / 2)[1], [0, 1, 0], atol=1e-12)


def test_a_matlab_file_of_another_layout_is_told_the_python_route(tmp_path):
    """No description format reads a .mat file: the message gives the route that works, not a sidecar."""
    import scipy.io

    from footzoo.sim import simulate

    walk = simulate(n_strides=2, rate=50.0)
    p = tmp_path / "lab.mat"
    scipy.io.savemat(p, {"accel": walk.acc, "gyro": walk.gyr, "time": walk.t})
    for options in ({}, {"format": "pyshoe"}):
        with pytest.raises(FormatError) as err:
            load(p, **options)
        text = str(err.value)
        assert "accel" in text and "scipy.io.loadmat" in text and "Recording.from_dataframe" in text, text
        assert "lab.mat.footzoo.yaml" not in text, text  # no sidecar reads a binary file
