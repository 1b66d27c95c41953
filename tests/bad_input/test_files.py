"""Bad recording files: cut short, a non-finite value, another delimiter, a damaged MATLAB file.

Each is a clear error naming the file, the problem and the fix (never a raw traceback, never a silently
wrong recording).
"""

from __future__ import annotations

import numpy as np
import pytest

import footzoo
from footzoo.core.errors import FormatError, RecordingError
from footzoo.io.canonical import write
from footzoo.sim import simulate


@pytest.fixture(scope="module")
def walk_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("walk") / "walk.csv"
    write(simulate(n_strides=4, rate=50.0), path)
    return path


def _lines(path):
    return path.read_text().splitlines()


def test_a_file_cut_short_in_its_last_row_is_named_not_read(walk_csv, tmp_path):
    lines = _lines(walk_csv)
    cut = tmp_path / "cut.csv"
    cut.write_text("\n".join(lines[:-1] + [lines[-1][: len(lines[-1]) // 3]]) + "\n")  # cut mid-row
    with pytest.raises(RecordingError, match=r"cut\.csv.*row \d+ \(t = [\d.]+ s\) has values in only its first \d+ "
                                             r"of \d+ columns: the file is cut short"):
        footzoo.load(cut)


def test_a_non_finite_value_names_its_time_in_seconds(walk_csv, tmp_path):
    lines = _lines(walk_csv)
    fields = lines[10].split(",")
    fields[3] = "nan"
    lines[10] = ",".join(fields)
    bad = tmp_path / "nan.csv"
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(RecordingError, match=r"column 'acc_z' has 1 non-finite value\(s\), first at row 9 "
                                             r"\(t = 0\.180000 s\)") as info:
        footzoo.load(bad)
    assert "np.float64" not in str(info.value)


def test_a_semicolon_separated_file_says_so(walk_csv, tmp_path):
    semi = tmp_path / "semi.csv"
    semi.write_text(walk_csv.read_text().replace(",", ";"))
    with pytest.raises(FormatError, match=r"separated by semicolons, not commas"):
        footzoo.load(semi)


def test_a_truncated_matlab_file_is_called_damaged(tmp_path):
    from scipy.io import savemat

    whole = tmp_path / "whole.mat"
    savemat(whole, {"imu": np.random.default_rng(0).normal(size=(2000, 6)), "ts": np.arange(2000) / 200.0})
    cut = tmp_path / "cut.mat"
    cut.write_bytes(whole.read_bytes()[:3000])
    with pytest.raises(FormatError, match=r"cut\.mat.*(damaged or truncated|cannot)"):
        footzoo.load(cut)
    other = tmp_path / "other.mat"
    savemat(other, {"x": np.zeros(3)})
    with pytest.raises(FormatError, match=r"variables \['x'\]; PyShoe's trials have imu and ts"):
        footzoo.load(other)


@pytest.mark.parametrize("suffix, opener", [(".gz", "gzip"), (".bz2", "bz2"), (".xz", "lzma")])
def test_a_compressed_recording_is_recognised_and_read_as_its_text(walk_csv, tmp_path, suffix, opener):
    """Before: 'cannot tell the format' quoting the compressed bytes as a header (pandas reads it with format=)."""
    import importlib

    packed = tmp_path / f"walk.csv{suffix}"
    with importlib.import_module(opener).open(packed, "wb") as fh:
        fh.write(walk_csv.read_bytes())
    assert footzoo.io.detect_format(packed) == "canonical"
    plain = footzoo.load(walk_csv)
    np.testing.assert_array_equal(footzoo.load(packed).acc, plain.acc)


def test_a_header_with_spaces_after_the_commas_is_read_by_its_names(walk_csv, tmp_path):
    """Recognised as canonical (its names stripped) but then read with ' acc_x': 'missing column(s)' before."""
    lines = _lines(walk_csv)
    spaced = tmp_path / "spaced.csv"
    spaced.write_text("\n".join([", ".join(lines[0].split(","))] + lines[1:]) + "\n")
    np.testing.assert_array_equal(footzoo.load(spaced).gyr, footzoo.load(walk_csv).gyr)
