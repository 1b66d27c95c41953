"""The Xsens MT Manager text reader: packet time with its gaps, the 16-bit counter, axes, IPOL annotations.

Synthetic fixtures: a simulated walk (FRD, SI, known truth) written as an Xsens export with the
sensor in the IPOL data set's mounting (x to the heel, z up) and packets dropped; the reader must
give the walk back at the packets' times. Real files: Voisard et al.'s IPOL gait data under
``../shared/data/ipol_gait`` (skipped when absent).
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from footzoo import FormatError
from footzoo.core.errors import FootzooWarning, RecordingError
from footzoo.io import detect_format, load
from footzoo.io.axes import parse_axes
from footzoo.io.xsens import COUNTER_WRAP, packet_times, reference_events
from footzoo.sim import NoiseModel, simulate

from ..conftest import data_file

HEADER = "PacketCounter\tAcc_X\tAcc_Y\tAcc_Z\tGyr_X\tGyr_Y\tGyr_Z\tMag_X\tMag_Y\tMag_Z"


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=3), magnetometer=True)


def xsens_text(rec, first: int = 0, drop=(), rate_line: str = "Acquisition frequency: 100 Hz", counter=None) -> str:
    """The walk as an IPOL-style Xsens export: sensor x to the heel and z up (180° about y), rows ``drop`` left out."""
    to_sensor = parse_axes("[-x, y, -z]").T  # FRD -> sensor (the map is a rotation: its inverse is its transpose)
    acc, gyr, mag = rec.acc @ to_sensor.T, rec.gyr @ to_sensor.T, rec.mag @ to_sensor.T
    pc = np.arange(rec.n) + first if counter is None else np.asarray(counter)
    keep = np.setdiff1d(np.arange(rec.n), drop)
    lines = [rate_line, HEADER] if rate_line else [HEADER]
    for k in keep:
        values = [*acc[k], *gyr[k], *mag[k]]
        lines.append("\t".join([f"{float(pc[k]):.1f}"] + [f"{v:.9f}" for v in values]))
    return "\n".join(lines) + "\n"


def test_an_xsens_export_comes_back_in_frd_at_its_packet_times(walk, tmp_path):
    path = tmp_path / "walk_lf.txt"
    drop = [150, 151, 152, 300]  # a wireless sensor's dropped packets: 30 ms and 10 ms gaps
    path.write_text(xsens_text(walk, first=1, drop=drop))
    assert detect_format(path) == "xsens"
    with pytest.warns(FootzooWarning, match="bridged 2 gap"):
        rec = load(path)
    keep = np.setdiff1d(np.arange(walk.n), drop)
    np.testing.assert_allclose(rec.t, (keep + 1) / 100.0, atol=1e-12)  # PacketCounter / rate, gaps kept
    np.testing.assert_allclose(rec.acc, walk.acc[keep], atol=1e-8)
    np.testing.assert_allclose(rec.gyr, walk.gyr[keep], atol=1e-8)
    np.testing.assert_allclose(rec.mag, walk.mag[keep], atol=1e-8)
    assert rec.meta["foot"] == "left" and rec.meta["axes"] == "[-x, y, -z]" and rec.truth is None


def test_a_gap_longer_than_max_gap_is_refused_or_bridged_when_allowed(walk, tmp_path):
    path = tmp_path / "gap.txt"
    path.write_text(xsens_text(walk, drop=list(range(200, 230))))  # 30 packets lost: a 0.31 s interval
    with pytest.raises(RecordingError, match="longer than 250.0 ms"):
        load(path)
    with pytest.warns(FootzooWarning, match="bridged 1 gap"):
        assert load(path, max_gap=0.5).n == walk.n - 30


def test_the_axis_map_is_an_option_and_must_be_right_handed(walk, tmp_path):
    path = tmp_path / "walk.txt"
    path.write_text(xsens_text(walk))
    sensor = load(path, axes="[x, y, z]")  # the sensor's own axes
    np.testing.assert_allclose(sensor.acc, walk.acc @ parse_axes("[-x, y, -z]"), atol=1e-8)
    with pytest.raises(FormatError, match="left-handed"):
        load(path, axes="[x, y, -z]")


def test_the_rate_comes_from_the_file_or_the_option(walk, tmp_path):
    path = tmp_path / "walk.txt"
    path.write_text(xsens_text(walk, rate_line="// Update Rate: 100.00Hz"))  # MT Manager's own header
    assert load(path).rate == pytest.approx(100.0)
    path.write_text(xsens_text(walk, rate_line=""))
    assert detect_format(path) == "xsens"
    with pytest.raises(FormatError, match="rate=100"):
        load(path)
    np.testing.assert_allclose(load(path, rate=50.0).t, np.arange(walk.n) / 50.0)


def test_the_16_bit_counter_wraps_and_a_counter_going_back_is_refused(walk, tmp_path):
    t = packet_times(np.array([65533.0, 65534.0, 65535.0, 0.0, 1.0, 3.0]), 100.0, tmp_path)
    np.testing.assert_allclose(t * 100.0, [65533, 65534, 65535, 65536, 65537, 65539])
    twice = packet_times(np.array([65535.0, 0.0, 65535.0, 0.0]), 100.0, tmp_path)  # two wraps: 655 s apart each
    np.testing.assert_allclose(twice * 100.0, [65535, COUNTER_WRAP, 2 * COUNTER_WRAP - 1, 2 * COUNTER_WRAP])
    with pytest.raises(FormatError, match="goes back from 120 to 100"):
        packet_times(np.array([100.0, 120.0, 100.0]), 100.0, tmp_path)
    with pytest.raises(FormatError, match="whole numbers"):
        packet_times(np.array([1.0, 2.5]), 100.0, tmp_path)
    # a whole file across the wrap reads as one continuous walk
    path = tmp_path / "wrap.txt"
    path.write_text(xsens_text(walk, counter=(np.arange(walk.n) + COUNTER_WRAP - 100) % COUNTER_WRAP))
    rec = load(path)
    np.testing.assert_allclose(np.diff(rec.t), 0.01, atol=1e-9)


def test_ipol_annotations_become_reference_strides(walk, tmp_path):
    path = tmp_path / "9-1_rf.txt"
    path.write_text(xsens_text(walk, first=1))
    notes = {"Subject": 9, "Age": 30, "Gender": "F", "Height": 170.0, "Weight": 60.0,
             "TrialBoundaries": [100, 500], "UTurnBoundaries": [250, 320],
             "LeftFootEvents": [[120, 160]], "RightFootEvents": [[90, 130], [140, 180], [240, 280], [330, 370],
                                                                 [460, 510]]}
    (tmp_path / "9-1.json").write_text(json.dumps(notes))
    rec = load(path)
    steps = rec.truth.steps
    # inside the trial [100, 500], outside the U-turn [250, 320]: the swings at 140 and 330 packets
    # an annotation names a sample: the middle of its interval, (first packet 1 + count − ½) / 100 Hz
    np.testing.assert_allclose(steps["to_s"], [1.405, 3.305])
    np.testing.assert_allclose(steps["end_s"], [1.805, 3.705])
    np.testing.assert_allclose(steps["start_s"], [1.305, 2.805])  # the heel strike before each swing
    assert not steps["turn"].any()
    assert rec.meta["subject"]["age"] == 30 and rec.meta["trial_s"] == [1.005, 5.005]
    both = load(path, uturn=True).truth.steps
    assert list(both["turn"]) == [False, True, False]
    left = reference_events(notes, "left", 1.0, 100.0)
    assert list(left["to_s"]) == [1.205]


def test_an_annotation_file_that_is_not_json_is_named(walk, tmp_path):
    path = tmp_path / "9-2_lf.txt"
    path.write_text(xsens_text(walk))
    (tmp_path / "9-2.json").write_text("{not json")
    with pytest.raises(FormatError, match="9-2.json"):
        load(path)



@pytest.mark.parametrize("rate_line, encoding, match", [
    ("Acquisition frequency: 100 Hz\n// Update Rate: 60.00Hz", "utf-8",
     r"two sampling rates, 100 Hz and 60 Hz.*rate=100"),
    ("Acquisition frequency: 0 Hz", "utf-8", r"9-3_lf\.txt: the header says a sampling rate of 0 Hz.*rate=100"),
    ("Acquisition frequency: 100 Hz", "utf-16", r"9-3_lf\.txt: .*UTF-16"),  # named as such, not "not an Xsens export"
])
def test_a_header_with_an_impossible_or_contradicting_rate_or_a_foreign_encoding_is_refused(walk, tmp_path, rate_line,
                                                                                            encoding, match):
    path = tmp_path / "9-3_lf.txt"
    path.write_text(xsens_text(walk, rate_line=rate_line), encoding=encoding)
    with pytest.raises(FormatError, match=match):
        load(path, format="xsens")


@pytest.mark.parametrize("notes, match", [
    ({"LeftFootEvents": [[150, 100]]}, r"LeftFootEvents\[0\] = \[150.0, 100.0\].*toe-off first"),
    ({"LeftFootEvents": [[100000, 100050]], "TrialBoundaries": [0, 200000]}, r"packets 100000-100050.*another trial"),
    ({"LeftFootEvents": [[10, 50]], "TrialBoundaries": "all"}, r"TrialBoundaries must be two packet counts"),
    ({"LeftFootEvents": "none"}, r"no readable LeftFootEvents"),
])
def test_annotations_that_cannot_describe_this_file_are_refused_with_the_file_named(walk, tmp_path, notes, match):
    path = tmp_path / "9-4_lf.txt"
    path.write_text(xsens_text(walk))
    (tmp_path / "9-4.json").write_text(json.dumps(notes))
    with pytest.raises(FormatError, match=r"9-4\.json: .*" + match):
        load(path)


# ------------------------------------------------------------------------------- real recordings


def test_the_ipol_files_read_with_their_dropped_packets():
    folder = data_file("ipol_gait", "6-1_lf.txt").parent
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FootzooWarning)  # every file has gaps: bridged with a warning
        rec = load(folder / "6-1_lf.txt")
    # the data README: 2 847 rows over 3 130 packets, 191 gaps of up to 8 packets (80 ms)
    assert rec.n == 2847 and rec.t[-1] == pytest.approx(31.29)
    gaps = np.diff(rec.t)
    assert int(np.sum(gaps > 0.015)) == 191 and gaps.max() == pytest.approx(0.08)
    # at rest (the first 0.5 s) the sensor reads about (5.1, 0.7, 8.6) m/s², z up: in FRD (-5.1, 0.7, -8.6)
    np.testing.assert_allclose(rec.acc[:50].mean(axis=0), [-5.1, 0.7, -8.6], atol=0.1)
    assert rec.meta["foot"] == "left" and rec.meta["subject"]["subject"] == 6
    assert len(rec.truth.steps) == 14  # 15 left swings, one of them in the U-turn


@pytest.mark.slow
def test_every_ipol_file_reads_and_its_mounting_is_named_right():
    """All 36 foot files: the default axis map makes the sensor's x axis forward and y right on the foot."""
    from footzoo.runtime.pipeline import Pipeline

    files = sorted(data_file("ipol_gait", "6-1_lf.txt").parent.glob("*_?f.txt"))
    assert len(files) == 36
    for f in files:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FootzooWarning)
            res = Pipeline.from_yaml("recommended").run(load(f))
        report = res.diagnostics["mounting"]
        assert not report["walks_backwards"] and not report["pitch_reversed"], f.name
        assert report["x_forward"] > 0.5 and report["y_right"] > 0.7  # measured ≥ 0.52 and ≥ 0.72
