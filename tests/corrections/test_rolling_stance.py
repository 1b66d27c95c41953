"""The rolling-foot stance update ``rolling_stance``: its rows by hand, its Jacobian, the simulator's rolling foot."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.core.conventions import quat_from_euler, quat_to_matrix
from footzoo.corrections.rolling_stance import (
    HEEL,
    Q_LAST,
    TOE,
    V_LAST,
    RollingStance,
    contact_feedback,
    contact_measure,
)
from footzoo.evaluation.metrics import stride_errors
from footzoo.filters.measurement import Context, Q, Rows, V
from footzoo.plugins.registry import build
from footzoo.sim import NoiseModel, simulate

#: The simulator's contact points (footzoo.sim.gait.FootGeometry: sensor to heel and to toe, FRD, m).
SIM_HEEL, SIM_TOE = [-0.10, 0.0, 0.06], [0.12, 0.0, 0.06]
#: Error-state layout of the hand cases: attitude, gyro bias, position, velocity, no accelerometer bias, then
#: the heel's and the toe's lever.
IDX = np.array([0, 3, 6, 9, -1, 12, 15])


def _rows(model, nav, w, stance=True):
    z, H, R = np.zeros(6), np.zeros((6, 18)), np.zeros(6)
    ctx = Context(0, 0.0, nav, np.asarray(w, float), np.zeros(3), stance, IDX, model.par, model.mem, np.zeros(0))
    return contact_measure(ctx, Rows(z, H, R, 0)), z, H, R


def _still_nav(q, v):
    nav = np.zeros(16)
    nav[Q:Q + 4] = q
    nav[V:V + 3] = v
    return nav


def test_a_level_foot_rolling_over_its_heel_by_hand():
    """Level foot (C = I), pitching toe-down at 2 rad/s (ω = (0, −2, 0)) about the heel c = (−0.1, 0, 0.06):
    ω × c = (−2·0.06 − 0, 0, 0 − (−2)(−0.1)) = (−0.12, 0, −0.2), so the sensor moves at −(ω × c) =
    (0.12, 0, 0.2) m/s (forward and down). With that velocity estimated the residual is 0; with the
    sensor estimated at rest it is (−0.12, 0, −0.2). σ² = 0.03² + (0.02 · 2)² on each row."""
    model = RollingStance(heel=[-0.1, 0.0, 0.06], toe=[0.1, 0.0, 0.06]).model(None)
    level = quat_from_euler(0.0, 0.0, 0.0)
    model.mem[Q_LAST:Q_LAST + 4] = level
    model.mem[V_LAST:V_LAST + 3] = [0.12, 0.0, 0.2]
    m, z, _, R = _rows(model, _still_nav(level, [0.12, 0.0, 0.2]), [0.0, -2.0, 0.0])
    assert m == 3
    np.testing.assert_allclose(z[:3], 0.0, atol=1e-15)
    np.testing.assert_allclose(R[:3], 0.03**2 + (0.02 * 2.0) ** 2, rtol=1e-15)
    model.mem[V_LAST:V_LAST + 3] = 0.0
    _, z, _, _ = _rows(model, _still_nav(level, [0.0, 0.0, 0.0]), [0.0, -2.0, 0.0])
    np.testing.assert_allclose(z[:3], [-0.12, 0.0, -0.2], atol=1e-15)
    # the toe explains a sensor rising (forward and up) on the same rotation: −(ω × (0.1, 0, 0.06)) = (0.12, 0, −0.2)
    model.mem[V_LAST:V_LAST + 3] = [0.12, 0.0, -0.2]
    _, z, H, _ = _rows(model, _still_nav(level, [0.12, 0.0, -0.2]), [0.0, -2.0, 0.0])
    np.testing.assert_allclose(z[:3], 0.0, atol=1e-15)
    assert not H[:3, 12:15].any() and H[:3, 15:18].any()  # the toe's lever columns, not the heel's
    assert _rows(model, _still_nav(level, [0.0, 0.0, 0.0]), [0.0, -2.0, 0.0], stance=False)[0] == 0


def test_the_jacobian_against_finite_differences():
    """H of every state the rows see (attitude, gyro bias, velocity, the lever) against the residual's change when
    the truth departs from the estimate by a small error, with footzoo's conventions: C = (I − [δφ×]) Ĉ,
    ω = ω̂ − δb, v = v̂ − δv, c = ĉ − δc."""
    from scipy.spatial.transform import Rotation

    model = RollingStance().model(None)
    q = quat_from_euler(0.2, -0.3, 1.1)
    model.mem[Q_LAST:Q_LAST + 4] = q
    v = np.array([0.1, -0.05, 0.02])
    model.mem[V_LAST:V_LAST + 3] = v
    w = np.array([0.4, -3.0, 0.7])
    _, z, H, _ = _rows(model, _still_nav(q, v), w)
    c = model.mem[HEEL:HEEL + 3] if not H[:3, 15:18].any() else model.mem[TOE:TOE + 3]
    own = 12 if not H[:3, 15:18].any() else 15
    C = quat_to_matrix(q)

    def h(C_, v_, w_, c_):
        return v_ + C_ @ np.cross(w_, c_)

    np.testing.assert_allclose(z[:3], h(C, v, w, c), atol=1e-15)
    eps, numeric = 1e-7, np.zeros((3, 18))
    for j in range(18):
        d = np.zeros(18)
        d[j] = eps
        truth = h(Rotation.from_rotvec(-d[0:3]).as_matrix() @ C, v - d[9:12], w - d[3:6], c - d[own:own + 3])
        numeric[:, j] = (z[:3] - truth) / eps
    np.testing.assert_allclose(H[:3], numeric, atol=2e-6)
    assert not H[:3, 6:9].any()  # no position column


def test_the_levers_are_fed_back_as_estimate_minus_truth():
    model = RollingStance().model(None)
    dx = np.zeros(18)
    dx[12:18] = [0.01, 0.02, 0.03, -0.01, 0.0, 0.005]
    before = model.mem[:6].copy()
    contact_feedback(Context(0, 0.0, np.zeros(16), np.zeros(3), np.zeros(3), True, IDX, model.par, model.mem,
                             np.zeros(0)), dx)
    np.testing.assert_allclose(model.mem[:6], before - dx[12:18])


@pytest.mark.parametrize("bad", [{"heel": [0.0, 0.0]}, {"toe": [0.0, 0.0, 0.9]}, {"contact_spread": -0.1}])
def test_bad_parameters_are_refused(bad):
    name = next(iter(bad))
    with pytest.raises(ConfigError, match=name):
        build("correction", {"type": "rolling_stance", **bad})  # a config
    with pytest.raises(ConfigError, match=name):
        RollingStance(**bad).check_params()  # made in Python: refused when a pipeline is given it


@pytest.fixture(scope="module")
def rolling_walk():
    """The simulator's physical foot rolls over its heel after initial contact and over its toes before toe-off
    (footzoo.sim.gait, exactly about the contact points), but its truth calls only the flat foot stance. The
    stance here is the whole ground contact: the roll phases too, as a detector that takes them for stance."""
    walk = simulate(n_strides=16, profile="physical", rate=200.0, noise=NoiseModel(seed=2))
    contact = walk.truth.stance.copy()
    for _, s in walk.truth.steps.iterrows():
        contact |= (walk.t > s["start"]) & (walk.t <= s["swing_start"])  # pre-swing: about the toes
        contact |= (walk.t > s["swing_end"]) & (walk.t <= s["end"] + 1e-9)  # initial contact: about the heel
    return walk, dataclasses.replace(walk, truth=dataclasses.replace(walk.truth, stance=contact))


def _run(rec, corrections):
    return Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": "oracle"},
                               "corrections": corrections}).run(rec)


def test_on_the_simulators_rolling_foot_it_learns_the_contact_points_and_keeps_the_strides(rolling_walk):
    """Zero-velocity rows stop a sensor that rolls: strides 0.46 m short; the rolling model learns the heel and
    the toe within 3 mm of the simulator's geometry from a prior 1-2 cm off, and keeps the strides within
    1 cm (measured 0.6 cm short), better than the zero-velocity update's rolling noise (roll_lever 0.2 m:
    2.0 cm short). With both, 1.3 cm short: the zero-velocity rows still pull while the simulated toe turns
    the foot at 9.4 rad/s until it leaves the floor."""
    walk, rec = rolling_walk

    def bias(res):
        e = stride_errors(res.steps, walk.truth.steps)
        assert e["matched_strides"] == e["ref_strides"] == 16
        return e["stride_length_mean_error_m"]

    zupt = bias(_run(rec, [{"type": "zupt", "velocity_std": 0.03}]))
    lever = bias(_run(rec, [{"type": "zupt", "velocity_std": 0.03, "roll_lever": 0.2}]))
    res = _run(rec, [{"type": "rolling_stance"}])
    rolling = bias(res)
    assert zupt < -0.2
    assert abs(rolling) < 0.01 and abs(rolling) < abs(lever)
    levers = res.diagnostics["contact_levers"]
    np.testing.assert_allclose(levers["heel"], SIM_HEEL, atol=0.003)
    np.testing.assert_allclose(levers["toe"], SIM_TOE, atol=0.003)
    # with the zero-velocity update: the same levers, the strides within 1.5 cm (and better than the lever alone)
    both = _run(rec, [{"type": "zupt", "velocity_std": 0.03, "roll_lever": 0.2, "hold_after": 0.0},
                      {"type": "rolling_stance"}])
    assert abs(bias(both)) < 0.015 and abs(bias(both)) < abs(lever)
    np.testing.assert_allclose(both.diagnostics["contact_levers"]["toe"], SIM_TOE, atol=0.003)


def test_where_the_foot_does_not_turn_it_is_the_zero_velocity_update():
    """Noise-free, on the flat-foot stance (the simulator's truth) ω = 0 and the velocity does not change in every
    stance sample: the rows are the zero-velocity rows with σ_r, and the positions agree with zupt's."""
    walk = simulate(n_strides=8, profile="physical", rate=100.0)
    a = _run(walk, [{"type": "zupt", "velocity_std": 0.03, "hold_after": 0.0}])
    b = _run(walk, [{"type": "rolling_stance", "lever_std": 0.0, "lever_noise": 0.0, "hold_after": 0.0}])
    np.testing.assert_allclose(b.pos, a.pos, atol=1e-6)
