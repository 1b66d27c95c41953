"""benchmarks/nested_cv.py and select_nested.py: outer folds, the inner choice that never sees them, and the rule
for changing ``recommended``, on small hand-built tables (the real selection needs ../shared/data and runs in the
benchmark)."""

import numpy as np
import pandas as pd
import pytest

from footzoo import Pipeline

from ..conftest import load_benchmark


@pytest.fixture(scope="module")
def cv():
    return load_benchmark("nested_cv")


@pytest.fixture(scope="module")
def nested():
    return load_benchmark("select_nested")


def pyshoe_like_classes():
    """PyShoe's class sizes: 23 walking, 10 running/fast, 2 slow unusual, 1 inverted."""
    sizes = {"walking": 23, "running/fast": 10, "slow unusual": 2, "inverted": 1}
    labels = [c for c, n in sizes.items() for _ in range(n)]
    return pd.Series(labels, index=[f"t{i:02d}" for i in range(len(labels))])


def test_stratified_folds_spread_every_class_and_repeat_with_the_seed(cv):
    classes = pyshoe_like_classes()
    folds = cv.stratified_folds(classes, 6, seed=0)
    assert folds.value_counts().sort_index().tolist() == [6] * 6
    per_class = pd.crosstab(folds, classes)
    assert set(per_class["walking"]) == {3, 4} and set(per_class["running/fast"]) == {1, 2}
    # the small classes sit in different folds, not all in the last one
    small = per_class[["slow unusual", "inverted"]].sum(axis=1)
    assert small.max() == 1 and small.sum() == 3
    assert cv.stratified_folds(classes, 6, seed=0).equals(folds)
    assert not cv.stratified_folds(classes, 6, seed=1).equals(folds)
    with pytest.raises(ValueError, match="k = 1 folds for 36 trials"):
        cv.stratified_folds(classes, 1, seed=0)


def test_the_inner_choice_never_sees_the_outer_fold(cv):
    classes = pyshoe_like_classes()
    folds = cv.stratified_folds(classes, 6, seed=3)
    rng = np.random.default_rng(0)
    errors = pd.DataFrame(rng.uniform(0.02, 0.2, size=(len(classes), 3)), index=classes.index, columns=list("ABC"))
    seen = []

    def spy(e, strata):
        seen.append(set(e.index))
        assert strata.index.equals(e.index)
        return str(e.mean().idxmin())

    chosen, held_out = cv.nested_choice(errors, classes, folds, spy)
    assert len(seen) == 6
    for f, rows in zip(sorted(folds.unique()), seen, strict=True):
        test = set(folds.index[folds == f])
        assert rows.isdisjoint(test) and rows | test == set(classes.index)
        assert held_out[list(test)].tolist() == errors.loc[list(test), chosen[f]].tolist()


def test_nested_choice_by_hand(cv):
    # 3 folds of 2 trials; the inner choice: the lowest mean error on the training trials
    errors = pd.DataFrame({"A": [1.0, 1.0, 1.0, 1.0, 9.0, 9.0], "B": [2.0, 2.0, 2.0, 2.0, 2.0, 2.0]},
                          index=list("abcdef"))
    folds = pd.Series([0, 0, 1, 1, 2, 2], index=errors.index)
    strata = pd.Series("walking", index=errors.index)
    chosen, held_out = cv.nested_choice(errors, strata, folds, lambda e, s: str(e.mean().idxmin()))
    # without fold 0: A (1+1+9+9)/4 = 5 vs B 2 -> B; the same without fold 1; without fold 2: A 1 vs B 2 -> A
    assert chosen.tolist() == ["B", "B", "A"]
    assert held_out.tolist() == [2.0, 2.0, 2.0, 2.0, 9.0, 9.0]
    # the procedure against the fixed settings: worse median than A (2 vs 1); B has the better worst (2 vs 9) but
    # the same median (2): neither improves on the other by the rule, which needs both
    assert not cv.improves(held_out, errors["A"]) and not cv.improves(errors["B"], held_out)
    assert errors["B"].max() < held_out.max() and errors["B"].median() == held_out.median()
    three_d = errors * 10
    assert cv.held_out_of(chosen, folds, three_d).tolist() == [20.0, 20.0, 20.0, 20.0, 90.0, 90.0]


def test_improves_needs_median_and_worst_and_counts_a_failure_as_worst(cv):
    base = pd.Series([1.0, 2.0, 3.0])
    assert cv.improves(pd.Series([0.5, 1.5, 2.5]), base)
    assert not cv.improves(pd.Series([0.5, 1.5, 3.0]), base)  # the worst only ties
    assert not cv.improves(pd.Series([1.0, 2.0, 2.5]), base)  # the median only ties
    assert not cv.improves(pd.Series([0.5, 1.5, np.nan]), base)  # a failed run is not an absent one


