"""Gait events and strides that do not depend on the sensor's mounting; wrong axis maps named with their fix."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

from footzoo.analysis.gait_events import sagittal_rate, travel_directions
from footzoo.analysis.mounting import mounting_report, nearest_axis_map, swing_correlation, warn_mounting
from footzoo.core.conventions import quat_from_euler, quat_rotate
from footzoo.core.errors import SensorWarning
from footzoo.evaluation.metrics import event_stance_mask, gait_phase_errors, match_strides, reference_steps
from footzoo.runtime.pipeline import Pipeline
from footzoo.sim import NoiseModel, axis_map_name, proper_axis_permutations, remount, simulate

from ..conftest import data_file

CONFIG = "recommended"


def _run(rec):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = Pipeline.from_yaml(CONFIG).run(rec)
    return res, [w for w in caught if issubclass(w.category, SensorWarning)]


def test_sagittal_rate_of_a_level_foot_is_the_rate_about_the_axis_right_of_travel():
    # hand-derived: the foot turns at 2 rad/s about north and 1 rad/s about east (NED). Walking north
    # the axis right of travel is east (ω_ml = 1), walking east it is south (ω_ml = −2). A level sensor
    # aligned with north (C = I) reads (2, 1, 0); one turned a quarter about down (x east, y south)
    # reads (1, −2, 0) for the same motion, and gives the same ω_ml.
    n = 40
    stances = np.array([[0, 5], [15, 25], [35, 40]])  # middles 2, 19, 37
    pos = np.zeros((n, 3))
    pos[10:, 0] = 1.0  # stride 0 (samples before 19) goes 1 m north
    pos[30:, 1] = 1.0  # stride 1 (from 19 on) goes 1 m east
    w = sagittal_rate(np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)), np.tile([2.0, 1.0, 0.0], (n, 1)), pos, stances)
    assert np.array_equal(w[:19], np.ones(19)) and np.array_equal(w[19:], np.full(n - 19, -2.0))
    q = np.tile(quat_from_euler(0.0, 0.0, np.pi / 2), (n, 1))
    body = np.tile([1.0, -2.0, 0.0], (n, 1))
    assert np.allclose(quat_rotate(q[0], body[0]), [2.0, 1.0, 0.0])
    assert np.allclose(sagittal_rate(q, body, pos, stances), w, rtol=0, atol=1e-12)


def test_compiled_sagittal_rate_equals_the_array_formula():
    rng = np.random.default_rng(4)
    n = 500
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    gyr, pos = rng.normal(size=(n, 3)), np.cumsum(rng.normal(size=(n, 3)), axis=0)
    stances = np.array([[0, 30], [90, 130], [200, 220], [220, 260], [400, 500]])  # two touching stances
    d, _ = travel_directions(pos, stances)
    w_n = quat_rotate(q, gyr)
    assert np.allclose(sagittal_rate(q, gyr, pos, stances), -w_n[:, 0] * d[:, 1] + w_n[:, 1] * d[:, 0],
                       rtol=0, atol=1e-12)


@pytest.fixture(scope="module")
def walk():
    return simulate(path="rectangle", length=10.0, width=5.0, rate=100.0, profile="physical",
                    noise=NoiseModel(seed=1), magnetometer=False)


def test_the_24_proper_axis_permutations_are_the_rotations_of_a_cube():
    perms = proper_axis_permutations()
    assert len(perms) == 24 and np.array_equal(perms[0], np.eye(3))
    assert len({axis_map_name(p) for p in perms}) == 24
    for p in perms:
        np.testing.assert_allclose(p @ p.T, np.eye(3))
        assert np.linalg.det(p) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="mirror"):
        remount(simulate(n_strides=2, rate=50.0), np.diag([1.0, 1.0, -1.0]))


def test_remount_turns_the_readings_not_the_motion(walk):
    m = proper_axis_permutations()[7]
    rec = remount(walk, m)
    # v_body = m · v_sensor: the turned readings rotated back are the original ones
    np.testing.assert_allclose(rec.gyr @ m.T, walk.gyr, atol=1e-12)
    np.testing.assert_allclose(rec.acc @ m.T, walk.acc, atol=1e-12)
    np.testing.assert_array_equal(rec.truth.pos, walk.truth.pos)


@pytest.mark.slow
def test_events_and_strides_are_the_same_for_every_mounting(walk):
    """24 proper axis permutations of one simulated walk: the same strides and events (target ≤ 10 ms)."""
    ref = reference_steps(walk.truth.steps)
    base = None
    for m in proper_axis_permutations():
        steps = _run(remount(walk, m))[0].steps
        assert len(match_strides(steps, ref)) == len(ref), axis_map_name(m)
        if base is None:
            base = steps
            continue
        assert len(steps) == len(base), axis_map_name(m)
        # measured: 0 ms (the whole pipeline turns with the sensor; only rounding differs)
        np.testing.assert_allclose(steps["to_s"], base["to_s"], atol=0.010, err_msg=axis_map_name(m))
        np.testing.assert_allclose(steps["end_s"], base["end_s"], atol=0.010, err_msg=axis_map_name(m))
        np.testing.assert_allclose(steps["stride_length_m"], base["stride_length_m"], atol=0.005)


@pytest.mark.parametrize("name, backwards, reversed_pitch", [
    ("[x, y, z]", False, False), ("[x, -y, -z]", False, True), ("[-x, y, -z]", True, False),
    ("[-x, -y, z]", True, True),
])
def test_a_walk_backwards_or_a_reversed_pitch_is_named_with_its_fix(walk, name, backwards, reversed_pitch):
    m = next(p for p in proper_axis_permutations() if axis_map_name(p) == name)
    res, warned = _run(remount(walk, m))
    rep = res.diagnostics["mounting"]
    assert rep["walks_backwards"] is backwards and rep["pitch_reversed"] is reversed_pitch
    # the fix is the map that undoes the turn: v_FRD = m · v_sensor
    assert rep["suggested_axes"] == name
    np.testing.assert_allclose(rep["sensor_in_foot"], m, atol=0.05)
    assert bool(warned) is (backwards or reversed_pitch)
    if warned:
        text = str(warned[0].message)
        assert name in text and "diagnostics['mounting']" in text
        assert f"--option 'axes={name}'" in text and f'footzoo.load(path, axes="{name}")' in text
        assert ("walks backwards" in text) is backwards and ("toe lifts" in text) is reversed_pitch


def test_the_fix_is_composed_with_the_axis_map_the_file_was_read_with():
    rep = {"walks_backwards": True, "x_forward": -1.0, "pitch_reversed": True, "y_right": -1.0,
           "suggested_axes": "[-x, -y, z]"}
    with pytest.warns(SensorWarning, match=r"axis map \[-x, y, -z\].*--option 'axes=\[-x, y, -z\]'"):
        warn_mounting(rep, "r", axes="[x, -y, -z]")


def test_no_mounting_estimate_from_too_few_strides():
    rep = mounting_report(np.tile([1.0, 0, 0, 0], (300, 1)), np.zeros((300, 3)), np.zeros((300, 3)),
                          np.array([[0, 100], [150, 300]]))
    assert rep == {"strides": 1}  # too few strides: no estimate
    assert nearest_axis_map(np.full((3, 3), 1 / np.sqrt(3))) is None


def test_gait_phases_from_events_against_a_hand_made_reference():
    t = np.arange(0.0, 4.0, 0.01)
    ref = pd.DataFrame({"to_s": [0.5, 1.5, 2.5], "end_s": [0.9, 1.9, 2.9]})
    np.testing.assert_array_equal(event_stance_mask(t, ref["to_s"], ref["end_s"])[[49, 50, 89, 90]],
                                  [True, False, False, True])
    e = gait_phase_errors(t, ref.assign(to_s=ref["to_s"] + 0.02), ref, margin=0.305)
    assert e["gait_phase_error_rate"] == 0.0 and e["stance_phases"] == 4
    # scored from 0.2 s to 3.2 s: 3 × 2 samples of 300 differ
    assert e["gait_phase_sample_error"] == pytest.approx(6 / 301, abs=1e-9)
    # a missed swing merges two stance phases: two reference stance phases are wrong
    e = gait_phase_errors(t, ref.iloc[[0, 2]], ref)
    assert e["gait_phase_error_rate"] == pytest.approx(2 / 4)


# ----------------------------------------------------------------------------- gaitmap example


@pytest.mark.parametrize("foot", ["left", "right"])
def test_gaitmap_events_and_gait_phases_against_motion_capture(foot):
    from footzoo.io import load

    rec = load(data_file("gaitmap_example", "imu_sample.csv"), foot=foot)
    res, warned = _run(rec)
    assert not warned and not res.diagnostics["mounting"]["walks_backwards"]
    m = res.metrics
    # target 10 ms; measured (left / right): IC against the heel marker's touch-down 5.4 / 4.6 ms, TO 8.0 / 8.2 ms,
    # the largest pitch against the event file's IC (the foot's largest pitch) 2.5 / 4.3 ms
    assert m["ic_error_median_abs_s"] <= 0.010
    assert m["largest_pitch_error_median_abs_s"] <= 0.010
    assert m["to_error_median_abs_s"] <= 0.010
    g = gait_phase_errors(rec.t, res.steps, rec.truth.steps)
    # measured: 0 wrong stance phases of 29 / 30, 1.1 % of the samples in the wrong phase; target 3 % (Nguyen & La)
    assert g["gait_phase_error_rate"] <= 0.03
    assert g["gait_phase_sample_error"] <= 0.03


@pytest.mark.parametrize("name", ["[-x, -y, z]", "[x, -y, -z]", "[y, -x, z]"])
def test_gaitmap_read_with_a_wrong_right_handed_map(name):
    """The real recording through a wrong map: the same events; the reversed ones warned with the fix."""
    from footzoo.io import load

    rec = load(data_file("gaitmap_example", "imu_sample.csv"), foot="left")
    m = next(p for p in proper_axis_permutations() if axis_map_name(p) == name)
    base = _run(rec)[0].steps
    res, warned = _run(remount(rec, m))
    assert len(res.steps) == len(base)
    np.testing.assert_allclose(res.steps["to_s"], base["to_s"], atol=0.010)
    np.testing.assert_allclose(res.steps["end_s"], base["end_s"], atol=0.010)
    rep = res.diagnostics["mounting"]
    assert rep["suggested_axes"] == name
    flagged = rep["walks_backwards"] or rep["pitch_reversed"] or rep["x_across"]
    assert flagged  # a sensor turned 90° about z ([y, -x, z]): its x points left, across the direction of travel
    assert rep["x_across"] is (name == "[y, -x, z]")
    assert bool(warned) is flagged


def test_pyshoe_upside_down_trial_is_named():
    from footzoo.io import load

    rec = load(data_file("pyshoe_vicon", "2018-02-22-10-09-36.mat"))
    res, warned = _run(rec)
    rep = res.diagnostics["mounting"]
    assert rep["pitch_reversed"] and not rep["walks_backwards"]
    assert rep["suggested_axes"] == "[x, -y, -z]" and warned
    steps = res.steps
    assert len(steps) > 5 and steps["events_from_rate"].mean() > 0.9
    # the fix the warning names is an option the reader takes: read so, the trial has its pitch right
    text = str(warned[0].message)
    assert "--option 'axes=[x, -y, -z]'" in text and 'footzoo.load(path, axes="[x, -y, -z]")' in text
    fixed = load(data_file("pyshoe_vicon", "2018-02-22-10-09-36.mat"), axes="[x, -y, -z]")
    res, warned = _run(fixed)
    assert not res.diagnostics["mounting"]["pitch_reversed"] and not warned
    assert res.diagnostics["mounting"]["suggested_axes"] == "[x, y, z]"


def test_the_swing_correlation_is_numpys_over_the_swing_samples():
    """The pitch-rate correlation of the mounting report, computed over the swings in one compiled pass,
    against ``np.corrcoef`` of the samples the swings select (and NaN where there is nothing to correlate)."""
    rng = np.random.default_rng(4)
    for _ in range(50):
        n = int(rng.integers(20, 2000))
        gyr = rng.normal(size=(n, 3))
        w = 0.4 * gyr[:, 1] + rng.normal(size=n) * rng.random()
        cuts = np.sort(rng.choice(n + 1, size=2 * int(rng.integers(1, 6)), replace=False))
        lo, hi = cuts[0::2], cuts[1::2]
        mask = np.zeros(n, bool)
        for a, b in zip(lo, hi, strict=True):
            mask[a:b] = True
        got = swing_correlation(gyr, w, lo.astype(np.int64), hi.astype(np.int64))
        if mask.sum() > 2:
            assert abs(got - np.corrcoef(gyr[mask, 1], w[mask])[0, 1]) < 1e-13
        else:
            assert np.isnan(got)
    gyr = np.zeros((10, 3))
    assert np.isnan(swing_correlation(gyr, np.arange(10.0), np.array([0]), np.array([10])))  # constant gyr_y
    gyr[:, 1] = np.arange(10.0)
    assert abs(swing_correlation(gyr, -2.0 * np.arange(10.0), np.array([0, 6]), np.array([4, 10])) + 1.0) < 1e-15


@pytest.mark.parametrize("name", ["[y, -z, -x]", "[y, -x, z]"])
def test_an_x_axis_across_the_direction_of_travel_is_named_with_its_fix(walk, name):
    """An axis map that takes a vertical or sideways sensor axis for x: flagged, with the map that undoes it."""
    m = next(p for p in proper_axis_permutations() if axis_map_name(p) == name)
    res, warned = _run(remount(walk, m))
    rep = res.diagnostics["mounting"]
    assert rep["x_across"] and abs(rep["x_forward"]) < 0.1 and rep["suggested_axes"] == name
    text = str(warned[0].message)
    assert "x axis is not along the foot" in text and f"axes={name.replace(' ', '')}" in text.replace(" ", "")



def test_a_track_across_x_with_the_pitch_axis_right_is_not_blamed_on_the_map():
    """mbgtd with only a height correction: the track goes sideways (strides of metres on a 1.2 m walk) while gyr_y
    is still the pitch rate; the map is right, so no mounting warning names it."""
    from footzoo import Pipeline
    from footzoo.sim import NoiseModel, simulate

    rec = simulate(n_strides=3, rate=50.0, profile="physical", noise=NoiseModel(seed=0), distance_sensors=True,
                   clearance=0.1)
    cfg = {"orientation": {"type": "ins"}, "detector": {"type": "mbgtd"}, "corrections": [{"type": "height_distance"}]}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = Pipeline.from_dict(cfg).run(rec).diagnostics["mounting"]
    assert abs(rep["x_forward"]) < 0.26 and rep["pitch_rate_correlation"] > 0.8  # measured 0.06 and 0.92
    assert not rep["x_across"] and not rep["walks_backwards"] and not rep["pitch_reversed"]
    assert not [w for w in caught if "mounting" in str(w.message)]


def _turned(axis: int, deg: float) -> np.ndarray:
    """The rotation by ``deg`` degrees about sensor axis ``axis`` (rows: FRD axes in sensor coordinates)."""
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.eye(3)
    m[i, i] = m[j, j] = c
    m[i, j], m[j, i] = s, -s
    return m


def test_a_tilted_sensor_still_gets_its_nearest_axis_map():
    # hand-derived: a sensor turned 180° about z ([-x, -y, z]) and tilted 40° about x, then 40° about y. Rows y
    # and z both peak in the sensor's y column (0.766, 0.643), yet trace(Pᵀ A) = 2.119 for [-x, -y, z] against
    # 1.901 for the next map
    flip = np.diag([-1.0, -1.0, 1.0])
    a = flip @ _turned(0, 40.0) @ _turned(1, 40.0)
    assert np.argmax(np.abs(a[1])) == np.argmax(np.abs(a[2])) == 1
    assert np.sum(flip * a) == pytest.approx(2.119, abs=1e-3)
    assert np.array_equal(nearest_axis_map(a), flip)
    assert np.array_equal(nearest_axis_map(_turned(1, 20.0)), np.eye(3))
    assert nearest_axis_map(_turned(1, 45.0)) is None  # halfway between [x, y, z] and [z, y, -x]: no map named


@pytest.mark.slow  # two runs of a 30 s real trial (3.6 s)
def test_ipol_trial_read_upside_down_is_named_with_its_fix():
    """A tilted MTw (IPOL, about 30° pitched on the foot) read as if turned 180° about z: the warning names the map."""
    from footzoo.io import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the file's own gaps and spikes (tested with the reader)
        rec = remount(load(data_file("ipol_gait", "7-2_lf.txt")), np.diag([-1.0, -1.0, 1.0]))
    res, warned = _run(rec)
    rep = res.diagnostics["mounting"]
    assert rep["walks_backwards"] and rep["pitch_reversed"] and rep["suggested_axes"] == "[-x, -y, z]"
    text = str(next(w for w in warned if "mounting" in str(w.message)).message)
    assert "--option 'axes=[-x, -y, z]'" in text
