"""Every bad-input case gets an error that names the problem and the fix."""

import re

import numpy as np
import pandas as pd
import pytest

from footzoo import ConfigError, Recording, RecordingError
from footzoo.core.data import ACC_COLS, GYR_COLS, Truth
from footzoo.core.errors import FootzooWarning
from footzoo.sim import simulate


def frame(n=400, rate=100.0, acc_scale=1.0, gyr_scale=1.0):
    rng = np.random.default_rng(0)
    t = np.arange(n) / rate
    acc = np.tile([0.0, 0.0, -9.81], (n, 1)) + rng.normal(scale=0.02, size=(n, 3))
    gyr = rng.normal(scale=0.01, size=(n, 3))
    gyr[200:260, 1] += 5.0  # a swing (noisy: a constant 5.0 would read as a clipped gyro)
    df = pd.DataFrame({"t": t})
    for i, a in enumerate("xyz"):
        df[f"acc_{a}"] = acc[:, i] * acc_scale
        df[f"gyr_{a}"] = gyr[:, i] * gyr_scale
    return df


def test_a_good_frame_builds_a_recording():
    rec = Recording.from_dataframe(frame())
    assert rec.n == 400 and rec.rate == pytest.approx(100.0)
    assert rec.mag is None and rec.truth is None


def test_missing_columns_are_named():
    with pytest.raises(RecordingError, match=r"missing column\(s\) \['gyr_z'\]"):
        Recording.from_dataframe(frame().drop(columns="gyr_z"))


def test_two_levels_of_column_names_are_named_with_the_way_to_flatten_them_and_number_names_are_missing_columns():
    df = frame()
    two = df.set_axis(pd.MultiIndex.from_tuples([(c, "") for c in df.columns]), axis=1)
    with pytest.raises(RecordingError, match=r"2 levels of column names \(e.g. \('t', ''\)\).*df.columns = "):
        Recording.from_dataframe(two)
    flat = two.set_axis(["_".join(map(str, c)).strip("_") for c in two.columns], axis=1)  # the fix the error gives
    assert Recording.from_dataframe(flat).n == len(df)
    with pytest.raises(RecordingError, match=r"missing column\(s\) \['t', 'acc_x'"):  # a header=None table
        Recording.from_dataframe(df.set_axis(range(7), axis=1))


def test_empty_frame():
    with pytest.raises(RecordingError, match="empty"):
        Recording.from_dataframe(frame().iloc[:0])


def test_non_finite_values_name_the_column_and_row():
    df = frame()
    df.loc[17, "acc_y"] = np.nan
    with pytest.raises(RecordingError, match=r"'acc_y' has 1 non-finite value\(s\), first at row 17.*nan_policy"):
        Recording.from_dataframe(df)
    rec = Recording.from_dataframe(df, nan_policy="interpolate")
    assert np.isfinite(rec.acc).all()


def test_time_going_backwards():
    df = frame()
    df.loc[50, "t"] = df.loc[48, "t"]
    with pytest.raises(RecordingError, match=r"time stamps go backwards at sample 50 \(t = 0.490000 s -> 0.480000 s\)"):
        Recording.from_dataframe(df)


def test_duplicate_time_stamps_are_an_error_unless_dropped_with_a_count():
    df = frame()
    df = pd.concat([df.iloc[:30], df.iloc[[29, 29]], df.iloc[30:]]).reset_index(drop=True)
    with pytest.raises(RecordingError, match=r"2 duplicate time stamp\(s\).*duplicates='drop'\), "
                                             "on the command line --option duplicates=drop"):
        Recording.from_dataframe(df)
    with pytest.warns(UserWarning, match=r"dropped 2 row\(s\)"):
        rec = Recording.from_dataframe(df, duplicates="drop")
    assert rec.n == 400


def test_gaps_are_reported_with_their_length_and_place():
    df = frame().drop(index=range(100, 130)).reset_index(drop=True)
    with pytest.raises(RecordingError, match=r"gap\(s\) longer than 250.0 ms, the first 310.0 ms at t = 0.990 s"):
        Recording.from_dataframe(df)
    with pytest.warns(FootzooWarning, match="bridged 1 gap"):
        assert Recording.from_dataframe(df, max_gap=0.4).n == 370


def test_too_short_to_align():
    with pytest.raises(RecordingError, match="too short to align") as err:
        Recording.from_dataframe(frame().iloc[:50])
    assert "min" not in str(err.value)  # 0.49 s at 100 Hz: no other unit makes it a plausible recording


