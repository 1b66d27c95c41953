"""benchmarks/relabel.py: its relabelled cases and how it scores them, on a simulated walk (the real table needs
../shared/data and runs in the benchmark)."""

import math

import numpy as np
import pytest

from footzoo import Pipeline
from footzoo.core.conventions import ACC_UNITS
from footzoo.sim import NoiseModel, simulate

from ..conftest import load_benchmark

BASE = {"name": "physics", "orientation": {"type": "madgwick", "use_magnetometer": False},
        "detector": {"type": "angular_rate_fsm"}, "corrections": [{"type": "zvu_dedrift"}]}


@pytest.fixture(scope="module")
def relabel():
    return load_benchmark("relabel")


@pytest.fixture(scope="module")
def walk():
    return simulate("rectangle", n_strides=24, rate=100.0, noise=NoiseModel(seed=4))


def test_each_case_declares_the_recording_as_its_name_says(relabel, walk):
    cases = {c["case"]: c for c in relabel.cases("xio", walk)}  # x-io's files: g and deg/s
    assert cases["as recorded"]["rate"] == 100.0 and cases["as recorded"]["t"] is walk.t
    np.testing.assert_allclose(cases["rate ×2, time stamps"]["t"], walk.t / 2.0)
    np.testing.assert_allclose(np.diff(cases["rate ×½, rate only"]["t"]), 1.0 / 50.0)
    np.testing.assert_allclose(cases["gyroscope deg/s declared rad/s"]["gyr"], walk.gyr * 180.0 / math.pi)
    np.testing.assert_allclose(cases["accelerometer g declared m/s^2"]["acc"], walk.acc / ACC_UNITS["g"])
    np.testing.assert_allclose(cases["accelerometer g declared mg"]["acc"], walk.acc / 1000.0)
    assert "gyroscope deg/s declared deg/s" not in cases and len(cases) == 1 + 2 * 5 + 1 + 2


def test_a_case_is_right_only_with_the_real_rate_or_unit(relabel, walk):
    pipeline = Pipeline.from_dict(BASE)
    cases = {c["case"]: c for c in relabel.cases("pyshoe", walk)}  # PyShoe's files: m/s² and rad/s
    clean = relabel.run_case(pipeline, "walk", cases["as recorded"])
    assert not clean["caught"] and not clean["others"]
    twice = relabel.run_case(pipeline, "walk", cases["rate ×2, time stamps"])
    assert twice["caught"] and twice["right"] and twice["named"].startswith("rate 100 Hz")
    slow = relabel.run_case(pipeline, "walk", cases["gyroscope rad/s declared deg/s"])
    assert slow["caught"] and slow["right"]
    heavy = relabel.run_case(pipeline, "walk", cases["accelerometer m/s^2 declared g"])
    assert heavy["caught"] and heavy["right"] and "declare acc_unit: m/s^2" in heavy["named"]


def test_the_summary_counts_caught_right_and_missed(relabel):
    import pandas as pd

    table = pd.DataFrame([
        {"case": "as recorded", "kind": "clean", "caught": False, "right": False, "alternative": False, "others": ""},
        {"case": "as recorded", "kind": "clean", "caught": True, "right": False, "alternative": False, "others": ""},
        {"case": "rate ×2", "kind": "rate", "caught": True, "right": True, "alternative": False, "others": "gaps"},
        {"case": "rate ×2", "kind": "rate", "caught": True, "right": False, "alternative": True, "others": ""},
        {"case": "rate ×2", "kind": "rate", "caught": True, "right": False, "alternative": False, "others": ""},
        {"case": "rate ×2", "kind": "rate", "caught": False, "right": False, "alternative": False, "others": ""},
    ])
    rows = relabel.summarise(table).set_index("case")
    assert rows.loc["as recorded", "false positives"] == 1
    assert rows.loc["rate ×2", "right fix"] == "2 (1 as the alternative)"
    assert (rows.loc["rate ×2", "wrong fix"], rows.loc["rate ×2", "missed"]) == (1, 1)
    assert rows.loc["rate ×2", "other warnings"] == 1


def test_a_case_keeps_what_the_checks_measured_and_why_nothing_else_was_named(relabel, walk):
    pipeline = Pipeline.from_dict(BASE)
    cases = {c["case"]: c for c in relabel.cases("pyshoe", walk)}
    clean = relabel.run_case(pipeline, "walk", cases["as recorded"])
    assert clean["why"] == "the declared rate costs the least"
    assert clean["cadence"] == pytest.approx(120.0, rel=0.02)  # the simulator's 1 s cycle: 120 steps/min
    assert clean["lowest_at"] == pytest.approx(1.0, rel=0.1) and clean["at_real"] == pytest.approx(clean["residual"])
    twice = relabel.run_case(pipeline, "walk", cases["rate ×2, time stamps"])
    assert twice["why"].startswith("named ×2") and twice["cadence"] == pytest.approx(240.0, rel=0.02)
    assert twice["lowest_at"] == pytest.approx(2.0, rel=0.1) and twice["at_real"] < twice["residual"] / 2


def test_the_simulated_recordings_are_each_scenario_at_each_rate(relabel):
    recs = list(relabel.simulated())
    assert len(recs) == len(relabel.SIMULATED) * len(relabel.SIMULATED_RATES)
    for (dataset, rec), (name, rate) in zip(recs, [(n, r) for n in relabel.SIMULATED for r in relabel.SIMULATED_RATES],
                                            strict=True):
        assert dataset == "sim" and rec.name == f"{name} {rate:g} Hz"
        assert rec.rate == pytest.approx(rate, rel=1e-9)
