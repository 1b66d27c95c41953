"""Command-line and output frictions: each one that a new user hit, with the fix."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from footzoo.apps.cli import build_parser, main
from footzoo.apps.compat import check
from footzoo.config import library
from footzoo.io.canonical import write
from footzoo.sim import simulate

YUN = "yun2012"


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


def test_validate_reports_every_problem_at_once(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("gravty: 9.8\norientation: {type: fqa_complementary, static_gane: 1.0}\n"
                   "detector: {type: angular_rate_fsm, threshold: -1}\ncorrections:\n  - {type: zvu_dedrif}\n")
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "4 problem(s)" in err
    for what in ("'gravty'", "'static_gane'", "threshold = -1 rad/s is out of range", "'zvu_dedrif'"):
        assert what in err
    assert main(["validate", YUN]) == 0


def test_compatibility_list_keeps_whole_reasons(capsys):
    assert main(["list", "--compatibility"]) == 0
    out = capsys.readouterr().out
    reason = check({"orientation": {"type": "madgwick"}, "detector": {"type": "angular_rate_fsm"},
                    "corrections": [{"type": "ekf_zupt"}, {"type": "zvu_dedrift"}]})
    assert reason is not None
    assert reason.split(":", 1)[-1].strip() in out
    longest = max((len(line) for line in out.splitlines() if line.startswith("- ")), default=0)
    assert longest > 162  # reasons used to be cut at 160 characters


def test_missing_pyarrow_warns_instead_of_silently_skipping_parquet(tmp_path, monkeypatch):
    from footzoo.studies.report import write_outputs

    def no_pyarrow(*args, **kwargs):
        raise ImportError("Unable to find a usable engine; tried using: 'pyarrow'")

    monkeypatch.setattr(pd.DataFrame, "to_parquet", no_pyarrow)
    table = pd.DataFrame({"run": ["a"], "base": ["yun2012"], "recording": ["r"], "metric": ["m"], "value": [1.0],
                          "error": [None]})
    with pytest.warns(UserWarning, match="results.parquet was not written"):
        write_outputs(table, [], [], tmp_path)
    assert (tmp_path / "results.csv").exists() and not (tmp_path / "results.parquet").exists()


def test_config_comments_show_commands_that_parse():
    """Every `footzoo ...` command quoted in a config comment is accepted by the parser."""
    parser = build_parser()
    found = 0
    for cfg in library.BUILTIN.glob("*.yaml"):
        for line in cfg.read_text().splitlines():
            m = re.search(r"#.*?footzoo ((?:run|calibrate|simulate|validate|list|ablate)\b[^,;]*)", line)
            if m:
                args = ["x.csv" if a.isupper() else a for a in m.group(1).split()]
                parser.parse_args(args)
                found += 1
    assert found >= 1


def test_steps_csv_columns_carry_units(tmp_path):
    rec = simulate(n_strides=4, rate=50.0)
    path = write(rec, tmp_path / "walk.csv")
    assert main(["run", "huang2016", "--data", str(path), "--out", str(tmp_path / "out")]) == 0
    cols = pd.read_csv(tmp_path / "out" / "steps.csv").columns
    unit = re.compile(r"_(s|m|m_s|rad|steps_min)$")
    assert all(unit.search(c) for c in cols if c != "events_from_rate"), list(cols)
    assert "fpa_rad" in cols and "heading_rad" in cols


@pytest.mark.parametrize("page, at_least", [("README.md", 5), ("docs/command-line.md", 15)])
def test_every_command_in_the_readme_parses(page, at_least):
    """The `footzoo ...` lines of the README and of the command-line page (continuations joined, comments cut)
    are accepted by the parser."""
    import shlex

    parser = build_parser()
    text = (Path(__file__).resolve().parents[2] / page).read_text().replace("\\\n", " ")
    commands = [line.split("#", 1)[0] for line in text.splitlines() if line.startswith("footzoo ")]
    assert len(commands) >= at_least
    for cmd in commands:
        parser.parse_args(shlex.split(cmd)[1:])
