"""The level-stance height update (``height_level``): its rows by hand, and what it does on the simulator's truth."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from footzoo import ConfigError, Pipeline
from footzoo.config.library import path as config_path
from footzoo.corrections.height_level import (
    CHANGES,
    ENDS_SEEN,
    LEVEL,
    ON_LEVEL,
    HeightLevel,
    level_after,
    level_measure,
)
from footzoo.filters.measurement import ATT, POS, VEL, Context, P, Rows
from footzoo.sim import NoiseModel, simulate


def _ctx(model, height: float, stance: bool, k: int = 5) -> Context:
    nav = np.zeros(16)
    nav[P + 2] = height
    idx = np.full(5, -1)
    idx[[ATT, POS, VEL]] = [0, 3, 6]
    return Context(k, 0.01 * k, nav, np.zeros(3), np.array([0.0, 0.0, -9.81]), stance, idx, model.par, model.mem,
                   np.zeros(0))


def _rows(n: int = 4) -> Rows:
    return Rows(np.zeros(n), np.zeros((n, 9)), np.zeros(n), 0)


def test_the_height_row_by_hand():
    """After a stance that ended at p_d = −0.30 m, a stance sample at −0.34 m (4 cm higher, within 0.1 m) gives one
    row z = p̂_d − h = −0.04 on δp_d with R = σ² = 1e-4 m²; at −0.45 m (15 cm: a stair riser) and in swing, none."""
    model = HeightLevel(threshold=0.1, height_std=0.01).model(None)
    rows = _rows()
    assert level_measure(_ctx(model, -0.34, True), rows) == 0  # no stance has ended yet: no reference
    model.mem[ENDS_SEEN], model.mem[LEVEL] = 1.0, -0.30
    assert level_measure(_ctx(model, -0.34, True), rows) == 1
    assert rows.z[0] == pytest.approx(-0.04, abs=1e-15)
    assert rows.R[0] == pytest.approx(1e-4, rel=1e-15)
    expected = np.zeros(9)
    expected[3 + 2] = 1.0
    np.testing.assert_array_equal(rows.H[0], expected)
    assert level_measure(_ctx(model, -0.45, True), _rows()) == 0
    assert level_measure(_ctx(model, -0.34, False), _rows()) == 0


def test_each_stance_end_sets_the_level_and_is_counted():
    """The first swing sample after a stance stores that stance's last height; a stance that ended within the
    threshold of the level before counts as on its level, one beyond it as a level change (a stair)."""
    model = HeightLevel(threshold=0.1).model(None)
    heights = [(0.0, True), (0.0, True), (-0.2, False),  # the start's stance ends at 0
               (-0.01, True), (-0.3, False),  # on its level (1 cm)
               (-0.18, True), (-0.5, False)]  # 17 cm up: a new level
    for k, (h, stance) in enumerate(heights, start=1):
        level_after(_ctx(model, h, stance, k))
    assert model.mem[ENDS_SEEN] == 3
    assert model.mem[LEVEL] == pytest.approx(-0.18)
    assert (model.mem[ON_LEVEL], model.mem[CHANGES]) == (1, 1)
    d = model.diagnostics(model.mem)["height_level"]
    # the stance held landed 20 cm up (the swing's last height, -0.2) and ended 1 cm up: it counts its landing
    assert d == {"stances_on_level": 1, "level_changes": 1, "held_landing_mean_m": pytest.approx(0.2),
                 "held_landing_max_m": pytest.approx(0.2)}


def _without_height(cfg: dict) -> dict:
    out = copy.deepcopy(cfg)
    out["corrections"] = [c for c in out["corrections"] if c["type"] != "height_level"]
    return out


@pytest.fixture(scope="module")
def recommended() -> dict:
    cfg = yaml.safe_load(config_path("recommended").read_text())
    assert any(c["type"] == "height_level" for c in cfg["corrections"])
    return cfg


def test_a_flat_walk_ends_at_its_true_height(recommended):
    """30 simulated strides on a flat floor (the simulator's sensor noise and biases): without the update the end
    height drifts 12 cm from the truth (measured), with it by less than 1 cm, every stance on one level, and
    the swings landed within millimetres of it."""
    walk = simulate(n_strides=30, profile="physical", rate=100.0, noise=NoiseModel(seed=3))
    plain = Pipeline.from_dict(_without_height(recommended)).run(walk)
    held = Pipeline.from_dict(recommended).run(walk)
    assert abs(plain.pos[-1, 2] - walk.truth.pos[-1, 2]) > 0.05
    assert abs(held.pos[-1, 2] - walk.truth.pos[-1, 2]) < 0.01
    d = held.diagnostics["height_level"]
    assert (d["stances_on_level"], d["level_changes"]) == (29, 0)
    # the swings landed within millimetres of their level (the simulator's floor is flat): no slope to report
    assert abs(d["held_landing_mean_m"]) < 0.01 and d["held_landing_max_m"] < 0.03


def test_a_staircase_keeps_its_steps(recommended):
    """Simulated stairs (2.2 m up in six strides, a landing, down again): every stride on the stairs climbs more
    than the threshold, so it starts a new level, and the top is reached within 1 cm; the landing's stances are
    held level."""
    st = simulate(path="stairs", n_strides=6, landing_strides=3, cycle=1.2, rate=100.0, profile="physical",
                  clearance=0.1, noise=NoiseModel(seed=0))
    up = -(st.truth.pos[:, 2] - st.truth.pos[0, 2])
    top = int(np.argmax(up))
    assert up[top] > 2.0
    res = Pipeline.from_dict(recommended).run(st)
    est = -(res.pos[:, 2] - res.pos[0, 2])
    assert abs(est[top] - up[top]) < 0.01
    d = res.diagnostics["height_level"]
    assert d["level_changes"] >= 2 * 6 - 1 and d["stances_on_level"] >= 2


@pytest.mark.parametrize("rise", [0.06, 0.04])
def test_low_stairs_are_kept_above_the_threshold_and_flattened_below_it(recommended, rise):
    """The same stairs with 6 cm risers (12 cm per stride, above the 0.1 m threshold): the climb is kept; with 4 cm
    risers (8 cm per stride, below it): flattened, as the docstring's limits say, and the stances held show it,
    each landing about 8 cm off its level."""
    st = simulate(path="stairs", n_strides=6, landing_strides=3, cycle=1.2, rate=100.0, profile="physical",
                  clearance=0.1, noise=NoiseModel(seed=0), rise=rise)
    up = -(st.truth.pos[:, 2] - st.truth.pos[0, 2])
    top = int(np.argmax(up))
    res = Pipeline.from_dict(recommended).run(st)
    est = -(res.pos[:, 2] - res.pos[0, 2])
    d = res.diagnostics["height_level"]
    if 2 * rise > 0.1:
        assert abs(est[top] - up[top]) < 0.01 and d["level_changes"] >= 11
    else:
        assert est[top] < up[top] / 2 and d["level_changes"] == 0
        assert d["held_landing_max_m"] == pytest.approx(2 * rise, abs=0.025)


@pytest.mark.parametrize("threshold", [0.0, -0.1, 2.0, float("nan")])
def test_a_threshold_outside_its_range_is_refused_with_its_unit(threshold):
    with pytest.raises(ConfigError, match=r"threshold.*m"):
        Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": "shoe"},
                            "corrections": [{"type": "zupt"}, {"type": "height_level", "threshold": threshold}]})
