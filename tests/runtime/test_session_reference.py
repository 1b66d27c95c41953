"""Two-foot sessions, the references readers load, Result.metrics, and the command line around them."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pandas as pd
import pytest

from footzoo import Pipeline, Recording, Session
from footzoo.apps.cli import main
from footzoo.core.errors import FootzooWarning, FormatError
from footzoo.evaluation.metrics import footprint_errors, rigid_align_2d
from footzoo.io import load
from footzoo.io.canonical import write
from footzoo.runtime.session import step_times
from footzoo.sim import NoiseModel, simulate

from ..conftest import HARD_IRON_NOT_FITTED, KOROGLU_MOUNTING, data_file

YUN = "yun2012"


def test_step_time_and_symmetry_index_by_hand():
    left = pd.DataFrame({"start_s": [np.nan, 1.0, 2.0], "end_s": [1.0, 2.0, 3.0]})
    right = pd.DataFrame({"start_s": [np.nan, 1.4, 2.4], "end_s": [1.4, 2.4, 3.4]})
    st = step_times({"left": left, "right": right})
    # left lands 0.6 s after right, right 0.4 s after left; the first left contact has no right one before it
    np.testing.assert_allclose(st["left"], [np.nan, 0.6, 0.6])
    np.testing.assert_allclose(st["right"], [np.nan, 0.4, 0.4])


@pytest.fixture(scope="module")
def gaitmap_session():
    path = data_file("gaitmap_example", "imu_sample.csv")
    session = Session.load(path)
    return session, session.run(Pipeline.from_yaml(YUN))


def test_gaitmap_session_runs_both_feet_with_bilateral_tables(gaitmap_session):
    session, res = gaitmap_session
    assert set(session.recordings) == {"left", "right"}
    steps = res.steps
    assert set(steps["foot"]) == {"left", "right"} and "step_time_s" in steps
    # a left step and the right step after it make one stride
    both = steps.dropna(subset=["step_time_s", "stride_time_s"])
    assert len(both) > 40
    bil = res.bilateral
    left, right = bil.loc["step_time_s", "left"], bil.loc["step_time_s", "right"]
    assert left + right == pytest.approx(bil.loc["stride_time_s", ["left", "right"]].mean(), rel=0.03)
    si = 100 * abs(bil.loc["stride_length_m", "left"] - bil.loc["stride_length_m", "right"]) / (
        0.5 * (bil.loc["stride_length_m", "left"] + bil.loc["stride_length_m", "right"]))
    assert bil.loc["stride_length_m", "symmetry_index_pct"] == pytest.approx(si)
    per_foot = res.per_foot
    assert list(per_foot.index) == ["left", "right"]
    # IC against the heel marker's touch-down: measured 5.4 / 4.6 ms
    assert (per_foot["ic_error_median_abs_s"] <= 0.01).all()


def test_cli_runs_both_feet_of_a_gaitmap_file(tmp_path, capsys):
    path = data_file("gaitmap_example", "imu_sample.csv")
    assert main(["run", YUN, "--data", str(path), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "imu_sample_left" in out and "imu_sample_right" in out and "symmetry_index_pct" in out
    for name in ("left/steps.csv", "right/steps.csv", "left/metrics.json", "steps.csv", "bilateral.csv"):
        assert (tmp_path / name).stat().st_size > 0
    assert main(["run", YUN, "--data", str(path), "--foot", "left"]) == 0
    out = capsys.readouterr().out
    assert "imu_sample_left" in out and "imu_sample_right" not in out


def test_a_one_foot_file_is_not_a_session(tmp_path, capsys):
    path = data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat")
    with pytest.raises(FormatError, match="holds one foot"):
        Session.load(path)
    assert main(["run", YUN, "--data", str(path), "--foot", "both"]) == 3  # a data error
    assert "--foot both needs a gaitmap file" in capsys.readouterr().err


def test_gaitmap_stride_paths_against_motion_capture(gaitmap_session):
    from footzoo.evaluation.metrics import stride_path_errors

    session, res = gaitmap_session
    for foot in ("left", "right"):
        truth = session.recordings[foot].truth
        assert truth.stride_positions is not None
        r = res.results[foot]
        m = r.metrics
        # measured with yun2012 0.046 m (left), 0.053 m (right): mostly the instep sensor against the heel
        # marker; 25 and 26 straight strides
        assert m["stride_path_rms_error_median_m"] < 0.08 and m["stride_paths"] >= 25
        # with up and down swapped the paths do not fit (measured 0.16 m): the z-up conversion is right.
        # (A left-right mirror is hardly visible on straight strides: 0.063 m.)
        t = r.samples["t"].to_numpy()
        worse = stride_path_errors(t, r.pos * [1.0, 1.0, -1.0], truth.stride_positions, truth.steps["turn"].to_numpy())
        assert worse["stride_path_rms_error_median_m"] > 2 * m["stride_path_rms_error_median_m"]


# ----------------------------------------------------------------------------- PyShoe


def test_pyshoe_trial_knows_its_foot_and_hand_counted_strides(capsys):
    path = data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat")
    rec = load(path)
    table = pd.read_csv(path.with_name("trials.csv"), dtype={"trial": str}).set_index("trial")
    assert rec.meta["foot"] == "right"
    assert rec.truth.stride_count == table.loc[path.stem, "n_strides_manual_koroglu"]
    m = Pipeline.from_yaml(YUN).run(rec).metrics
    assert m["stride_count_error"] == 0  # measured: 22 of 22
    assert 80 < m["median_cadence_steps_min"] < 130  # was 29/min with the standing in the first stride
    # --foot right agrees with the file; --foot left is refused with the reason, not a TypeError
    assert main(["run", YUN, "--data", str(path), "--foot", "right"]) == 0
    assert "stride_count_error" in capsys.readouterr().out
    assert main(["run", YUN, "--data", str(path), "--foot", "left"]) == 3  # a data error
    assert "from the right foot" in capsys.readouterr().err


# ----------------------------------------------------------------------------- Köroğlu


# indoors, the magnetometer's readings lie on no sphere: no hard-iron fit (expected warning)
# the mounting report finds the sensor's x axis pointing backwards (expected warning)
@pytest.mark.filterwarnings(KOROGLU_MOUNTING)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_koroglu_footprints_and_stride_count():
    import scipy.io as sio

    path = data_file("koroglu_gcp", "SensorConnectData_31.csv")
    ref = sio.loadmat(path.with_suffix(".mat"))
    rec = load(path)
    assert rec.truth.stride_count == int(ref["numberOfStrides"][0, 0]) == 33
    np.testing.assert_array_equal(rec.truth.footprints, ref["GCP_meters"])
    m = Pipeline.from_yaml(YUN).run(rec).metrics
    assert m["stride_count_error"] == 0  # measured: 33 of 33
    assert m["footprints_est"] == m["footprints_ref"] == 34
    assert m["footprint_error_mean_m"] < 1.0  # measured 0.45 m after the rigid alignment


def test_rigid_alignment_undoes_a_rotation_a_shift_and_a_reflection():
    rng = np.random.default_rng(3)
    est = rng.normal(size=(20, 2)) * 5
    c, s = np.cos(0.7), np.sin(0.7)
    ref = est @ np.array([[c, -s], [s, c]]).T + [3.0, -2.0]
    aligned, mirrored = rigid_align_2d(est, ref)
    np.testing.assert_allclose(aligned, ref, atol=1e-9)
    assert not mirrored
    aligned, mirrored = rigid_align_2d(est, ref * [1.0, -1.0])
    np.testing.assert_allclose(aligned, ref * [1.0, -1.0], atol=1e-9)
    assert mirrored


def test_footprint_errors_need_equal_counts():
    steps = pd.DataFrame({"start_n_m": [0.0, 1.0], "start_e_m": [0.0, 0.0], "end_n_m": [1.0, 2.1],
                          "end_e_m": [0.0, 0.0]})
    e = footprint_errors(steps, np.array([[0.0, 0.0], [0.0, 1.0], [0.0, 2.0]]))
    # rotated onto the reference: errors are the residual of 0, 1, 2.1 against 0, 1, 2 after centring
    resid = np.array([0, 1, 2.1]) - np.mean([0, 1, 2.1]) - (np.array([0, 1, 2.0]) - 1.0)
    assert e["footprint_error_rms_m"] == pytest.approx(np.sqrt(np.mean(resid**2)))
    short = footprint_errors(steps, np.zeros((5, 2)))
    assert "footprint_error_rms_m" not in short and short["footprints_est"] == 3


# ----------------------------------------------------------------------------- simulator truth


def test_readme_simulator_example_reports_errors_against_the_truth(tmp_path, capsys):
    walk = tmp_path / "walk.csv"
    assert main(["simulate", "rectangle", "--out", str(walk)]) == 0
    capsys.readouterr()
    assert main(["run", YUN, "--data", str(walk), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    for key in ("stride_count_error", "armse_3d_m", "loop_closure_xy_m", "ic_error_median_abs_s",
                "stride_length_rms_error_m", "reference: simulator"):
        assert key in out
    metrics = json.loads((tmp_path / "out" / "metrics.json").read_text())["metrics"]
    assert metrics["stride_count_ref"] == 100 and metrics["stride_count_error"] == 0
    steps = pd.read_csv(tmp_path / "out" / "steps.csv")
    assert {"stride_length_m", "heading_rad", "stride_time_s", "cadence_steps_min"} <= set(steps.columns)


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_result_metrics_against_the_simulator_truth():
    rec = simulate(n_strides=20, rate=100.0, noise=NoiseModel(seed=2))
    res = Pipeline.from_yaml(YUN).run(rec)
    assert res.reference is rec.truth
    m = res.metrics
    assert m["strides"] == 20 and m["stride_count_ref"] == 20 and m["matched_strides"] == 20
    assert m["median_stride_time_s"] == pytest.approx(1.0, abs=0.01)
    assert m["median_stride_length_m"] == pytest.approx(1.2, rel=0.01)
    assert m["stride_length_rms_error_m"] < 0.01  # measured 0.0017 m
    assert m["ic_error_median_abs_s"] < 0.005  # measured 1.5 ms


def test_canonical_file_keeps_the_truth_strides(tmp_path):
    rec = simulate(n_strides=5, rate=50.0)
    back = load(write(rec, tmp_path / "walk.csv"))
    assert back.truth.stride_count == 5 and back.truth.source == "simulator"
    assert len(back.truth.steps) == 5


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_short_reprs():
    rec = simulate(n_strides=3, rate=50.0)
    text = repr(rec)
    assert text.startswith("Recording('sim_straight', n=") and "rate=50.0 Hz" in text and "duration=" in text
    assert "channels=['acc', 'gyr', 'mag']" in text and "array" not in text and len(text) < 300
    res = Pipeline.from_yaml(YUN).run(rec)
    assert "array" not in repr(res) and len(repr(res)) < 200


def test_two_feet_on_different_clocks_are_warned_and_one_clock_is_not():
    """Step times pair one foot's contact with the other's: an hour apart they were NaN without a word."""
    walk = simulate(n_strides=3, rate=100.0)
    later = Recording(t=walk.t + 3600.0, acc=walk.acc, gyr=walk.gyr)
    with pytest.warns(FootzooWarning, match=r"session: the left foot's recording spans t = 0–5.99 s and the right "
                                            r"foot's 3600–3605.99 s, overlapping 0 s: the two are not on one clock"):
        Session({"left": walk, "right": later})
    with warnings.catch_warnings():
        warnings.simplefilter("error", FootzooWarning)
        Session({"left": walk, "right": Recording(t=walk.t + 0.5, acc=walk.acc, gyr=walk.gyr)})


def test_a_list_of_recordings_is_keyed_by_the_foot_each_names():
    """IPOL's `_lf` / `_rf` files each name their foot: a list of the two was refused with the recordings' reprs."""
    t = np.arange(300) / 100.0
    acc, gyr = np.tile([0.0, 0.0, -9.81], (300, 1)), np.zeros((300, 3))
    left = Recording(t=t, acc=acc, gyr=gyr, meta={"name": "walk_lf", "foot": "left"})
    right = Recording(t=t, acc=acc, gyr=gyr, meta={"name": "walk_rf", "foot": "right"})
    session = Session([right, left])
    assert session.recordings == {"right": right, "left": left}
    with pytest.raises(FormatError, match=r"session\[1\] \('walk_lf'\) is a second left foot \(with 'walk_lf'\)"):
        Session([left, left])
    unnamed = Recording(t=left.t, acc=left.acc, gyr=left.gyr)
    with pytest.raises(FormatError, match=r"session\[0\] \('recording'\) names no foot \(meta\['foot'\] is None\): "
                                          r".*give Session\(\{'left': rec_l, 'right': rec_r\}\)"):
        Session([unnamed, right])
    with pytest.raises(FormatError, match=r"got the keys \['l'\]: give Session\(\{'left'"):
        Session({"l": left})


def test_footprint_errors_with_a_footprint_not_measured_or_a_run_that_diverged_compare_nothing():
    """NaN in either set defines no alignment (the SVD would fail): the counts are kept, no error is given."""
    steps = pd.DataFrame({"start_n_m": [0.0, 1.0], "start_e_m": [0.0, 0.0], "end_n_m": [1.0, 2.1],
                          "end_e_m": [0.0, 0.0]})
    e = footprint_errors(steps, np.array([[0.0, 0.0], [np.nan, 1.0], [0.0, 2.0]]))
    assert e == {"footprints_ref": 3.0, "footprints_est": 3.0}
    diverged = steps.assign(end_n_m=[1.0, np.inf])
    assert "footprint_error_rms_m" not in footprint_errors(diverged, np.array([[0.0, 0.0], [0.0, 1.0], [0.0, 2.0]]))
