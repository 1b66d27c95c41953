"""References without per-sample columns (a stride table, a closed loop, a hand count, the true ranges) written
with a recording and read back; what the canonical files cannot hold is named.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

import footzoo
from footzoo.core.data import Recording, Truth
from footzoo.core.errors import FootzooWarning, FormatError
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate

from ..conftest import data_file


@pytest.fixture(scope="module")
def walk() -> Recording:
    return simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=1))


def _bare(walk: Recording, truth: Truth | None) -> Recording:
    """The walk's signals with ``truth`` as its only reference."""
    return Recording(t=walk.t, acc=walk.acc, gyr=walk.gyr, meta={"name": "bare"}, truth=truth)


def test_a_reference_that_is_only_a_stride_table_round_trips(walk, tmp_path):
    steps = walk.truth.steps.copy()  # the simulator's strides, not something the writer made
    rec = _bare(walk, Truth(steps=steps, source="hand-labelled strides"))
    back = footzoo.load(write(rec, tmp_path / "strides.csv"))
    assert back.truth is not None and back.truth.pos is None
    pd.testing.assert_frame_equal(back.truth.steps, steps)  # dtypes too
    assert back.truth.source == "hand-labelled strides"
    assert back.truth.stride_count is None  # none was given: the table's rows are not taken for a hand count


def test_whole_number_floats_of_a_stride_table_reload_as_floats(walk, tmp_path):
    steps = pd.DataFrame({"start_s": [1.0, 2.0, 3.0], "stride_length_m": [1.0, 1.0, np.nan], "n": [1, 2, 3],
                          "tiny": [5e-324, 0.1, 1e22]})
    back = footzoo.load(write(_bare(walk, Truth(steps=steps)), tmp_path / "whole.csv"))
    pd.testing.assert_frame_equal(back.truth.steps, steps)  # float64 stays float64, int64 stays int64, bit for bit


@pytest.mark.parametrize("truth, check", [
    (Truth(closed_loop=True), lambda t: t.closed_loop and t.steps is None),
    (Truth(stride_count=17, source="by hand"), lambda t: t.stride_count == 17 and t.source == "by hand"),
    (Truth(steps=pd.DataFrame({"start_s": [1.0, 2.0], "end_s": [2.0, 3.0]}), stride_count=3),
     lambda t: t.stride_count == 3 and len(t.steps) == 2),  # a hand count that differs from the table
])
def test_references_without_per_sample_columns_round_trip(walk, tmp_path, truth, check):
    back = footzoo.load(write(_bare(walk, truth), tmp_path / "r.csv"))
    assert back.truth is not None and check(back.truth), back.truth


def test_a_written_recording_without_a_reference_reads_back_without_one(walk, tmp_path):
    assert footzoo.load(write(_bare(walk, None), tmp_path / "none.csv")).truth is None


def test_reference_parts_the_canonical_files_cannot_hold_are_named_when_written(walk, tmp_path):
    rec = _bare(walk, Truth(footprints=np.zeros((3, 2)), stride_count=2))
    with pytest.warns(FootzooWarning, match=r"footprints \(truth.footprints\) are not written.*original recording"):
        back = footzoo.load(write(rec, tmp_path / "f.csv"))
    assert back.truth.stride_count == 2


def test_a_bad_truth_entry_in_a_sidecar_is_named(walk, tmp_path):
    path = write(_bare(walk, Truth(closed_loop=True)), tmp_path / "s.csv")
    side = path.with_name(path.name + ".meta.yaml")
    side.write_text(side.read_text(encoding="utf-8") + "truth: {stride_count: -2}\n", encoding="utf-8")
    with pytest.raises(FormatError, match=r"truth.stride_count must be a whole number of strides.*got -2"):
        footzoo.load(path)


def test_the_real_gaitmap_stride_table_survives_a_round_trip(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FootzooWarning)  # the reader's gap report; stride_positions are not written
        rec = footzoo.load(data_file("gaitmap_example", "imu_sample.csv"), foot="left")
        back = footzoo.load(write(rec, tmp_path / "left.csv"))
    assert rec.truth.steps is not None and rec.truth.pos is None
    pd.testing.assert_frame_equal(back.truth.steps, rec.truth.steps)  # dtypes too
    assert (back.truth.source, back.truth.stride_count) == (rec.truth.source, rec.truth.stride_count)


def test_a_reference_that_is_only_the_true_ranges_round_trips(tmp_path):
    rec = simulate(n_strides=3, rate=50.0, distance_sensors=True)
    bare = Recording(t=rec.t, acc=rec.acc, gyr=rec.gyr, dist=rec.dist, meta={"name": "ranges"},
                     truth=Truth(dist=rec.truth.dist))
    back = footzoo.load(write(bare, tmp_path / "ranges.csv"))
    np.testing.assert_array_equal(back.truth.dist, rec.truth.dist)
