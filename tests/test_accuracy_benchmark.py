"""benchmarks/accuracy.py: its --quick path on a simulated walk only, its helpers, its gaitmap strides."""

import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from .conftest import data_file

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def accuracy():
    spec = importlib.util.spec_from_file_location("accuracy_benchmark", ROOT / "benchmarks" / "accuracy.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_quick_run_without_datasets_skips_them_and_writes_table_and_summary(accuracy, tmp_path):
    summary = tmp_path / "summary.md"
    assert accuracy.main(["--quick", "--data", str(tmp_path / "absent"), "--results", str(tmp_path / "res"),
                          "--configs", "duong2015_zupt", "--summary", str(summary)]) == 0
    table = pd.read_csv(tmp_path / "res" / "accuracy.csv")
    assert set(table["dataset"]) == {"sim_walk_short"}  # every real dataset is absent: skipped
    armse = table.loc[table["metric"] == "armse_3d_m", "value"]
    assert len(armse) == 1 and 0 < armse.iloc[0] < 1.0  # a 30 m loop tracked within a metre of the truth
    text = summary.read_text()
    assert "## Simulator scenarios" in text and "## PyShoe" not in text


def test_rigid_alignment_undoes_a_rotation_and_a_reflection(accuracy):
    rng = np.random.default_rng(0)
    ref = rng.uniform(-5, 5, (12, 2))
    a = 0.8
    rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    moved = ref @ rot.T + [3.0, -1.0]
    np.testing.assert_allclose(accuracy.rigid_align_2d(moved, ref), ref, atol=1e-9)
    mirrored = moved * [1.0, -1.0]  # Köroğlu's ground control points have y flipped
    np.testing.assert_allclose(accuracy.rigid_align_2d(mirrored, ref), ref, atol=1e-9)
    # a proper rotation alone cannot undo the mirror
    assert np.abs(accuracy.rigid_align_2d(mirrored, ref, reflection=False) - ref).max() > 0.5


def test_footprints_are_the_stance_middles_around_strides(accuracy):
    steps = pd.DataFrame({"start_n": [0.0, 1.0], "start_e": [0.0, 0.1], "end_n": [1.0, 2.0], "end_e": [0.1, 0.0]})
    np.testing.assert_allclose(accuracy.footprints(steps), [[0, 0], [1, 0.1], [2, 0]])


def test_motion_classes_follow_the_recording_day(accuracy):
    assert accuracy.motion_class("2017-11-22-11-22-03") == "walking"
    assert accuracy.motion_class("2017-12-15-18-01-18") == "running/fast"
    assert accuracy.motion_class("2018-02-22-10-09-36") == "inverted"


def test_gaitmap_stride_errors_are_the_ones_session_reports(accuracy):
    """One implementation: the benchmark's gaitmap rows are Session.per_foot's values (Result.metrics)."""
    from footzoo import Pipeline, Session

    path = data_file("gaitmap_example", "imu_sample.csv")
    config = ROOT / "configs" / "yun2012.yaml"
    per_foot = Session.load(path).run(Pipeline.from_yaml(config)).per_foot
    for foot in ("left", "right"):
        rows = accuracy.stride_metrics(f"gaitmap_{foot}", {"path": str(path), "format": "gaitmap", "foot": foot},
                                       config)
        got = {r["metric"]: r["value"] for r in rows}
        assert got["strides_matched"] == got["strides_reference"] == per_foot.loc[foot, "ref_strides"] >= 28
        assert got["stride_length_rms_m"] == pytest.approx(per_foot.loc[foot, "stride_length_rms_error_m"])
        assert got["stride_length_rms_straight_m"] == pytest.approx(
            per_foot.loc[foot, "stride_length_rms_error_straight_m"])
