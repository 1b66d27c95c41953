"""One metric registry for footzoo run, Result.metrics and studies; refused metrics (NaN with a reason)."""

import warnings

import numpy as np
import pandas as pd
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.core.data import Recording, Truth
from footzoo.evaluation.metrics import METRICS, result_metrics, run_metrics
from footzoo.evaluation.validity import (
    MIN_STANCE_S,
    STEP_METRICS,
    STRIDE_COMPARISONS,
    MetricWarning,
    checked_metrics,
    reference_problems,
)
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate
from footzoo.studies import Study, run_study

from ..conftest import HARD_IRON_NOT_FITTED

RATE = 100.0


def _mask(phases_s: list[tuple[float, float]], duration: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """A stance mask at 100 Hz with stance in each (start, length) of ``phases_s`` (s)."""
    t = np.arange(0.0, duration, 1.0 / RATE)
    mask = np.zeros(t.size, bool)
    for start, length in phases_s:
        mask[(t >= start - 1e-9) & (t < start + length - 1e-9)] = True
    return t, mask


def _strides(n: int, **drop) -> pd.DataFrame:
    ic = np.arange(1, n + 1, dtype=float)
    steps = pd.DataFrame({"start_s": np.r_[np.nan, ic[:-1]], "to_s": ic - 0.4, "end_s": ic,
                          "stride_length_m": np.full(n, 1.2)})
    for col, rows in drop.items():
        if rows == "all":
            steps = steps.drop(columns=col)
        else:
            steps.loc[: rows - 1, col] = np.nan
    return steps


# ------------------------------------------------------------------ the rules, each on a hand-built reference


def test_whole_stance_phases_are_usable():
    t, mask = _mask([(1.0 + k, 0.5) for k in range(10)])
    assert reference_problems(t, Truth(stance=mask)) == {}


def test_fragmented_stance_refuses_the_step_metrics_only():
    # 8 phases: 2 short ones (25 %) are allowed, 3 (37.5 %) are not; 90 ms is short, 100 ms is not
    ok = [(1.0 + k, 0.5) for k in range(6)] + [(7.0, 0.09), (8.0, 0.09)]
    bad = [(1.0 + k, 0.5) for k in range(5)] + [(6.0, 0.09), (7.0, 0.09), (8.0, 0.09)]
    edge = [(1.0 + k, 0.5) for k in range(5)] + [(6.0, MIN_STANCE_S), (7.0, MIN_STANCE_S), (8.0, MIN_STANCE_S)]
    assert reference_problems(*_mask(ok)[:1], Truth(stance=_mask(ok)[1])) == {}
    assert reference_problems(_mask(edge)[0], Truth(stance=_mask(edge)[1])) == {}
    problems = reference_problems(_mask(bad)[0], Truth(stance=_mask(bad)[1]))
    assert set(problems) == set(STEP_METRICS)
    assert "fragmented stance reference: 3 of its 8 stance phases last less than 100 ms" in problems["step_count_error"]


def test_no_stance_or_no_swing_refuses_every_stance_metric():
    t = np.arange(0.0, 10.0, 0.01)
    for mask, word in ((np.zeros(t.size, bool), "stance"), (np.ones(t.size, bool), "swing")):
        problems = reference_problems(t, Truth(stance=mask))
        assert "stance_f1" in problems and "step_count_error" in problems
        assert problems["stance_f1"] == f"the reference stance mask has no {word} sample"


def test_too_few_stance_phases():
    t, mask = _mask([(1.0, 0.5), (2.0, 0.5)])
    problems = reference_problems(t, Truth(stance=mask))
    assert set(problems) == set(STEP_METRICS)
    assert problems["gait_phase_error_rate"] == "too few reference stance phases: 2 (at least 3 needed)"


def test_too_few_strides_refuses_every_stride_comparison():
    t = np.arange(0.0, 10.0, 0.01)
    problems = reference_problems(t, Truth(steps=_strides(2)))
    assert set(problems) == set(STRIDE_COMPARISONS)
    assert reference_problems(t, Truth(steps=_strides(3))) == {}


def test_missing_events_refuse_the_comparisons_that_need_them():
    t = np.arange(0.0, 10.0, 0.01)
    problems = reference_problems(t, Truth(steps=_strides(6, to_s="all")))
    # no fpa_rad column: no FPA comparison
    assert set(problems) == {"to_error_median_abs_s", "to_error_mean_s", "to_error_median_s"}
    assert problems["to_error_mean_s"] == "the reference stride table has no 'to_s' column"
    # 3 of 6 toe-offs missing is allowed (at most half), 4 is not
    assert "to_error_mean_s" not in reference_problems(t, Truth(steps=_strides(6, to_s=3)))
    assert reference_problems(t, Truth(steps=_strides(6, to_s=4)))["to_error_mean_s"] == (
        "reference 'to_s' is missing in 4 of 6 strides")


def test_refused_metrics_are_nan_with_their_reason():
    values = {"step_count_error": -30.0, "stance_f1": 0.9, "matched_strides": 0.0, "ref_strides": 5.0}
    out, notes = checked_metrics(values, {"step_count_error": "fragmented"}, Truth(steps=_strides(5)))
    assert np.isnan(out["step_count_error"]) and notes["step_count_error"] == "fragmented"
    assert out["stance_f1"] == 0.9 and "stance_f1" not in notes
    assert np.isnan(out["stride_length_rms_error_m"])  # none matched: not a made-up number
    assert notes["ic_error_median_abs_s"] == "no estimated stride matched a reference stride"


# ------------------------------------------------------------------ one registry, footzoo run's names


@pytest.fixture(scope="module")
def walk():
    return simulate(path="straight", n_strides=8, rate=100.0, noise=NoiseModel(seed=0))


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_every_metric_of_a_run_is_registered_and_result_metrics_match(walk):
    res = Pipeline.from_yaml("yun2012").run(walk)
    m = run_metrics(walk.t, res.pos, res.steps, res.stance, walk.truth)
    assert set(m) <= set(METRICS)
    assert {k: v for k, v in m.items() if k in res.metrics} == pytest.approx(res.metrics, nan_ok=True)
    assert set(m) - set(res.metrics) <= {k for k in METRICS if k.startswith("stance_")} | set(STEP_METRICS)
    # the simulator's truth: 8 strides of 1.2 m at 1 s each
    assert m["strides"] == walk.truth.stride_count == 8
    assert m["median_stride_length_m"] == pytest.approx(1.2, abs=0.05)
    assert m["median_stride_time_s"] == pytest.approx(1.0, abs=0.02)
    assert m["median_speed_m_s"] == pytest.approx(1.2, abs=0.06)


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_a_study_reports_gait_metrics_by_footzoo_runs_names(walk, tmp_path):
    base = {"simulate": {"path": "straight", "n_strides": 8, "rate": 100, "noise": {"scale": 1}}, "seeds": [0]}
    study = Study.from_dict({"base": "yun2012", "recordings": [base],
                             "metrics": ["median_stride_length_m", "strides", "ic_error_median_abs_s"]})
    table = run_study(study, quiet=True)
    values = dict(zip(table["metric"], table["value"], strict=True))
    assert set(values) == {"median_stride_length_m", "strides", "ic_error_median_abs_s"}
    res = Pipeline.from_yaml("yun2012").run(walk)
    assert values["strides"] == res.metrics["strides"]
    assert values["median_stride_length_m"] == res.metrics["median_stride_length_m"]
    # by default a recording with stride and stance references reports every comparison
    table = run_study(Study.from_dict({"base": "yun2012", "recordings": [base]}), quiet=True)
    assert {"ic_error_median_abs_s", "to_error_median_abs_s", "stride_length_rms_error_m", "step_count_error",
            "gait_phase_error_rate", "median_stance_time_s"} <= set(table["metric"])


def test_a_metric_is_named_by_its_one_name():
    d = {"base": "yun2012", "recordings": [{"simulate": {"path": "straight", "n_strides": 4}}]}
    assert Study.from_dict({**d, "metrics": ["strides", "strides"]}).metrics == ["strides"]
    with pytest.raises(ConfigError, match=r"unknown metric 'steps' \(did you mean 'strides'\?\); valid metrics"):
        Study.from_dict({**d, "metrics": ["steps"]})
    with pytest.raises(ConfigError, match=r"unknown metric 'stride' \(did you mean 'strides'\?\)"):
        Study.from_dict({**d, "metrics": ["stride"]})


def test_a_fragmented_stance_reference_gives_nan_and_a_note_in_the_study_table(walk, tmp_path):
    # the stance reference chopped into 40 ms fragments, as the VICON labels of PyShoe's running trials
    stance = walk.truth.stance.copy()
    stance[(np.arange(stance.size) // 4) % 2 == 1] = False
    rec = Recording(t=walk.t, acc=walk.acc, gyr=walk.gyr, meta=dict(walk.meta), truth=Truth(stance=stance))
    write(rec, tmp_path / "fragmented.csv")
    study = Study.from_dict({"base": "yun2012", "recordings": [{"path": str(tmp_path / "fragmented.csv")}]})
    with pytest.warns(MetricWarning, match="fragmented stance reference"):
        table = run_study(study)
    row = table.set_index("metric").loc["step_count_error"]
    assert np.isnan(row["value"]) and row["note"].startswith("fragmented stance reference")
    assert pd.isna(table.set_index("metric").loc["stance_f1", "note"])  # per-sample scores stay
    assert "fragmented stance reference" in next(iter(table.attrs["refused"]))


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_result_metrics_apply_the_same_rules_as_a_study(walk, tmp_path):
    """A reference stride table too short to score: NaN with the same reason in Result.metrics, metrics.json
    and a study cell's scores; a usable reference keeps every number (and no note)."""
    res = Pipeline.from_yaml("yun2012").run(walk)
    assert res.metric_notes == {}
    assert res.metrics == pytest.approx(result_metrics(walk.t, res.pos, res.steps, walk.truth), nan_ok=True)

    short = Truth(steps=walk.truth.steps.iloc[:2].copy(), stride_count=walk.truth.stride_count)
    rec = Recording(t=walk.t, acc=walk.acc, gyr=walk.gyr, meta=dict(walk.meta), truth=short)
    res = Pipeline.from_yaml("yun2012").run(rec)
    with pytest.warns(MetricWarning, match="too few"):
        m = res.metrics
    refused = {k for k in STRIDE_COMPARISONS if k in m}
    assert refused and all(np.isnan(m[k]) for k in refused)
    assert set(res.metric_notes) == refused and all("too few" in why for why in res.metric_notes.values())
    assert m["strides"] == 8 and m["stride_count_error"] == 0  # what the reference can score stays

    import json

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # saving keeps the reasons in the file; the run already warned of them
        res.save(tmp_path / "out")
    saved = json.loads((tmp_path / "out" / "metrics.json").read_text())
    assert saved["metric_notes"] == res.metric_notes and all(saved["metrics"][k] is None for k in refused)

    # a study cell scores a run with the same rules (its table's value and note columns come from here)
    from footzoo.studies.runner import _metrics

    values, notes = _metrics(rec, res, res.pos, None)
    assert {k: notes[k] for k in refused} == res.metric_notes
    assert all(np.isnan(values[k]) for k in refused)


# ------------------------------------------------------------------ a metric asked for is never dropped


def test_a_metric_the_reference_cannot_give_is_nan_with_the_reason(walk, tmp_path):
    """A study asks for metrics a recording's reference has nothing for: a row each, NaN, and why."""
    rec = Recording(t=walk.t, acc=walk.acc, gyr=walk.gyr, meta=dict(walk.meta),
                    truth=Truth(stance=walk.truth.stance))  # a stance mask only: no strides, no positions
    write(rec, tmp_path / "stance_only.csv")
    asked = ["ic_error_median_abs_s", "armse_3d_m", "stance_f1", "loop_closure_xy_m", "fpa_mean_deg"]
    study = Study.from_dict({"base": "yun2012", "recordings": [{"path": str(tmp_path / "stance_only.csv")}],
                             "metrics": asked})
    with pytest.warns(MetricWarning, match="metrics refused"):
        table = run_study(study, out=tmp_path / "out")
    rows = table.set_index("metric")
    assert sorted(rows.index) == sorted(asked)
    assert np.isfinite(rows.loc["stance_f1", "value"]) and pd.isna(rows.loc["stance_f1", "note"])
    notes = rows["note"].to_dict()
    assert "has no stride table with initial contacts" in notes["ic_error_median_abs_s"]
    assert "has no reference positions" in notes["armse_3d_m"]
    assert "not known to be a closed walk" in notes["loop_closure_xy_m"]
    assert "no foot-progression-angle analysis" in notes["fpa_mean_deg"]
    assert all(np.isnan(rows.loc[m, "value"]) for m in asked if m != "stance_f1")
    summary = (tmp_path / "out" / "summary.md").read_text()
    line = next(x for x in summary.splitlines() if x.startswith("| yun2012 | ic_error_median_abs_s |"))
    assert "| 0 | " in line and notes["ic_error_median_abs_s"] in line  # in the summary too: count 0, and why


def test_the_summary_says_why_a_metric_has_no_value():
    """``summarise``'s reason column: the runs' notes where a level has no value, how many runs lack one where
    only some do, empty where every run has one."""
    from footzoo.studies.report import summarise

    table = pd.DataFrame({
        "run": [0, 1, 2, 3, 0, 1, 2, 3], "base": ["a", "a", "b", "b"] * 2, "recording": ["x", "y"] * 4,
        "metric": ["armse_3d_m"] * 4 + ["strides"] * 4, "value": [0.1, np.nan, np.nan, np.nan, 8, 9, 8, 9],
        "error": None, "note": [None, "no positions in y", "no positions in x", "no positions in y"] + [None] * 4})
    s = summarise(table, "base").set_index(["base", "metric"])
    assert s.loc[("a", "armse_3d_m"), "count"] == 1
    assert s.loc[("a", "armse_3d_m"), "reason"] == "1 of 2 runs: no positions in y"
    assert s.loc[("b", "armse_3d_m"), "count"] == 0
    assert s.loc[("b", "armse_3d_m"), "reason"] == "no positions in x; no positions in y"
    assert s.loc[("a", "strides"), "reason"] == "" and s.loc[("b", "strides"), "mean"] == 8.5
    unexplained = summarise(table.drop(columns="note"), "base").set_index(["base", "metric"])
    assert unexplained.loc[("b", "armse_3d_m"), "reason"] == "no reason recorded"


def test_two_factors_are_crossed_as_the_median_of_each_pair_of_levels():
    """``crossed``: one row per metric and level of the first factor, one column per level of the second, the
    median over the cell's recordings; a cell without a value is NaN; plug-in specs labelled as in the summaries."""
    from footzoo.studies.report import crossed

    shoe, fsm = '{"type": "shoe"}', '{"type": "angular_rate_fsm", "threshold": 0.6}'
    table = pd.DataFrame({
        "run": range(8), "recording": ["x", "y"] * 4, "metric": "armse_3d_m", "error": None, "note": None,
        "orientation.static_gain": [0.5, 0.5, 0.5, 0.5, 1.05, 1.05, 1.05, 1.05],
        "detector": [shoe, shoe, fsm, fsm] * 2, "value": [1.0, 3.0, 5.0, 6.0, 2.0, 2.0, np.nan, np.nan]})
    c = crossed(table, "orientation.static_gain", "detector")
    assert list(c.columns) == ["metric", "orientation.static_gain \\ detector", "shoe",
                               "angular_rate_fsm (threshold=0.6)"]
    assert c["shoe"].tolist() == [2.0, 2.0] and c["angular_rate_fsm (threshold=0.6)"].iloc[0] == 5.5
    assert np.isnan(c["angular_rate_fsm (threshold=0.6)"].iloc[1])  # both runs refused: no value, not a zero
    assert c["orientation.static_gain \\ detector"].tolist() == ["0.5", "1.05"]


def test_reasons_alike_but_for_their_numbers_are_given_once_with_their_count():
    """Nine PyShoe trials' fragmented stance references: one reason and how many more, not nine sentences."""
    from footzoo.studies.report import summarise

    notes = [f"fragmented stance reference: {k} of its {k + 20} stance phases last under 100 ms" for k in (16, 45, 24)]
    table = pd.DataFrame({"run": [0, 1, 2, 3], "base": ["a"] * 4, "recording": ["p1", "p2", "p3", "g"],
                          "metric": ["step_count_error"] * 4, "value": [np.nan] * 4, "error": None,
                          "note": [*notes, "the reference has no stance mask"]})
    reason = summarise(table, "base").set_index(["base", "metric"]).loc[("a", "step_count_error"), "reason"]
    assert reason == f"{notes[0]} (and 2 alike, with other numbers); the reference has no stance mask"


def test_a_reason_in_free_text_keeps_the_summary_tables_valid():
    """A note is free text: Markdown's cell separator and LaTeX's special characters are escaped."""
    from footzoo.studies.report import to_latex, to_markdown

    s = pd.DataFrame({"metric": ["fpa_mean_deg"], "reason": ["meta['foot'] {left|right} at 50% & $x_1 ~ #2^\\"]})
    md = to_markdown(s).splitlines()[2]
    assert md == "| fpa_mean_deg | meta['foot'] {left\\|right} at 50% & $x_1 ~ #2^\\ |"
    row = to_latex(s).splitlines()[4]
    assert row == (r"fpa\_mean\_deg & meta['foot'] \{left|right\} at 50\% \& \$x\_1 \textasciitilde{} \#2"
                   r"\textasciicircum{}\textbackslash{} \\")


def test_the_datasets_metrics_a_study_asks_for_are_kept():
    """The issue's cases: IC timing on PyShoe (no stride events), stance F1 on gaitmap (no stance mask)."""
    from ..conftest import data_file

    pyshoe = data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat")
    gaitmap = data_file("gaitmap_example", "imu_sample.csv")
    study = Study.from_dict({"base": "recommended", "metrics": ["ic_error_median_abs_s", "stance_f1"],
                             "recordings": [{"path": str(pyshoe)}, {"path": str(gaitmap), "foot": "left"}]})
    with pytest.warns(MetricWarning):
        table = run_study(study)
    rows = table.set_index(["recording", "metric"])
    assert len(rows) == 4
    assert np.isfinite(rows.loc[("2017-11-22-11-22-03", "stance_f1"), "value"])
    assert np.isfinite(rows.loc[("imu_sample", "ic_error_median_abs_s"), "value"])
    note = rows.loc[("2017-11-22-11-22-03", "ic_error_median_abs_s"), "note"]
    assert "reference (VICON (PyShoe)) has no stride table" in note
    note = rows.loc[("imu_sample", "stance_f1"), "note"]
    assert "reference (motion capture (gaitmap)) has no stance mask" in note
