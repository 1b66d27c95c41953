"""The stillness hold of the zero-velocity updates (``hold_after`` of ``zupt`` / ``ekf_zupt``).

See footzoo.corrections.stillness.
"""

from __future__ import annotations

import numpy as np
import pytest

from footzoo import Pipeline
from footzoo.config import BUILTIN
from footzoo.core.yamlsafe import load_file
from footzoo.corrections.ekf_zupt import HOLD, HOLD_STATE, ZUPT, zero_velocity_after, zero_velocity_measure
from footzoo.corrections.stillness import ANCHOR, HOLDING
from footzoo.filters.measurement import ATT, POS, VEL, Context, P, Rows, V
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate

#: A consumer-grade MEMS accelerometer's bias (m/s², per axis; about 15-20 mg) and a 0.2 °/s gyroscope bias.
MEMS = {"acc_bias": (0.15, -0.10, 0.20), "gyr_bias": float(np.radians(0.2))}


def _stand(seconds: float, rate: float = 100.0, **noise) -> object:
    """A sensor lying level and still for ``seconds`` (simulated noise and biases)."""
    return simulate(path="straight", n_strides=0, stand_start=seconds, stand_end=0.0, rate=rate,
                    noise=NoiseModel(seed=1, **noise), magnetometer=False, distance_sensors=True)


def _with_hold(name: str, hold_after: float) -> Pipeline:
    cfg = load_file(BUILTIN / f"{name}.yaml", ValueError, "config")
    for c in cfg["corrections"]:
        if c["type"] in ("zupt", "ekf_zupt"):
            c["hold_after"] = hold_after
    return Pipeline.from_dict(cfg)


def _ctx(model, stance=True, w=(0.0, 0.0, 0.0)):
    nav = np.zeros(16)
    nav[V:V + 3] = [0.01, -0.02, 0.005]
    nav[P:P + 3] = [1.0, 2.0, -0.3]
    idx = np.full(5, -1)
    idx[[ATT, POS, VEL]] = [0, 3, 6]
    return Context(0, 10.0, nav, np.array(w, float), np.array([0.0, 0.0, -9.81]), stance, idx, model.par,
                   model.mem, np.zeros(0))


def test_the_rows_by_hand():
    """Held: three more rows z = p̂ − p_0, H = I on δp, R = hold_std²; not yet held or not still: none."""
    model = ZUPT(velocity_std=0.03, hold_after=2.0, hold_std=0.004).model(None)
    z, H, R = np.zeros(6), np.zeros((6, 9)), np.zeros(6)
    ctx = _ctx(model)
    assert zero_velocity_measure(ctx, Rows(z, H, R, 0)) == 3  # still, but not yet for 2 s
    model.mem[HOLD_STATE + HOLDING] = 1.0
    model.mem[HOLD_STATE + ANCHOR:HOLD_STATE + ANCHOR + 3] = [0.99, 2.01, -0.3]
    z[:], H[:], R[:] = 0.0, 0.0, 0.0
    assert zero_velocity_measure(ctx, Rows(z, H, R, 0)) == 6
    np.testing.assert_allclose(z[3:6], [0.01, -0.01, 0.0], atol=1e-15)
    np.testing.assert_array_equal(H[3:6, 3:6], np.eye(3))
    assert not H[3:6, [0, 1, 2, 6, 7, 8]].any()
    np.testing.assert_allclose(R[3:6], 0.004**2, rtol=1e-15)
    # a sample that turns faster than hold_rate (0.2 rad/s) is not still: no hold rows
    assert zero_velocity_measure(_ctx(model, w=(0.0, 0.25, 0.0)), Rows(z, H, R, 0)) == 3


def test_the_still_run_is_followed_in_after():
    """p_0 is the corrected position at the run's first still sample; the hold starts hold_after later and
    ends at the first sample that is not still."""
    model = ZUPT(hold_after=2.0).model(None)
    ctx = _ctx(model)
    zero_velocity_after(ctx._replace(t=10.0))
    np.testing.assert_array_equal(model.mem[HOLD_STATE + ANCHOR:HOLD_STATE + ANCHOR + 3], ctx.nav[P:P + 3])
    later = ctx.nav.copy()
    later[P] += 0.5
    zero_velocity_after(ctx._replace(t=11.99, nav=later))
    assert model.mem[HOLD_STATE + HOLDING] == 0.0
    assert model.mem[HOLD_STATE + ANCHOR] == ctx.nav[P]  # p_0 stays the run's first
    zero_velocity_after(ctx._replace(t=12.0, nav=later))
    assert model.mem[HOLD_STATE + HOLDING] == 1.0
    zero_velocity_after(ctx._replace(t=12.01, stance=False))
    assert model.mem[HOLD_STATE + HOLDING] == 0.0
    assert model.par[HOLD] == 2.0


