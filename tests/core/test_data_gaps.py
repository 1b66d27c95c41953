"""Short logger gaps are bridged with a warning and a diagnostics entry; long ones are refused."""

import re

import numpy as np
import pandas as pd
import pytest

import footzoo
from footzoo import Recording, RecordingError
from footzoo.core.checks import DEFAULT_MAX_GAP
from footzoo.core.errors import FootzooWarning
from footzoo.evaluation.metrics import loop_closure
from footzoo.sim import simulate

from ..conftest import data_file


def still_frame(n=400, rate=100.0):
    t = np.arange(n) / rate
    df = pd.DataFrame({"t": t})
    for i, a in enumerate("xyz"):
        df[f"acc_{a}"] = [0.0, 0.0, -9.81][i]
        df[f"gyr_{a}"] = 0.0
    return df


def test_a_short_gap_is_bridged_with_a_warning_and_listed_in_the_diagnostics():
    df = still_frame().drop(index=range(200, 205)).reset_index(drop=True)  # 60 ms interval at 100 Hz
    with pytest.warns(FootzooWarning, match=r"bridged 1 gap\(s\).*the longest 60.0 ms at t = 1.990 s"):
        rec = Recording.from_dataframe(df)
    gaps = rec.meta["diagnostics"]["gaps"]
    assert gaps["count"] == 1
    assert gaps["start_s"] == pytest.approx([1.99])
    assert gaps["duration_s"] == pytest.approx([0.06])
    assert gaps["max_gap_s"] == DEFAULT_MAX_GAP
    assert rec.n == 395  # no samples invented


def test_a_gap_longer_than_the_limit_is_refused_with_the_fix():
    df = still_frame().drop(index=range(200, 226)).reset_index(drop=True)  # 270 ms
    with pytest.raises(RecordingError, match=r"longer than 250.0 ms, the first 270.0 ms at t = 1.990 s.*max_gap"):
        Recording.from_dataframe(df)
    with pytest.raises(RecordingError, match=r"longer than 40.0 ms"):
        Recording.from_dataframe(still_frame().drop(index=range(200, 205)), max_gap=0.04)


@pytest.mark.parametrize("missing", [10, 11, 23])  # 110 ms, 120 ms and 240 ms intervals at 100 Hz
def test_a_logger_dropout_of_a_tenth_of_a_second_is_bridged_with_a_warning_naming_it(missing):
    """Issue 23: 3 of 56 annotated 100 Hz gait files were refused for one 110-120 ms gap."""
    df = still_frame().drop(index=range(200, 200 + missing)).reset_index(drop=True)
    with pytest.warns(FootzooWarning, match=r"bridged 1 gap.*1 of them longer than 0.1 s: one in a swing loses"):
        rec = Recording.from_dataframe(df)
    assert rec.meta["diagnostics"]["gaps"]["duration_s"] == pytest.approx([(missing + 1) / 100])
    assert rec.meta["diagnostics"]["gaps"]["max_gap_s"] == DEFAULT_MAX_GAP == 0.25


def test_a_regular_recording_has_no_gap_entry(recwarn):
    rec = Recording.from_dataframe(still_frame())
    assert "gaps" not in rec.meta.get("diagnostics", {})
    assert not [w for w in recwarn if issubclass(w.category, FootzooWarning)]


@pytest.fixture(scope="module")
def loop_walk():
    rec = simulate(path="rectangle", length=10.0, width=5.0, rate=100.0, profile="physical", magnetometer=False)
    pipe = footzoo.Pipeline.from_yaml("duong2015_zupt")
    return rec, pipe, loop_closure(pipe.run(rec).pos)


def _holed(rec, k, n):
    df = rec.to_dataframe()
    with pytest.warns(FootzooWarning, match="bridged 1 gap"):
        holed = Recording.from_dataframe(df.drop(index=range(k, k + n)).reset_index(drop=True), meta={"name": "h"})
    return holed


def _gap_at(rec, stance: bool, fraction: float = 0.5) -> int:
    mask = rec.truth.stance if stance else ~rec.truth.stance
    idx = np.flatnonzero(mask[1:] & mask[:-1] & (rec.t[1:] > 3.0))
    return int(idx[int(len(idx) * fraction)])


def test_a_bridged_gap_in_stance_costs_nothing(loop_walk):
    rec, pipe, full = loop_walk
    gap = loop_closure(pipe.run(_holed(rec, _gap_at(rec, True), 8)).pos)  # 90 ms interval
    assert gap["path_length_m"] == pytest.approx(full["path_length_m"], abs=0.01)
    assert gap["loop_closure_xy_m"] < full["loop_closure_xy_m"] + 0.002


def test_xio_short_walk_loads_with_its_gaps_bridged():
    with pytest.warns(FootzooWarning) as caught:
        rec = footzoo.load(data_file("xio_gait_tracking", "short_walk.csv"))
    messages = [str(w.message) for w in caught]
    assert any("bridged" in m for m in messages)
    assert any(re.match(r"dropped \d+ row\(s\) whose time stamp repeats the previous one", m) for m in messages)
    gaps = rec.meta["diagnostics"]["gaps"]
    assert gaps["count"] > 0 and gaps["longest_s"] < DEFAULT_MAX_GAP
