"""benchmarks/accuracy_events.py: its landmarks agree with footzoo's events; the heel marker on gaitmap's walk."""

import warnings

import numpy as np
import pytest

from footzoo.evaluation.metrics import match_strides, reference_steps
from footzoo.runtime.pipeline import Pipeline
from footzoo.sim import NoiseModel, simulate

from ..conftest import data_file, load_benchmark


@pytest.fixture(scope="module")
def events():
    return load_benchmark("accuracy_events")


def test_the_landmark_loop_finds_footzoos_events(events):
    """The benchmark's per-swing loop and the library's compiled searches: the same largest pitch to the rounding,
    the same TO to well under a millisecond (the loop takes half the peak sample, the library half the parabola's
    vertex); its IC column is the library's contact."""
    from footzoo.analysis.gait_events import detect_gait_events, sagittal_rate
    from footzoo.analysis.strides import real_stances

    rec = simulate(path="rectangle", length=10.0, width=5.0, rate=100.0, profile="physical", noise=NoiseModel(seed=0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = Pipeline.from_yaml("recommended").run(rec)
    marks = events.landmarks(rec, res)
    assert len(marks) == len(res.steps) == 24
    pos = res.samples[["pos_n", "pos_e", "pos_d"]].to_numpy()
    st = real_stances(res.samples["stance"].to_numpy(bool), pos)
    quat = res.samples[["qw", "qx", "qy", "qz"]].to_numpy()
    ev = detect_gait_events(rec.t, sagittal_rate(quat, rec.gyr, pos, st), st, rec.acc, quat)
    np.testing.assert_allclose(marks["largest pitch (zero crossing)"], ev.largest_pitch, atol=1e-9)
    np.testing.assert_allclose(marks["contact (IC)"], res.steps["end_s"], atol=1e-9)
    np.testing.assert_allclose(marks["half-way back (TO)"], res.steps["to_s"], atol=5e-4)
    # against the truth: the landmarks' offsets are the events' errors with the sign turned
    offsets = events._offsets(marks, reference_steps(rec.truth.steps))
    m = match_strides(res.steps, reference_steps(rec.truth.steps))
    assert np.median(offsets["contact (IC)"]) == pytest.approx(-np.median(m["est_end_s"] - m["end_s"]), abs=1e-9)
    # the simulated toe leaves before the rate's zero crossing; the heel lands at the largest pitch, without an
    # impact, so the contact rule finds the loading response a few milliseconds later (measured 5.4 ms)
    assert np.median(offsets["zero crossing after it"]) < -0.005
    assert abs(np.median(offsets["largest pitch (zero crossing)"])) < 0.002
    assert -0.010 <= np.median(offsets["contact (IC)"]) < 0.0


def test_gaitmaps_heel_touches_down_about_20_ms_after_the_motion_capture_ic(events):
    folder = data_file("gaitmap_example", "mocap_sample.csv").parent
    heel = events.heel_marker(folder.parent)
    assert len(heel) == 57  # every stride's IC of both feet
    med = heel.median(numeric_only=True)
    # measured: the foot's pitch largest 1 ms before the IC; the heel marker there moves forward at 1.3 m/s,
    # descends fastest 12 ms after it at 0.29 m/s, stops 22 ms after it, slower than 0.5 m/s 22 ms after it
    assert abs(med["largest pitch (ms)"]) <= 5
    assert med["horizontal speed at IC (m/s)"] > 1.0
    assert 5 <= med["fastest descent (ms)"] <= 20 and med["speed (m/s)"] > 0.2
    assert 15 <= med["stopped (ms)"] <= 30 and 15 <= med["below 0.5 m/s (ms)"] <= 30


def test_the_motion_capture_reference_takes_ic_from_the_heel_marker(events):
    """The reader's contact (the heel marker's touch-down) lies where `heel_marker` finds the descent stopping, about
    20 ms after the event file's IC, which is kept as the largest pitch."""
    from footzoo.io.gaitmap_reference import reference_strides

    folder = data_file("gaitmap_example", "imu_sample.csv").parent
    for foot in ("left", "right"):
        ref = reference_strides(folder, foot)
        late = 1e3 * (ref["end_s"] - ref["largest_pitch_s"])
        assert 15 <= np.median(late) <= 30  # measured 23 / 21 ms
