"""Which metrics a study draws: the headline errors by default, the study's own choice with ``figures:``."""

import pytest

from footzoo import ConfigError
from footzoo.evaluation.metrics import FIGURE_METRICS, METRICS
from footzoo.studies import Study, run_study

STUDY = {
    "name": "figures",
    "base": {"orientation": {"type": "fqa_complementary"}, "detector": {"type": "angular_rate_fsm"},
             "corrections": [{"type": "zvu_dedrift"}]},
    "factors": {"orientation.static_gain": [0.5, 1.05]},
    "recordings": [{"simulate": {"path": "straight", "n_strides": 4, "rate": 50}, "seeds": [0]}],
}


def _drawn(out) -> set[str]:
    """The metrics of the box plots in ``out`` (``metric_<metric>_by_<factor>.png``)."""
    return {p.name.removeprefix("metric_").split("_by_")[0] for p in out.glob("metric_*_by_*.png")}


def test_the_headline_metrics_are_registered():
    assert set(FIGURE_METRICS) <= set(METRICS)


def test_by_default_the_headline_errors_are_drawn_and_the_table_keeps_every_metric(tmp_path):
    table = run_study(Study.from_dict(STUDY), out=tmp_path)
    kept = set(table["metric"].dropna())
    assert _drawn(tmp_path) == kept & set(FIGURE_METRICS)
    assert {"armse_3d_m", "stride_length_rms_error_m", "stance_f1"} <= _drawn(tmp_path)
    assert {"duration_s", "median_stride_time_s", "stride_count_ref"} <= kept - _drawn(tmp_path)
    assert list(tmp_path.glob("trajectories_*.png"))  # the trajectories are drawn whatever the choice


@pytest.mark.parametrize("figures,metrics,expected", [
    ("all", ["duration_s", "armse_3d_m", "stance_f1"], "every"),
    ("none", None, set()),
    (["stance_f1", "duration_s"], None, {"stance_f1", "duration_s"}),
    (None, ["duration_s", "armse_3d_m"], {"duration_s", "armse_3d_m"}),  # the metrics the study keeps
    (["armse_3d_m"], ["duration_s", "armse_3d_m"], {"armse_3d_m"}),
])
def test_figures_names_what_is_drawn(tmp_path, figures, metrics, expected):
    spec = {**STUDY, **({"figures": figures} if figures is not None else {}),
            **({"metrics": metrics} if metrics is not None else {})}
    table = run_study(Study.from_dict(spec), out=tmp_path)
    assert _drawn(tmp_path) == (set(table["metric"].dropna()) if expected == "every" else expected)


def test_changing_figures_rewrites_the_outputs_and_removes_the_figures_no_longer_drawn(tmp_path):
    run_study(Study.from_dict(STUDY), out=tmp_path)
    assert "duration_s" not in _drawn(tmp_path) and "stance_f1" in _drawn(tmp_path)
    (tmp_path / "my_notes.txt").write_text("the user's own file")
    table = run_study(Study.from_dict({**STUDY, "figures": ["duration_s", "armse_3d_m"]}), out=tmp_path)
    assert table.attrs["cached"] == 2 and table.attrs["computed"] == 0  # the runs are read back, not redone
    assert _drawn(tmp_path) == {"duration_s", "armse_3d_m"}  # the earlier report's other figures are gone
    assert (tmp_path / "my_notes.txt").read_text() == "the user's own file"  # what footzoo did not write stays
    assert list(tmp_path.glob("trajectories_*.png")) and (tmp_path / "results.csv").exists()


@pytest.mark.parametrize("figures,message", [
    (["armse_3d"], r"unknown metric 'armse_3d' \(did you mean 'armse_3d_m'\?\) in figures; valid metrics"),
    (3, r"figures must be a list of metric names, or the word all or none, got 3"),
    ("every", r"unknown metric 'every'.* in figures"),
])
def test_a_bad_figures_entry_names_the_problem(figures, message):
    with pytest.raises(ConfigError, match=message):
        Study.from_dict({**STUDY, "figures": figures})


def test_figures_of_a_metric_the_study_drops_are_refused():
    with pytest.raises(ConfigError, match=r"figures names \['stance_f1'\] but metrics does not keep them"):
        Study.from_dict({**STUDY, "metrics": ["armse_3d_m"], "figures": ["stance_f1", "armse_3d_m"]})


def test_a_manifest_of_an_older_footzoo_removes_nothing(tmp_path):
    """Older manifests listed every file of the folder, the user's own included: none of them is removed."""
    import json

    (tmp_path / "my_notes.txt").write_text("the user's own file")
    (tmp_path / "outputs.json").write_text(json.dumps({"digest": "old", "files": {"my_notes.txt": "0" * 64}}))
    run_study(Study.from_dict(STUDY), out=tmp_path)
    assert (tmp_path / "my_notes.txt").read_text() == "the user's own file"
    assert "my_notes.txt" not in json.loads((tmp_path / "outputs.json").read_text())["files"]



