"""Reader and writer frictions (issues 23-25): blank first lines, cut last rows, missing gaitmap rows, closed loops,
stale sidecars, text metadata, extensions, and writers that never replace their inputs."""

from __future__ import annotations

import shutil
import warnings

import numpy as np
import pytest

from footzoo import FormatError
from footzoo.core.atomic import TMP_INFIX
from footzoo.core.conventions import GRAVITY
from footzoo.core.errors import FootzooWarning, OutputError
from footzoo.io import builtin_sample, load
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate

from ..conftest import data_file


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=3, rate=204.8, noise=NoiseModel(seed=11))


def xio_text(rec) -> str:
    head = "Time (s),Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),Accelerometer X (g)," \
           "Accelerometer Y (g),Accelerometer Z (g)"
    flip = np.array([1.0, -1.0, -1.0])
    rows = np.column_stack([rec.t, np.degrees(rec.gyr * flip), rec.acc * flip / GRAVITY])
    return head + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n"


def sensorconnect_text(rec) -> str:
    dev = "inertial-6253.76535"
    head = ",".join(["Time", *[f"{dev}:scaled{s}{a}" for s in ("Accel", "Gyro") for a in "XYZ"]])
    rows = np.column_stack([rec.t, rec.acc / GRAVITY, rec.gyr])
    return head + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n"


def gaitmap_text(rec, index=None) -> str:
    flip = np.array([1.0, -1.0, -1.0])  # FRD -> gaitmap's foot frame (x toe, y left, z up)
    acc, gyr = rec.acc * flip, np.degrees(rec.gyr * flip)
    cols = [(f"{foot}_sensor", f"{s}_{a}") for s in ("acc", "gyr") for a in "xyz" for foot in ("left",)]
    head = "sensor," + ",".join(c[0] for c in cols) + "\naxis," + ",".join(c[1] for c in cols)
    index = np.arange(rec.n) if index is None else index
    rows = [f"{i}," + ",".join(repr(float(v)) for v in (*acc[k], *gyr[k])) for k, i in enumerate(index)]
    return head + "\n" + "\n".join(rows) + "\n"


def canonical_text(rec) -> str:
    return rec.to_dataframe().to_csv(index=False, float_format="%.17g")


WRITERS = {"canonical": canonical_text, "xio": xio_text, "sensorconnect": sensorconnect_text,
           "gaitmap": gaitmap_text}


def quiet_load(path, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return load(path, **options)


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


def test_only_the_known_xio_walk_is_a_closed_loop(walk, tmp_path):
    other = tmp_path / "my_walk.csv"
    other.write_text(xio_text(walk))
    assert not quiet_load(other).truth.closed_loop  # an unknown x-io file: no loop closure assumed
    assert quiet_load(other, closed_loop=True).truth.closed_loop
    other.with_name("my_walk.csv.meta.yaml").write_text("closed_loop: true\nmeta: {subject: '1e3'}\n")
    rec = quiet_load(other)
    assert rec.truth.closed_loop and rec.meta["subject"] == "1e3"
    assert builtin_sample().truth.closed_loop
    known = quiet_load(data_file("xio_gait_tracking", "short_walk.csv"))
    assert known.truth.closed_loop and "short_walk.csv" in known.truth.source
    copy = tmp_path / "renamed.csv"
    shutil.copy(data_file("xio_gait_tracking", "short_walk.csv"), copy)
    assert quiet_load(copy).truth.closed_loop  # recognised by its content, not its name


def test_metadata_text_stays_text_through_write_and_load(walk, tmp_path):
    rec = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))
    rec.meta.update(code="1e3", subject="007", flag="true", hexa="0x1F", empty="", number=1e3)
    back = load(write(rec, tmp_path / "w.csv"))
    assert (back.meta["code"], back.meta["subject"], back.meta["flag"], back.meta["hexa"], back.meta["empty"]) == \
        ("1e3", "007", "true", "0x1F", "")
    assert back.meta["number"] == 1e3 and isinstance(back.meta["number"], float)


