"""footzoo tune: leave-one-group-out choice of a setting, grid and random search, the chosen config written."""

import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from footzoo import ConfigError, Pipeline
from footzoo.apps.cli import main
from footzoo.core.errors import FootzooWarning
from footzoo.studies import Study, TuneSpec, cross_validate, leave_one_group_out, tune
from footzoo.studies.tune import load_tune_file, sample_space

from ..conftest import ALL_STANCE, HARD_IRON_NOT_FITTED

ROOT = Path(__file__).resolve().parents[2]

#: Hand-built objective (lower is better): 6 recordings in 3 groups, 3 settings.
#: A is best on g1 and g2, C on g3 by far; over everything A wins (mean 1.5 vs 2.17 vs 2.33).
VALUES = pd.DataFrame({"A": [1.0, 1.0, 1.0, 1.0, 2.5, 2.5],
                       "B": [2.0, 2.0, 2.0, 2.0, 2.5, 2.5],
                       "C": [3.0, 3.0, 3.0, 3.0, 1.0, 1.0]},
                      index=[f"r{i}" for i in range(6)])
GROUPS = pd.Series(["g1", "g1", "g2", "g2", "g3", "g3"], index=VALUES.index)


def mean_score(values, groups):
    return float(values.mean())


def test_leave_one_group_out_masks():
    folds = leave_one_group_out(GROUPS)
    assert [f[0] for f in folds] == ["g1", "g2", "g3"]
    for name, train, test in folds:
        assert list(GROUPS[test].unique()) == [name] and name not in set(GROUPS[train])
        assert (train ^ test).all()


def test_cross_validation_on_a_hand_built_table():
    folds, held_out, chosen = cross_validate(VALUES, GROUPS, mean_score)
    # without g1: A = (1+1+2.5+2.5)/4 = 1.75, B = 2.25, C = 2.0 -> A; without g2: the same -> A;
    # without g3: A = 1, B = 2, C = 3 -> A. A everywhere, so the held-out figures are A's.
    assert list(folds["chosen"]) == ["A", "A", "A"] and chosen == "A"
    assert folds["train_score"].tolist() == pytest.approx([1.75, 1.75, 1.0])
    assert folds["test_score"].tolist() == pytest.approx([1.0, 1.0, 2.5])
    assert held_out.tolist() == VALUES["A"].tolist()
    # weighting groups the same: C's win on g3 outweighs (A: mean of 1, 1, 2.5 = 1.5; C: 2.33)
    spec = TuneSpec.from_dict({"objective": "armse_3d_m", "weight": "group"})
    assert spec.score_function()(VALUES["C"], GROUPS) == pytest.approx(7 / 3)
    maximise = TuneSpec.from_dict({"objective": "stance_f1", "direction": "maximize"}).score_function()
    assert cross_validate(VALUES, GROUPS, maximise)[2] == "C"  # highest mean of group means (2.33)


def test_a_failed_run_is_never_chosen():
    values = VALUES.copy()
    values.loc["r0", "A"] = np.nan
    score = TuneSpec.from_dict({"objective": "armse_3d_m"}).score_function()
    _, _, chosen = cross_validate(values, GROUPS, score)
    assert chosen == "B"  # A has a missing run; B (mean of group means 2.17) beats C (2.33)


def test_select_recommended_is_a_call_of_footzoos_cross_validation():
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import select_recommended as sr

    # 2 walking trials, 1 running, 1 slow unusual; PyShoe's best 1 m everywhere: the ratio is the error
    trials = ["2017-11-22-a", "2017-11-22-b", "2017-11-27-a", "2018-02-09-a"]
    err = pd.DataFrame({"s1": [1.0, 1.0, 4.0, 1.0], "s2": [2.0, 2.0, 1.0, 3.0]}, index=trials)
    best = pd.Series(1.0, index=trials)
    folds, held_out, final = sr.cross_validate(err, best)
    # per class, the mean log ratio: s1 walking 0, running log 4, slow 0; s2 walking log 2, running 0, slow log 3.
    # held out walking: s1 = log 4 / 2 = 0.69, s2 = log 3 / 2 = 0.55 -> s2; held out running: s1 = 0 -> s1;
    # held out slow: s1 = 0.69, s2 = log 2 / 2 = 0.35 -> s2; on all: s1 = log 4 / 3 = 0.46, s2 = log 6 / 3 = 0.60 -> s1
    assert folds["held-out class"].tolist() == ["walking", "running/fast", "slow unusual"]
    assert folds["chosen on the other classes"].tolist() == ["s2", "s1", "s2"]
    assert final == "s1"
    assert held_out.to_dict() == {"2017-11-22-a": 2.0, "2017-11-22-b": 2.0, "2017-11-27-a": 4.0, "2018-02-09-a": 3.0}


