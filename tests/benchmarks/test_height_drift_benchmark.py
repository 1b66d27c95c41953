"""benchmarks/height_drift.py: its stance shortening and its configs (the full run needs PyShoe's trials)."""

from pathlib import Path

import numpy as np
import pytest

from footzoo.runtime.pipeline import Pipeline

from ..conftest import load_benchmark

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def hd():
    return load_benchmark("height_drift")


def test_shorten_stances_drops_seconds_at_each_inner_edge(hd):
    t = np.arange(0, 3.0, 0.01)  # 100 Hz
    stance = (t < 0.5) | ((t >= 1.0) & (t < 1.4)) | (t >= 2.0)
    out = hd.shorten_stances(stance, t, 0.04, 0.02)

    def span(lo, hi):
        i = np.flatnonzero(out & (t >= lo) & (t < hi))
        return t[i[0]], t[i[-1]]

    first, inner, last = span(0.0, 0.9), span(0.9, 1.9), span(1.9, 3.0)
    assert first[0] == 0.0 and abs(first[1] - 0.47) <= 0.011  # the still start keeps its start, loses 20 ms
    assert abs(inner[0] - 1.04) <= 0.011 and abs(inner[1] - 1.37) <= 0.011  # 40 ms off the start, 20 off the end
    assert abs(last[0] - 2.04) <= 0.011 and last[1] == t[-1]  # the still end keeps its end


def test_shorten_stances_keeps_three_samples_of_a_short_stance(hd):
    t = np.arange(0, 1.0, 0.01)
    stance = (t >= 0.4) & (t < 0.45)
    out = hd.shorten_stances(stance, t, 0.04, 0.04)
    assert out.sum() == 3 and out[[41, 42, 43]].all()


def test_no_trim_is_the_identity(hd):
    t = np.arange(0, 2.0, 0.005)
    stance = np.sin(2 * np.pi * t) > 0.2
    assert np.array_equal(hd.shorten_stances(stance, t, 0.0, 0.0), stance)


def test_every_variant_builds_and_the_baseline_is_recommended(hd):
    assert hd.LEVERS["recommended"] == hd.base_config()
    assert hd.GRID[hd.GRID_BASE]["corrections"] == hd.base_config()["corrections"]
    assert hd.GRID[hd.GRID_BASE]["navigation"] == hd.base_config()["navigation"]
    for cfg in [*hd.LEVERS.values(), *hd.GRID.values()]:
        Pipeline.from_dict(cfg)


def test_impact_weighted_prototype_passes_the_plugin_check_and_reduces_to_zupt(hd):
    import footzoo
    from footzoo.plugins.registry import get
    from footzoo.sim import simulate

    rec = simulate(path="rectangle", length=6.0, width=3.0, rate=100.0)
    plain = Pipeline.from_dict(hd.base_config()).run(rec).samples[["pos_n", "pos_e", "pos_d"]].to_numpy()
    cfg = hd.variant({"type": "impact_weighted_zupt", "velocity_std": 0.03, "impact_time": 0.0},
                     plugins=[str(hd.PROTOTYPE)])
    same = Pipeline.from_dict(cfg).run(rec).samples[["pos_n", "pos_e", "pos_d"]].to_numpy()
    np.testing.assert_allclose(same, plain, atol=1e-9)  # τ = 0 is recommended's zupt
    footzoo.check_plugin(get("correction", "impact_weighted_zupt"))  # loaded by the config's plugins: list