def test_a_comparison_of_base_configs_is_drawn_and_summarised_as_a_factor(tmp_path):
    """Several base configs and no factors: a box plot per metric by base, as a factor gets."""
    fsm = STUDY["base"]
    shoe = {**fsm, "name": "shoe", "detector": {"type": "shoe"}}
    spec = {"name": "configs", "base": [{**fsm, "name": "fsm"}, shoe], "recordings": STUDY["recordings"],
            "figures": "all", "metrics": ["armse_3d_m", "strides", "stance_f1"]}
    table = run_study(Study.from_dict(spec), out=tmp_path)
    assert sorted(table["base"].unique()) == ["fsm", "shoe"]
    drawn = {p.name for p in tmp_path.glob("metric_*_by_base.png")}
    assert {f"metric_{m}_by_base.png" for m in table["metric"].dropna().unique()} == drawn
    summary = (tmp_path / "summary.md").read_text()
    assert "| fsm | armse_3d_m |" in summary and "| shoe | armse_3d_m |" in summary


def test_inline_base_configs_without_a_name_are_named_by_what_differs():
    fsm = STUDY["base"]
    shoe = {**fsm, "detector": {"type": "shoe"}}
    names = [n for n, _ in Study.from_dict({**STUDY, "base": [fsm, shoe]}).bases]
    assert names == ["detector: angular_rate_fsm", "detector: shoe"]
    named = [n for n, _ in Study.from_dict({**STUDY, "base": [fsm, {**shoe, "name": "mine"}]}).bases]
    assert named == ["detector: angular_rate_fsm", "mine"]
    with pytest.raises(ConfigError, match="'base0' and 'base1' are the same config"):  # nothing differs: one config
        Study.from_dict({**STUDY, "base": [fsm, fsm]})


def test_dictionary_levels_are_labelled_readably_in_the_summary(tmp_path):
    spec = {**STUDY, "factors": {"detector": [{"type": "shoe"}, {"type": "angular_rate_fsm", "threshold": 0.6}]},
            "metrics": ["armse_3d_m"]}
    table = run_study(Study.from_dict(spec), out=tmp_path)
    assert '{"type": "shoe"}' in set(table["detector"])  # the table keeps the level as written, for programs
    summary = (tmp_path / "summary.md").read_text()
    section = summary.split("## detector")[1]
    assert "| shoe | armse_3d_m |" in section and "| angular_rate_fsm (threshold=0.6) | armse_3d_m |" in section
    assert '{"' not in section  # no raw JSON for a reader


def test_a_study_of_two_factors_summarises_each_pair_of_their_levels(tmp_path):
    spec = {**STUDY, "factors": {**STUDY["factors"], "detector.type": ["angular_rate_fsm", "shoe"]},
            "metrics": ["armse_3d_m"]}
    table = run_study(Study.from_dict(spec), out=tmp_path)
    section = (tmp_path / "summary.md").read_text().split("## orientation.static_gain × detector.type (median)")[1]
    row = next(x for x in section.splitlines() if x.startswith("| armse_3d_m | 0.5 |"))
    cell = table[(table["orientation.static_gain"] == 0.5) & (table["detector.type"] == "shoe")]["value"].median()
    assert row.split("|")[4].strip() == f"{cell:.4g}"  # the shoe column's median, as to_markdown writes it


def test_a_metric_no_run_could_compute_is_kept_in_the_table_but_not_drawn(tmp_path):
    """A simulated walk without a reference has no stance mask: ``stance_f1`` is NaN with its reason, no empty plot."""
    import numpy as np

    from footzoo.evaluation.validity import MetricWarning
    from footzoo.sim import simulate

    walk = simulate(path="straight", n_strides=4, rate=50)
    walk.truth = None
    from footzoo.io import canonical

    canonical.write(walk, tmp_path / "walk.csv")
    spec = {**STUDY, "recordings": [{"path": str(tmp_path / "walk.csv")}], "figures": "all",
            "metrics": ["strides", "stance_f1"]}
    with pytest.warns(MetricWarning, match="stance mask"):
        table = run_study(Study.from_dict(spec), out=tmp_path / "study")
    f1 = table[table["metric"] == "stance_f1"]
    assert len(f1) == 2 and f1["value"].isna().all() and f1["note"].str.contains("reference").all()
    assert _drawn(tmp_path / "study") == {"strides"}
    assert np.isfinite(table[table["metric"] == "strides"]["value"]).all()