def test_stale_sidecars_of_an_earlier_file_are_never_the_reference(tmp_path):
    first = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))
    second = simulate(n_strides=5, rate=100.0, noise=NoiseModel(seed=2))
    p = write(first, tmp_path / "walk.csv")
    assert load(p).truth.stride_count == len(first.truth.steps)
    # the data file is replaced by hand (a copy from elsewhere); its old sidecars stay behind
    other = write(second, tmp_path / "other.csv")
    shutil.copy(other, p)
    with pytest.warns(FootzooWarning, match=r"walk.csv.meta.yaml describes an earlier walk.csv.*stale, ignored "
                                            r"together with walk.csv.steps.csv"):
        rec = load(p)
    assert rec.truth.steps is None and rec.truth.stride_count is None and rec.meta["name"] == "walk"
    # footzoo's writer replaces the data and its sidecars together, and removes a steps file the new one lacks
    no_steps = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=3))
    no_steps.truth.steps = None
    write(no_steps, p)
    assert not p.with_name("walk.csv.steps.csv").exists()
    # a steps file put next to a hashed sidecar later is not vouched for
    p.with_name("walk.csv.steps.csv").write_text(first.truth.steps.to_csv(index=False))
    with pytest.warns(FootzooWarning, match="walk.csv.steps.csv is not listed in the metadata sidecar"):
        assert load(p).truth.steps is None


def test_the_writer_refuses_an_unknown_extension_and_its_own_input(tmp_path):
    rec = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))
    with pytest.raises(OutputError, match=r"footzoo writes recordings as .csv or .parquet, not '.xlsx'"):
        write(rec, tmp_path / "walk.xlsx")
    with pytest.raises(OutputError, match="not 'a file without extension'"):
        write(rec, tmp_path / "walk")
    assert list(tmp_path.iterdir()) == []
    p = write(rec, tmp_path / "walk.csv")
    loaded = load(p)
    before = {f.name: f.read_bytes() for f in tmp_path.iterdir()}
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.csv").symlink_to(p)
    for target in (p, tmp_path / "sub" / ".." / "walk.csv", tmp_path / "link.csv"):
        with pytest.raises(OutputError, match="would overwrite the input"):
            write(loaded, target)
    assert {f.name: f.read_bytes() for f in tmp_path.iterdir() if f.is_file() and not f.is_symlink()} == before
    assert not [f for f in tmp_path.rglob("*") if TMP_INFIX in f.name]


def test_a_gap_bridged_in_a_canonical_file_is_reported_not_refused(tmp_path):
    rec = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))
    df = rec.to_dataframe().drop(index=range(300, 312))  # 130 ms
    df.to_csv(tmp_path / "g.csv", index=False)
    with pytest.warns(FootzooWarning, match="bridged 1 gap"):
        got = load(tmp_path / "g.csv")
    assert got.meta["diagnostics"]["gaps"]["longest_s"] == pytest.approx(0.13)


def test_a_sidecar_that_cannot_be_written_leaves_no_data_file_without_it(tmp_path, monkeypatch):
    from footzoo.io import canonical

    old = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))
    p = write(old, tmp_path / "walk.csv")
    before = {f.name: f.read_bytes() for f in tmp_path.iterdir()}

    def full_disk(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(canonical, "facts_text", full_disk)
    with pytest.raises(OSError, match="No space left"):
        write(simulate(n_strides=5, rate=100.0, noise=NoiseModel(seed=2)), p)
    assert {f.name: f.read_bytes() for f in tmp_path.iterdir()} == before  # the old three files, complete
    with pytest.raises(OSError):
        write(old, tmp_path / "new.csv")
    assert sorted(f.name for f in tmp_path.iterdir()) == sorted(before)  # no data file without its sidecar