def test_without_the_hold_a_standing_foot_creeps_at_half_a_sample_of_its_acceleration_error():
    """The mechanism, against a hand-derived rate: a level sensor with accelerometer bias b reads
    f = b + (0, 0, −g); the still-start alignment takes f's direction for the vertical, so the
    downward acceleration error is a = g − |f|. Zero-velocity updates leave the trapezoidal half
    step a·dt²/2 of every sample, so over T seconds the height drifts by a·dt/2·T whatever their
    gain (to first order: 1.8 % more here, the attitude rows' share). The hold keeps it within a
    centimetre."""
    rec = _stand(120.0, rate=100.0, acc_bias=MEMS["acc_bias"], acc_sigma=0.0, gyr_sigma=0.0, gyr_bias=0.0)
    a = 9.81 - np.linalg.norm(np.array(MEMS["acc_bias"]) + [0.0, 0.0, -9.81])
    expected = a * 0.01 / 2 * (rec.t[-1] - rec.t[0])
    off = _with_hold("duong2015_zupt", 0.0).run(rec).pos
    assert off[-1, 2] == pytest.approx(expected, rel=0.025)
    at_200hz = _stand(120.0, rate=200.0, acc_bias=MEMS["acc_bias"], acc_sigma=0.0, gyr_sigma=0.0, gyr_bias=0.0)
    assert _with_hold("duong2015_zupt", 0.0).run(at_200hz).pos[-1, 2] == pytest.approx(expected / 2, rel=0.025)
    on = _with_hold("duong2015_zupt", 2.0).run(rec).pos
    assert np.linalg.norm(on, axis=1).max() < 0.01


def test_a_walk_whose_stances_are_shorter_than_hold_after_is_the_same_to_the_bit():
    walk = simulate(n_strides=12, profile="physical", rate=100.0, stand_start=1.5, stand_end=0.5,
                    noise=NoiseModel(seed=3))
    for name in ("recommended", "nguyen2016"):
        np.testing.assert_array_equal(_with_hold(name, 2.0).run(walk).pos, _with_hold(name, 0.0).run(walk).pos)


@pytest.mark.slow
def test_a_stream_in_chunks_of_any_size_and_the_reference_engine_give_the_same_hold():
    rec = _stand(6.0, **MEMS)
    batch = _with_hold("recommended_live", 2.0).run(rec)
    assert np.abs(batch.pos).max() < 0.01
    live = Stream(_with_hold("recommended_live", 2.0), rate=rec.rate).run(rec, chunk=np.array([1, 7, 130]))
    np.testing.assert_allclose(live["pos"], batch.pos, rtol=0, atol=1e-9)
    rts = _with_hold("recommended", 2.0)
    np.testing.assert_allclose(rts.run(rec, engine="fast").pos, rts.run(rec, engine="reference").pos, rtol=0,
                               atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["recommended", "recommended_live", "nguyen2016", "duong2015", "duong2015_zupt",
                                  "duong2015_zupt_height"])
def test_ten_minutes_still_stay_within_a_centimetre_in_every_shipped_kalman_config(name):
    """Issue 44's target: 10 minutes lying still (consumer MEMS biases and noise, detected as stance
    throughout), |position| ≤ 0.01 m and height within 1 cm, offline and live."""
    rec = _stand(600.0, **MEMS)
    p = Pipeline.from_yaml(name)
    runs = {"offline": p.run(rec).pos}
    if not p.live_problems():
        runs["live"] = Stream(Pipeline.from_yaml(name), rate=rec.rate, guess=False).run(rec, chunk=500)["pos"]
    for how, pos in runs.items():
        assert np.linalg.norm(pos, axis=1).max() <= 0.01, how
        assert np.abs(pos[:, 2]).max() <= 0.01, how
