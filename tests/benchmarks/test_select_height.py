"""benchmarks/select_height.py: its candidates, fixed procedure and "no worse" (the run needs PyShoe's trials)."""

import numpy as np
import pandas as pd
import pytest
import yaml

from footzoo.config.library import path as config_path
from footzoo.corrections.height_level import HeightLevel

from ..conftest import load_benchmark


@pytest.fixture(scope="module")
def sh():
    return load_benchmark("select_height")


def test_the_baseline_is_recommended_without_the_update_and_the_default_is_shipped(sh):
    shipped = yaml.safe_load(config_path("recommended").read_text())
    cands = {c["name"]: c for c in sh.candidates()}
    base = cands[sh.BASELINE]
    assert [c["type"] for c in base["corrections"]] == ["zupt"]
    assert {k: v for k, v in base.items() if k not in ("name", "corrections")} == \
        {k: v for k, v in shipped.items() if k not in ("name", "corrections")}
    level = [c for c in shipped["corrections"] if c["type"] == "height_level"]
    assert level == [{"type": "height_level", "threshold": sh.DEFAULT, "height_std": 0.01}]
    assert sh.DEFAULT == HeightLevel().threshold  # the plug-in's default, fixed before the folds ran
    assert cands[sh.name_of(sh.DEFAULT)]["corrections"] == shipped["corrections"]


def test_the_inner_choice_scores_each_class_equally(sh):
    """Two classes: candidate a is better on the big class, b on the small one by more (log scale): b wins."""
    classes = pd.Series(["walk"] * 4 + ["run"], index=list("vwxyz"))
    errors = pd.DataFrame({"a": [0.05] * 4 + [0.4], "b": [0.06] * 4 + [0.1]}, index=classes.index)
    assert sh.choose(errors, classes) == "b"
    assert sh.log_score(errors["a"], classes) == pytest.approx((np.log(0.05) + np.log(0.4)) / 2)


def test_no_worse_allows_the_resolution_not_more(sh):
    assert sh.no_worse(0.05001, 0.05, "min")  # 10 µm on a 5 cm RMS: 0.02 %
    assert not sh.no_worse(0.0501, 0.05, "min")
    assert sh.no_worse(56, 56, "max", count=True) and not sh.no_worse(55, 56, "max", count=True)


def test_every_other_selection_keeps_the_shipped_height_update():
    """select_recommended.py's and --nested's candidates (and so what their --write would ship) keep it."""
    sr, sn = load_benchmark("select_recommended"), load_benchmark("select_nested")
    shipped = yaml.safe_load(config_path("recommended").read_text())["corrections"]
    assert sr.shipped_height() == [c for c in shipped if c["type"] == "height_level"] != []
    assert all(c["corrections"][-1] == sr.shipped_height()[0] for c in sn.candidates())
