"""benchmarks/accuracy.py: its --quick path on a simulated walk only, its helpers, its per-stride references."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from ..conftest import KOROGLU_MOUNTING, data_file, load_benchmark

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def accuracy():
    return load_benchmark("accuracy")


@pytest.mark.slow
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


@pytest.mark.slow
def test_the_configs_table_alone_keeps_the_flagship_blocks(accuracy, tmp_path):
    summary = tmp_path / "summary.md"
    summary.write_text(f"# an old configs table\n\n{accuracy.FLAGSHIP_MARK}\n\n<!-- part: rates -->\n"
                       "### Rates, from an earlier run\n")
    assert accuracy.main(["--quick", "--parts", "configs", "--data", str(tmp_path / "absent"), "--results",
                          str(tmp_path / "res"), "--configs", "duong2015_zupt", "--summary", str(summary)]) == 0
    text = summary.read_text()
    assert "an old configs table" not in text and "## Simulator scenarios" in text
    assert text.count(accuracy.FLAGSHIP_MARK) == 1 and "### Rates, from an earlier run" in text


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
        assert got["strides_reference"] == per_foot.loc[foot, "ref_strides"] >= 28
        assert got["strides_matched"] == per_foot.loc[foot, "matched_strides"] >= 27
        assert got["stride_length_rms_m"] == pytest.approx(per_foot.loc[foot, "stride_length_rms_error_m"])
        assert got["stride_length_rms_straight_m"] == pytest.approx(
            per_foot.loc[foot, "stride_length_rms_error_straight_m"])


# the mounting report finds the sensor's x axis pointing backwards (expected warning)
@pytest.mark.filterwarnings(KOROGLU_MOUNTING)
@pytest.mark.slow
def test_koroglu_footprint_errors_against_the_measured_footprints(accuracy):
    """Where the stride count is exact, the benchmark reports the footprint error against GCP_meters."""
    from scipy.io import loadmat

    from footzoo import Pipeline
    from footzoo.evaluation.metrics import rigid_align_2d
    from footzoo.io import load

    path = data_file("koroglu_gcp", "SensorConnectData_31.csv")
    config = ROOT / "configs" / "recommended.yaml"
    got = {r["metric"]: r["value"] for r in accuracy.stride_metrics("koroglu", {"path": str(path),
                                                                                 "format": "sensorconnect"}, config)}
    gcp = np.asarray(loadmat(path.with_suffix(".mat"))["GCP_meters"], float)
    steps = Pipeline.from_yaml(config).run(load(path)).steps
    assert got["stride_count_error"] == 0 and got["strides_detected"] == len(steps) == len(gcp) - 1
    # the footprints by hand: the first stride's start and every stride's end, rigidly aligned (reflection allowed)
    est = np.vstack([steps[["start_n_m", "start_e_m"]].to_numpy()[:1], steps[["end_n_m", "end_e_m"]].to_numpy()])
    aligned, _ = rigid_align_2d(est, gcp)
    assert got["footprint_error_mean_m"] == pytest.approx(np.linalg.norm(aligned - gcp, axis=1).mean())
    assert 0 < got["footprint_error_mean_m"] < 1.0  # measured 0.24 m over a 51 m walk


@pytest.mark.slow
def test_flagship_parts_rewrite_only_their_section(accuracy, tmp_path):
    summary = tmp_path / "summary.md"
    summary.write_text(f"# kept\n\nthe configs' table\n\n{accuracy.FLAGSHIP_MARK}\n\n<!-- part: rates -->\n"
                       "### Rates, from an earlier run\n\n<!-- part: mounting -->\n### an old mounting block\n")
    assert accuracy.main(["--parts", "mounting", "--data", str(tmp_path / "absent"), "--summary", str(summary)]) == 0
    text = summary.read_text()
    assert text.startswith("# kept\n\nthe configs' table") and accuracy.FLAGSHIP_MARK in text
    assert "### Rates, from an earlier run" in text and "an old mounting block" not in text  # only its own block
    assert text.index("<!-- part: rates -->") < text.index("<!-- part: mounting -->")
    assert "--parts rates,mounting`" in text
    assert "### 24 sensor mountings (simulator)" in text
    assert "| 24 mountings: largest event difference | ≤ 10 ms |" in text
    # a second run replaces the section, it does not append another
    assert accuracy.main(["--parts", "mounting", "--data", str(tmp_path / "absent"), "--summary", str(summary)]) == 0
    assert summary.read_text().count(accuracy.FLAGSHIP_MARK) == 1
    with pytest.raises(SystemExit, match="unknown part"):
        accuracy.main(["--parts", "nonsense", "--summary", str(summary)])


def test_the_rate_spread_is_paired_over_the_seeds():
    """Hand-derived: each seed's error 10 % higher at the second rate is a 10 % spread with no uncertainty, however
    much the seeds differ; the unpaired bootstrap of the earlier design put it anywhere from 0 to 100 %."""
    import numpy as np

    parts = load_benchmark("accuracy_parts")
    seeds = np.random.default_rng(0).uniform(0.04, 0.3, 24)  # one seed's error varies by a factor 7
    s = parts.rate_spread([seeds, 1.1 * seeds, seeds * 1.05])
    assert s["spread"] == pytest.approx(0.1) and s["spread_lo"] == pytest.approx(0.1)
    assert s["spread_hi"] == pytest.approx(0.1) and s["p"] < 1e-6