@pytest.mark.parametrize("unit, seconds, fix", [
    ("min", 60.0, "multiply t by 60"),  # 100 Hz read as 6000 Hz over 0.067 s: too short, not too fast
    ("h", 3600.0, "multiply t by 3600"),
    ("ms", 1e-3, "divide t by 1000"),
    ("us", 1e-6, "divide t by 1e+06"),
])
def test_a_time_column_in_another_unit_is_named_with_the_unit_that_makes_it_plausible(unit, seconds, fix):
    df = frame()
    df["t"] = df["t"] / seconds
    with pytest.raises(RecordingError) as err:
        Recording.from_dataframe(df)
    text = str(err.value)
    assert (f"are the time stamps in {unit}?" in text and "it is 100 Hz over 3.99 s" in text and fix in text
            and f"unit: {unit}}}" in text)


def test_a_sample_counter_as_time_is_told_to_declare_the_rate():
    df = frame()
    df["t"] = np.arange(len(df), dtype=float)
    with pytest.raises(RecordingError, match=r"the median sampling rate is 1 Hz.*if t counts samples, declare the "
                                             r"rate instead"):
        Recording.from_dataframe(df)


def test_acc_in_g_is_recognised():
    with pytest.raises(RecordingError, match="looks like g.*acc_unit: g"):
        Recording.from_dataframe(frame(acc_scale=1 / 9.81))
    rec = Recording.from_dataframe(frame(acc_scale=1 / 9.81), acc_unit="g")
    assert np.linalg.norm(rec.acc[0]) == pytest.approx(9.81, rel=0.01)


@pytest.mark.parametrize("values, declared, real", [
    (1.0, "g", "m/s^2"),  # m/s² declared as g: g reads 9.81 g = 96 m/s²
    (1.0, "mg", "m/s^2"),  # ... as mg: 0.0098 g
    (1 / 9.80665, "mg", "g"),  # g declared as mg: 0.001 g
    (1000 / 9.80665, "g", "mg"),  # mg declared as g: 1000 g
])
def test_an_accelerometer_declared_in_another_unit_is_named_with_the_unit_that_reads_g(values, declared, real):
    with pytest.raises(RecordingError, match=re.escape(f"this is what g reads in {real} declared as {declared}; "
                                                       f"declare acc_unit: {real}")):
        Recording.from_dataframe(frame(acc_scale=values), acc_unit=declared)
    rec = Recording.from_dataframe(frame(acc_scale=values), acc_unit=real)  # the unit it names reads g
    assert np.linalg.norm(rec.acc[0]) == pytest.approx(9.81, rel=0.01)


def test_gyro_in_deg_per_s_is_recognised():
    with pytest.raises(RecordingError, match="looks like deg/s; declare gyr_unit: deg/s"):
        Recording.from_dataframe(frame(gyr_scale=180 / np.pi))
    rec = Recording.from_dataframe(frame(gyr_scale=180 / np.pi), gyr_unit="deg/s")
    assert rec.gyr.max() == pytest.approx(5.0, rel=0.01)


def test_unknown_unit_is_rejected_with_the_choices():
    with pytest.raises(RecordingError, match=r"acc_unit='ft/s\^2' is not supported; use one of"):
        Recording.from_dataframe(frame(), acc_unit="ft/s^2")


def test_shape_mismatch_in_direct_construction():
    with pytest.raises(RecordingError, match=r"gyr must have shape \(400, 3\)"):
        Recording(t=np.arange(400) / 100.0, acc=np.zeros((400, 3)), gyr=np.zeros((399, 3)))


def test_round_trip_through_a_dataframe_keeps_truth():
    rec = Recording.from_dataframe(frame())
    rec.truth = Truth(pos=np.zeros((400, 3)), stance=np.ones(400, bool))
    back = Recording.from_dataframe(rec.to_dataframe())
    np.testing.assert_allclose(back.acc, rec.acc)
    assert back.truth is not None and back.truth.stance.all()


def test_read_only_inputs_become_writable_copies_and_the_caller_keeps_theirs():
    """pandas' copy-on-write columns are read-only: the recording owns writable copies (one type for the kernels)."""
    import numpy as np

    from footzoo.core.data import Recording

    n = 200
    t = np.arange(n) / 100.0
    acc = np.tile([0.0, 0.0, -9.81], (n, 1))
    gyr = np.zeros((n, 3))
    for a in (t, acc, gyr):
        a.flags.writeable = False
    rec = Recording(t=t, acc=acc, gyr=gyr)
    assert all(a.flags.writeable and a.flags.c_contiguous for a in (rec.t, rec.acc, rec.gyr))
    assert not np.shares_memory(rec.acc, acc)
    np.testing.assert_array_equal(rec.acc, acc)
    writable = np.zeros((n, 3))
    assert Recording(t=np.arange(n) / 100.0, acc=acc, gyr=writable).gyr is writable  # no copy when not needed