def test_random_search_draws_from_the_space():
    space = {"detector.threshold": {"low": 1e3, "high": 1e6, "log": True}, "detector.window": [3, 5],
             "x.n": {"low": 1, "high": 10, "integer": True}}
    a, b = sample_space(space, 8, seed=1), sample_space(space, 8, seed=1)
    assert a == b and len(a) == 8
    assert all(1e3 <= s["detector.threshold"] <= 1e6 and s["detector.window"] in (3, 5)
               and isinstance(s["x.n"], int) and 1 <= s["x.n"] <= 10 for s in a)
    logs = np.log10([s["detector.threshold"] for s in sample_space(space, 60, seed=2)])
    assert (logs < 4.5).any() and (logs > 4.5).any()  # log-uniform: both decades' halves


def test_tune_spec_errors():
    with pytest.raises(ConfigError, match=r"unknown tune key 'objectiv'"):
        TuneSpec.from_dict({"objective": "armse_3d_m", "objectiv": 1})
    with pytest.raises(ConfigError, match=r"not a metric \(did you mean 'armse_3d_m'\?\)"):
        TuneSpec.from_dict({"objective": "armse_3d"})
    with pytest.raises(ConfigError, match="random needs tune.space"):
        TuneSpec.from_dict({"objective": "armse_3d_m", "search": "random"})
    with pytest.raises(ConfigError, match="low < high"):
        TuneSpec.from_dict({"objective": "armse_3d_m", "space": {"a.b": {"low": 2, "high": 1}}})


SIM = {"path": "straight", "n_strides": 5, "rate": 100, "noise": {"scale": 1}}
STUDY = {"name": "tuned", "base": "yun2012",
         "factors": {"detector.threshold": [10.0, 1.0]},  # 10 rad/s: the swings are stances too
         "recordings": [{"simulate": SIM, "seeds": [0, 1], "group": "day1"},
                        {"simulate": SIM, "seeds": [2, 3], "group": "day2", "label": "other"}]}


def test_one_group_is_refused_before_any_run(tmp_path):
    """A group_by that puts every recording in one group is named at once: no run, no cache folder."""
    study = {"name": "one_group", "base": "yun2012", "factors": {"detector.threshold": [0.5, 1.0]},
             "recordings": [{"simulate": SIM, "seeds": [0, 1]}]}
    with pytest.raises(ConfigError, match=r"group_by '\^\(\.\)' puts all 2 recording\(s\) in one group"):
        tune(study, {"objective": "armse_3d_m", "group_by": r"^(.)"}, out=tmp_path / "out")
    assert not (tmp_path / "out" / "cache").exists()
    (tmp_path / "tune.yaml").write_text(yaml.safe_dump({**study, "tune": {"objective": "armse_3d_m",
                                                                          "group_by": "^(.)"}}))
    assert main(["validate", str(tmp_path / "tune.yaml")]) == 2  # footzoo validate says it too


def test_no_recordings_at_all_are_refused_by_the_group_check():
    from footzoo.studies.tune import check_groups

    with pytest.raises(ConfigError, match="there are no recordings"):
        check_groups(pd.Series([], dtype=object, name="group"))


def test_tune_chooses_the_better_threshold_and_writes_its_config(tmp_path):
    result = tune(Study.from_dict(STUDY), {"objective": "armse_3d_m"}, out=tmp_path, quiet=True)
    assert result.best_ == "detector.threshold=1" and list(result.folds_["chosen"]) == [result.best_] * 2
    assert set(result.folds_.columns) == {"group", "recordings", "chosen", "train_score", "test_score"}
    assert (result.values_["detector.threshold=10"] > result.values_["detector.threshold=1"]).all()
    cfg = Pipeline.from_yaml(tmp_path / "best.yaml").to_dict()
    assert cfg["detector"]["threshold"] == 1.0 and cfg["name"] == "tuned"
    assert (tmp_path / "tune_folds.csv").exists() and (tmp_path / "tune_scores.csv").exists()
    again = tune(Study.from_dict(STUDY), {"objective": "armse_3d_m"}, out=tmp_path, quiet=True)
    assert again.best_ == result.best_ and again.values_.equals(result.values_)  # from the cache


