"""Readers and the layout of a text file: blank first lines, a last row cut in its last number, rows missing from
gaitmap's sample index, a gap in a canonical file.
"""

from __future__ import annotations

import numpy as np
import pytest

from footzoo import FormatError
from footzoo.core.errors import FootzooWarning
from footzoo.io import load
from footzoo.sim import NoiseModel, simulate

from .texts import WRITERS, gaitmap_text, quiet_load


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=3, rate=204.8, noise=NoiseModel(seed=11))


@pytest.mark.parametrize("fmt", list(WRITERS))
def test_a_file_that_starts_with_blank_lines_is_read(fmt, walk, tmp_path):
    plain, blank = tmp_path / "plain.csv", tmp_path / "blank.csv"
    plain.write_text(WRITERS[fmt](walk))
    blank.write_text("\n\r\n  \n" + WRITERS[fmt](walk))
    options = {"foot": "left"} if fmt == "gaitmap" else {}
    a, b = quiet_load(plain, **options), quiet_load(blank, **options)
    assert b.meta["format"] == fmt or fmt == "canonical"
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.acc, b.acc)
    np.testing.assert_allclose(b.acc, walk.acc, rtol=0, atol=1e-12)


@pytest.mark.parametrize("fmt", list(WRITERS))
def test_a_file_cut_in_its_last_number_loses_that_row_with_a_warning(fmt, walk, tmp_path):
    text = WRITERS[fmt](walk).rstrip("\n")
    cut = tmp_path / "cut.csv"
    cut.write_text(text[:-5])  # in the middle of the last row's last number
    options = {"foot": "left"} if fmt == "gaitmap" else {}
    with pytest.warns(FootzooWarning, match="does not end with a line break.*dropped that row"):
        rec = load(cut, **options)
    assert rec.n == walk.n - 1
    np.testing.assert_allclose(rec.acc, walk.acc[:-1], rtol=0, atol=1e-12)  # the whole rest is there, exact


def test_gaitmap_rows_missing_from_the_sample_index_are_a_gap_not_lost_time(walk, tmp_path):
    long_walk = simulate(n_strides=20, rate=204.8, noise=NoiseModel(seed=12))
    keep = np.r_[0:1500, 2500:long_walk.n]  # 1000 rows missing: 4.88 s at 204.8 Hz
    holed = tmp_path / "imu_sample.csv"
    rec = long_walk

    class Sub:
        acc, gyr, n = rec.acc[keep], rec.gyr[keep], keep.size

    holed.write_text(gaitmap_text(Sub, index=keep))
    with pytest.raises(FormatError, match=r"1000 rows are missing from the sample index \(it jumps from 1499 to 2500: "
                                          r"4.88 s at 204.8 Hz\).*Restore the rows, split the file"):
        load(holed, foot="left")
    short = np.r_[0:1500, 1520:rec.n]  # 20 rows: 98 ms, bridged as a gap
    Sub.acc, Sub.gyr, Sub.n = rec.acc[short], rec.gyr[short], short.size
    holed.write_text(gaitmap_text(Sub, index=short))
    with pytest.warns(FootzooWarning, match=r"bridged 1 gap\(s\).*the longest 102.5 ms"):
        got = load(holed, foot="left")
    np.testing.assert_allclose(got.t, short / 204.8)
    with pytest.raises(FormatError, match="must count up"):
        holed.write_text(gaitmap_text(Sub, index=short[::-1]))
        load(holed, foot="left")


def test_a_gap_bridged_in_a_canonical_file_is_reported_not_refused(tmp_path):
    rec = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))
    df = rec.to_dataframe().drop(index=range(300, 312))  # 130 ms
    df.to_csv(tmp_path / "g.csv", index=False)
    with pytest.warns(FootzooWarning, match="bridged 1 gap"):
        got = load(tmp_path / "g.csv")
    assert got.meta["diagnostics"]["gaps"]["longest_s"] == pytest.approx(0.13)
