"""The command line reading data: unit options for a file in g and °/s, a unit the data contradict, a
header it does not recognise (each a data error whose message names the fix).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from footzoo.apps.cli import main
from footzoo.sim import simulate

from ..conftest import HARD_IRON_NOT_FITTED

YUN = "yun2012"


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_acc_and_gyr_unit_options_read_a_canonical_file_in_g_and_deg_s(tmp_path, capsys):
    rec = simulate(n_strides=4, rate=50.0)
    df = rec.to_dataframe()
    df[["acc_x", "acc_y", "acc_z"]] /= 9.81
    df[["gyr_x", "gyr_y", "gyr_z"]] = np.degrees(df[["gyr_x", "gyr_y", "gyr_z"]])
    path = tmp_path / "in_g.csv"
    df.to_csv(path, index=False)
    assert main(["run", YUN, "--data", str(path)]) == 3  # a data error
    assert "acc_unit: g" in capsys.readouterr().err  # the message names the fix ...
    assert main(["run", YUN, "--data", str(path), "--acc-unit", "g", "--gyr-unit", "deg/s"]) == 0  # ... which exists
    assert "strides" in capsys.readouterr().out


def test_a_unit_option_the_data_contradict_is_refused(tmp_path, capsys):
    from footzoo.samples import __file__ as samples

    sample = Path(samples).with_name("xio_short_walk.csv.gz")
    import gzip

    path = tmp_path / "walk.csv"
    path.write_bytes(gzip.decompress(sample.read_bytes()))
    # every reader takes the unit options; the data, in g, refuse m/s²
    assert main(["run", YUN, "--data", str(path), "--acc-unit", "m/s^2"]) == 3  # a data error
    assert "this looks like g, not m/s²" in capsys.readouterr().err


def test_an_unrecognised_header_lists_the_expected_columns(tmp_path, capsys):
    odd = tmp_path / "odd.csv"
    odd.write_text("time,ax,ay,az,gx,gy,gz\n0,0,0,-9.8,0,0,0\n")
    assert main(["run", YUN, "--data", str(odd)]) == 3  # a data error
    err = capsys.readouterr().err
    for expected in ("t, acc_x, acc_y, acc_z, gyr_x, gyr_y, gyr_z", "Gyroscope X (deg/s)", "left_sensor",
                     "scaledAccelX", "--format"):
        assert expected in err


def test_run_help_names_every_built_in_format(capsys):
    from footzoo.io.registry import BUILTIN

    assert main(["run", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    listed = text.split("--format FORMAT", 2)[-1]
    assert all(name in listed for name in BUILTIN), listed[:300]
    assert "xsens" in listed


def test_foot_both_on_a_described_file_names_the_two_description_route(tmp_path, capsys):
    rec = simulate(n_strides=2, rate=50.0)
    path = tmp_path / "walk.csv"
    frame = rec.to_dataframe()[["t", "acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"]]
    frame.set_axis(["time", "ax", "ay", "az", "gx", "gy", "gz"], axis=1).to_csv(path, index=False)
    (tmp_path / "walk.csv.footzoo.yaml").write_text(
        "time: {column: time, unit: s}\nacc: {columns: [ax, ay, az], unit: m/s^2}\n"
        "gyr: {columns: [gx, gy, gz], unit: rad/s}\naxes: [x, y, z]\n")
    assert main(["run", YUN, "--data", str(path), "--foot", "both"]) == 3
    err = capsys.readouterr().err
    assert "one description per foot" in err and "footzoo.Session" in err and "Both feet in one file" in err


def test_a_reader_option_that_cannot_apply_is_an_argument_error(tmp_path, capsys):
    """An unknown option, an axis map that is not one, a foot that is not one: exit code 2 (the arguments), the
    message naming the option and the fix; options without --data are refused, not ignored on the built-in walk."""
    rec = simulate(n_strides=2, rate=50.0)
    path = tmp_path / "walk.csv"
    rec.to_dataframe().to_csv(path, index=False)
    cases = {"foo=1": "unknown option 'foo'", "axes=[x, y, w]": "'w' is not a sensor axis",
             "axes=[x, y, -z]": "is left-handed", "foot=middle": "'middle' is not a foot"}
    for option, says in cases.items():
        assert main(["run", YUN, "--data", str(path), "--option", option]) == 2, option
        assert says in capsys.readouterr().err
    assert main(["run", YUN, "--option", "axes=[x, -y, -z]"]) == 2
    assert "without --data footzoo runs its built-in walk, which takes no reader options" in capsys.readouterr().err
    side = tmp_path / "lab.yaml"
    side.write_text("time: {rate: 50}\n")
    assert main(["run", YUN, "--data", str(path), "--format", "canonical", "--option", f"sidecar={side}"]) == 2
    assert "sidecar= is the generic reader's option" in capsys.readouterr().err