def test_time_stamps_rounded_by_a_float32_clock_are_refused_with_the_fix():
    """float32 at 10⁵ s resolves 7.8 ms: a 100 Hz recording's stamps rounded to steps of 0 and 7.8 ms were read as
    hundreds of bridged gaps, with no word of the cause."""
    df = frame()
    t = df["t"].to_numpy()
    acc, gyr = df[["acc_x", "acc_y", "acc_z"]].to_numpy(), df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy()
    with pytest.raises(RecordingError, match=r"t is float32 \(a 32-bit float\): at t = 100004 s it resolves only "
                                             r"7.81 ms, .* the sampling period .*Keep them as float64"):
        Recording(t=(t + 1e5).astype(np.float32), acc=acc, gyr=gyr)
    rec = Recording(t=t.astype(np.float32), acc=acc, gyr=gyr)  # near 0, float32 resolves a microsecond: fine
    assert rec.rate == pytest.approx(100.0, rel=1e-4)


def test_a_transposed_array_is_named_with_its_fix():
    df = frame()
    t, acc = df["t"].to_numpy(), df[["acc_x", "acc_y", "acc_z"]].to_numpy()
    gyr = df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy()
    fix = "gyr must have shape (400, 3) to match t, got (3, 400); it looks transposed: pass gyr.T"
    with pytest.raises(RecordingError, match=re.escape(fix)):
        Recording(t=t, acc=acc, gyr=gyr.T)
    with pytest.raises(RecordingError, match=r"got \(400, 4\)$"):  # not transposed: no such hint
        Recording(t=t, acc=np.c_[acc, acc[:, :1]], gyr=gyr)


def test_in_a_study_the_data_checks_name_the_recording_entrys_key():
    """A study reads its recordings with the options of their entries: that is the fix a message names there."""
    from footzoo.core.usage import used_from

    with used_from("study"), pytest.raises(RecordingError) as err:
        Recording.from_dataframe(frame(gyr_scale=180 / np.pi))
    assert "the recording entry's gyr_unit: deg/s key in the study" in str(err.value)
    assert "footzoo.load" not in str(err.value) and "--option" not in str(err.value)
    df = frame()
    df = pd.concat([df.iloc[:30], df.iloc[[29]], df.iloc[30:]]).reset_index(drop=True)
    with used_from("study"), pytest.raises(RecordingError, match=r"the recording entry's duplicates: drop key"):
        Recording.from_dataframe(df)
    with pytest.raises(RecordingError, match=r"footzoo\.load\(path, duplicates='drop'\)"):  # in Python, as before
        Recording.from_dataframe(df)
    with pytest.raises(ValueError, match="place must be one of"):
        with used_from("notebook"):
            pass


def test_a_table_with_no_time_column_takes_its_rate():
    walk = simulate(n_strides=2, rate=50.0)
    df = pd.DataFrame(np.column_stack([walk.acc, walk.gyr]), columns=[*ACC_COLS, *GYR_COLS])
    rec = Recording.from_dataframe(df, rate=50.0)
    np.testing.assert_allclose(rec.t, walk.t - walk.t[0], rtol=0, atol=1e-12)  # the simulator's clock, from 0
    assert rec.rate == pytest.approx(50.0)
    with pytest.raises(RecordingError, match=r"no time column: Recording.from_dataframe\(\.\.\., rate=HZ\)"):
        Recording.from_dataframe(df)
    with pytest.raises(RecordingError, match=r"has a time column 't' and rate=50 Hz is given too"):
        Recording.from_dataframe(df.assign(t=walk.t), rate=50.0)
    with pytest.raises(ConfigError, match="rate"):
        Recording.from_dataframe(df, rate=-5)


def test_a_dead_accelerometer_axis_is_not_named_a_unit_whose_fix_changes_nothing():
    """acc_z reads nothing (the gravity axis): at rest ‖f‖ is near 0, as g in m/s² declared as mg would read, but the
    motion reads m/s²: no unit scales one and not the other. The error names the ranges instead of a unit."""
    from footzoo.sim import NoiseModel, simulate

    walk = simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=0))
    acc = walk.acc.copy()
    acc[:, 2] = np.random.default_rng(0).normal(0.0, 1e-4, len(acc))
    with pytest.raises(RecordingError, match=r"a unit error scales both alike, so no unit explains it.*acc_z "
                                             r"0.000\d+\)") as info:
        Recording(t=walk.t, acc=acc, gyr=walk.gyr)
    assert "declare acc_unit" not in str(info.value)