def _rule_inputs(nested, xio_final):
    b, s = nested.BASELINE, nested.START
    err2 = pd.DataFrame({b: [0.05, 0.06, 0.20], s: [0.06, 0.07, 0.15], "X": [0.04, 0.05, 0.10]})
    other = pd.DataFrame({col: [1.0, 1.0, 1.0] for col in nested.CHECKS}, index=[b, s, "X"])
    other["gaitmap strides paired"] = 56
    other.loc["X", "x-io loop closure (m)"] = xio_final
    other.loc[s, "x-io loop closure (m)"] = 2.0
    return err2, other


def test_the_rule_ships_a_choice_only_when_it_is_no_worse_elsewhere(nested):
    err2, other = _rule_inputs(nested, xio_final=1.0)
    held = err2["X"]  # the procedure chose X on every fold
    assert nested.decide(held, err2, "X", other)[0] == "X"
    err2, other = _rule_inputs(nested, xio_final=1.5)  # X worse on x-io's loop than the baseline
    # the start has the better worst (0.15 vs 0.20) but not the median (0.07 vs 0.06), and is worse on x-io:
    # the baseline stays
    assert nested.decide(held, err2, "X", other)[0] == nested.BASELINE
    err2[nested.START] = [0.04, 0.05, 0.15]  # now better in median and worst, and as good on x-io
    other.loc[nested.START, "x-io loop closure (m)"] = 1.0
    decision, why = nested.decide(held, err2, "X", other)
    assert decision == nested.START and "reverted" in why


def test_the_baseline_is_the_shipped_recommended(nested):
    cands = {c["name"]: c for c in nested.candidates()}
    assert len(cands) == 12 + len(nested.ROLLING) + len(nested.HUANG) and nested.START in cands
    ours = Pipeline.from_dict(cands[nested.BASELINE]).to_dict()
    shipped = Pipeline.from_yaml("recommended").to_dict()
    ours.pop("name"), shipped.pop("name")
    assert ours == shipped


def test_the_huang_candidates_swap_only_the_shipped_detector(nested):
    cands = {c["name"]: c for c in nested.candidates()}
    shipped = Pipeline.from_yaml("recommended").to_dict()
    shipped.pop("name"), shipped.pop("detector")
    grid = set()
    for name in nested.HUANG:
        ours = Pipeline.from_dict(cands[name]).to_dict()
        detector = ours.pop("detector")
        ours.pop("name")
        assert ours == shipped and detector["type"] == "huang_stance"
        grid.add((detector["threshold"], detector["min_duration"]))
    # the 3 x 2 grid, the detector's own defaults (3e4, 0.05 s) among it
    assert grid == {(th, md) for th in (1.5e4, 3e4, 6e4) for md in (0.05, 0.1)}
    assert "huang_stance th 30000 min 0.05" in cands


def test_written_configs_are_twins_but_for_the_smoother(nested, tmp_path):
    cfg = next(c for c in nested.candidates() if c["name"] == "rolling_stance")
    stats = {"2-D median": 0.045, "2-D worst": 0.17, "3-D median": 0.11}
    nested.write_configs(cfg, stats, stats, tmp_path)
    offline = Pipeline.from_yaml(tmp_path / "recommended.yaml").to_dict()
    live = Pipeline.from_yaml(tmp_path / "recommended_live.yaml").to_dict()
    assert (offline.pop("name"), live.pop("name")) == ("recommended", "recommended_live")
    assert (offline.pop("smoother"), live.pop("smoother")) == ("rts", "stepwise")
    assert offline == live and offline["corrections"][0]["type"] == "rolling_stance"
    assert "2-D median\n# 0.0450 m" in (tmp_path / "recommended.yaml").read_text()


def test_by_class_by_hand(nested):
    err2 = pd.DataFrame({"A": [0.01, 0.03, 0.5, np.nan]}, index=["2017-w1", "2017-w2", "2017-r1", "2017-r2"])
    classes = pd.Series(["walking", "walking", "running/fast", "running/fast"], index=err2.index)
    row = nested.by_class(err2, classes, ["A"]).iloc[0]
    # walking: median of 0.01 and 0.03; running: 0.5 and a failed run (infinitely wrong)
    assert row["walking"] == pytest.approx(0.02) and row["running/fast"] == np.inf
    assert (row["worst trial"], row["worst (m)"], row["trials over 0.2 m"]) == ("r2", np.inf, 2)