# its threshold of 10 rad/s takes every sample for stance, which the run says (expected)
@pytest.mark.filterwarnings(ALL_STANCE)
# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_the_tune_command(tmp_path, capsys):
    d = {**STUDY, "tune": {"objective": "armse_3d_m", "config": "chosen.yaml"}}
    (tmp_path / "tune.yaml").write_text(yaml.safe_dump(d))
    assert main(["tune", str(tmp_path / "tune.yaml"), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "chosen on every group: detector.threshold=1" in out and "| day1 |" in out
    assert Pipeline.from_yaml(tmp_path / "chosen.yaml").to_dict()["detector"]["threshold"] == 1.0
    study, spec = load_tune_file(tmp_path / "tune.yaml")
    assert [r.group for r in study.recordings] == ["day1", "day1", "day2", "day2"]
    nogroup = {**STUDY, "recordings": [{"simulate": SIM, "seeds": [0]}], "tune": {"objective": "armse_3d_m"}}
    (tmp_path / "nogroup.yaml").write_text(yaml.safe_dump(nogroup))
    assert main(["tune", str(tmp_path / "nogroup.yaml"), "--out", str(tmp_path / "o2")]) == 2
    assert "has no group" in capsys.readouterr().err


def test_optuna_search_finds_the_better_threshold_with_nested_folds(tmp_path):
    pytest.importorskip("optuna")
    study = {k: v for k, v in STUDY.items() if k != "factors"}
    spec = {"objective": "armse_3d_m", "search": "optuna", "trials": 8, "seed": 3,
            "space": {"detector.threshold": [10.0, 1.0]}}
    result = tune(Study.from_dict(study), spec, out=tmp_path, quiet=True)
    assert result.best_ == "detector.threshold=1" and list(result.folds_["chosen"]) == [result.best_] * 2
    assert set(result.values_.columns) == {"detector.threshold=10", "detector.threshold=1"}  # each run once
    assert (result.values_["detector.threshold=10"] > result.values_["detector.threshold=1"]).all()
    # each fold's score on its held-out group is the chosen setting's own, as in the grid search
    for row in result.folds_.itertuples():
        held = result.groups_ == row.group
        assert row.test_score == pytest.approx(result.values_.loc[held, row.chosen].mean())
    assert Pipeline.from_yaml(tmp_path / "best.yaml").to_dict()["detector"]["threshold"] == 1.0
    again = tune(Study.from_dict(study), spec, out=tmp_path, quiet=True)  # seeded: the same proposals
    assert again.folds_.equals(result.folds_)


def test_optuna_search_without_optuna_names_the_fix(monkeypatch):
    monkeypatch.setitem(sys.modules, "optuna", None)  # import optuna raises ImportError
    study = {k: v for k, v in STUDY.items() if k != "factors"}
    spec = {"objective": "armse_3d_m", "search": "optuna", "space": {"detector.threshold": [10.0, 1.0]}}
    with pytest.raises(ConfigError, match=r"pip install 'footzoo\[tune\]'"):
        tune(Study.from_dict(study), spec, quiet=True)
    with pytest.raises(ConfigError, match="optuna needs tune.space"):
        TuneSpec.from_dict({"objective": "armse_3d_m", "search": "optuna"})


def test_the_edges_of_a_grid_and_of_a_range_are_named_with_a_next_value():
    from footzoo.studies.tune import grid_edges

    grid = {"detector.threshold": [1e4, 1e5, 1e6], "detector.window": [0.2, 0.4, 0.6, 0.8],
            "detector.type": ["shoe", "ared", "amvd"], "x.two": [1.0, 2.0]}
    chosen = {"base": "b", "detector.threshold": 1e6, "detector.window": 0.4, "detector.type": "shoe", "x.two": 2.0}
    edges = grid_edges(chosen, grid)
    # log-spaced: one more decade; the middle of a grid, a type and a two-level factor: no edge
    assert edges == ["detector.threshold = 1e+06 is the largest value of the grid [10000, 100000, 1e+06]: the best "
                     "may lie beyond it; extend the grid above (next: 1e+07)"]
    edges = grid_edges({**chosen, "detector.window": 0.2}, grid)
    assert "detector.window = 0.2 is the smallest value of the grid [0.2, 0.4, 0.6, 0.8]" in edges[1]
    assert edges[1].endswith("extend the grid below (next: 0.1)")  # the step would reach 0: half instead
    space = {"detector.threshold": {"low": 1e3, "high": 1e6, "log": True}, "a.b": {"low": 0.0, "high": 1.0}}
    assert grid_edges({"detector.threshold": 1.2e3, "a.b": 0.5}, space) == [
        "detector.threshold = 1200 is at the low end of the range [1000, 1e+06] searched: the best may lie beyond "
        "it; extend the range (e.g. low: 100)"]
    assert grid_edges({"detector.threshold": 3e4, "a.b": 0.97}, space)[0].startswith("a.b = 0.97 is at the high end")


def test_tune_says_when_the_chosen_value_is_the_grid_s_edge(tmp_path):
    study = Study.from_dict({**STUDY, "factors": {"detector.threshold": [10.0, 3.0, 1.0]}})
    with pytest.warns(FootzooWarning, match=r"tune: the chosen detector.threshold = 10 is the largest value of the "
                                            r"grid \[1, 3, 10\].*extend the grid above \(next: 33.3333\)"):
        result = tune(study, {"objective": "armse_3d_m"}, out=tmp_path, quiet=True,
                      eligible=lambda name: name == "detector.threshold=10")  # forced to the edge
    assert result.best_ == "detector.threshold=10" and len(result.edges_) == 1
    assert "# at the edge: detector.threshold = 10 is the largest value" in (tmp_path / "best.yaml").read_text()



def test_a_grid_of_one_value_is_said_to_compare_nothing(tmp_path):
    study = Study.from_dict({**STUDY, "factors": {"detector.threshold": [3.0]}})
    with pytest.warns(FootzooWarning, match=r"tune: only one setting was scored \(detector.threshold=3\): nothing was "
                                            r"compared.*two or more values"):
        result = tune(study, {"objective": "armse_3d_m"}, out=tmp_path, quiet=True)
    assert result.best_ == "detector.threshold=3"

def test_a_recording_that_cannot_give_the_objective_is_named_as_left_out(tmp_path):
    """A recording without a reference gives no ``armse_3d_m``: the tune says it is left out, not just fewer rows."""
    from footzoo.io.canonical import write
    from footzoo.sim import simulate

    bare = simulate(**{k: v for k, v in SIM.items() if k != "noise"})
    bare.truth = None
    write(bare, tmp_path / "bare.csv")
    d = {**STUDY, "recordings": [*STUDY["recordings"], {"path": str(tmp_path / "bare.csv"), "group": "day3"}]}
    with pytest.warns(FootzooWarning, match=r"tune: 1 of 5 recording\(s\) gave no armse_3d_m in any setting and are "
                                            r"left out of the cross-validation: \['bare'\]"):
        result = tune(Study.from_dict(d), {"objective": "armse_3d_m"}, out=tmp_path / "out", quiet=True)
    assert "bare" not in result.values_.index and result.groups_.nunique() == 2
    assert "left out of the cross-validation" in (tmp_path / "out" / "footzoo.log").read_text()


def test_a_geometric_mean_of_a_signed_objective_is_refused_not_scored_nan():
    """gmean of a signed error (a negative stride-length bias) is NaN: the grid's first value would "win"."""
    import pandas as pd

    from footzoo.core.errors import ConfigError
    from footzoo.studies.tune import TuneSpec

    score = TuneSpec(objective="stride_length_mean_error_m", aggregate="gmean").score_function()
    groups = pd.Series(["a", "b"])
    assert score(pd.Series([0.02, 0.08]), groups) == pytest.approx(0.05)  # per group, then their mean
    with pytest.raises(ConfigError, match=r"gmean needs positive values of the objective, but "
                                          r"'stride_length_mean_error_m' is -0.03 on a recording.*aggregate: mean"):
        score(pd.Series([0.02, -0.03]), groups)


def test_a_space_with_a_grid_search_is_refused_not_ignored():
    from footzoo.core.errors import ConfigError
    from footzoo.studies.tune import TuneSpec

    with pytest.raises(ConfigError, match=r"tune.space is searched by search: random or optuna; with search: grid"):
        TuneSpec.from_dict({"objective": "armse_3d_m", "space": {"detector.threshold": [0.5, 0.6]}})
