"""The command line's outputs: atomic, strict JSON, loadable, never written over an input; columns carry units."""

from __future__ import annotations

import json
import math
import re
import warnings
from pathlib import Path

import pandas as pd
import pytest

from footzoo import Result
from footzoo.apps.cli import EXIT_DATA, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE, main
from footzoo.core import archive
from footzoo.core.atomic import TMP_INFIX
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate, simulate_calibration

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=8))


@pytest.fixture(autouse=True)
def _here(monkeypatch):
    monkeypatch.chdir(ROOT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def no_temporaries(folder: Path) -> bool:
    return not [p for p in folder.rglob("*") if TMP_INFIX in p.name]


def test_run_out_into_the_folder_of_its_input_named_samples_csv_is_refused(walk, tmp_path, capsys):
    data = write(walk, tmp_path / "samples.csv")
    before = snapshot(tmp_path)
    assert main(["run", "yun2012", "--data", str(data), "--out", str(tmp_path)]) == EXIT_DATA
    err = capsys.readouterr().err
    assert "--out would overwrite the input" in err and "samples.csv" in err and "Traceback" not in err
    assert snapshot(tmp_path) == before


def test_run_out_through_a_symlink_or_dotdot_onto_the_input_is_refused(walk, tmp_path, capsys):
    data = write(walk, tmp_path / "walk.csv")
    out = tmp_path / "out"
    out.mkdir()
    (out / "steps.csv").symlink_to(data)
    assert main(["run", "yun2012", "--data", str(data), "--out", str(out)]) == EXIT_DATA
    assert "would overwrite the input" in capsys.readouterr().err
    sub = tmp_path / "a"
    sub.mkdir()
    data2 = write(walk, sub / "samples.csv")
    assert main(["run", "yun2012", "--data", str(data2), "--out", str(sub / ".." / "a")]) == EXIT_DATA
    assert data2.read_bytes() == write(walk, tmp_path / "copy.csv").read_bytes()


def test_calibrate_out_equal_to_data_is_refused(tmp_path, capsys):
    data = write(simulate_calibration(rate=100.0), tmp_path / "cal.csv")
    before = data.read_bytes()
    assert main(["calibrate", "--data", str(data), "--out", str(data)]) == EXIT_USAGE  # refused before it is read
    assert "the foot-vector calibration is a YAML file" in capsys.readouterr().err and data.read_bytes() == before
    assert main(["calibrate", "--data", str(data), "--out", str(tmp_path / "fv.yaml")]) == EXIT_OK
    assert (tmp_path / "fv.yaml").read_text().startswith("foot_vector:") and no_temporaries(tmp_path)


@pytest.mark.parametrize("argv", [["run", "yun2012", "--out", ""], ["simulate", "straight", "--out", " "],
                                  ["calibrate", "--data", "x.csv", "--out", ""]])
def test_an_empty_out_is_a_usage_error(argv, capsys):
    assert main(argv) == EXIT_USAGE
    assert "argument --out: an empty path" in capsys.readouterr().err


def test_simulate_refuses_an_unknown_extension_before_simulating(tmp_path, capsys):
    assert main(["simulate", "straight", "--out", str(tmp_path / "walk.xlsx")]) == EXIT_DATA
    assert "not '.xlsx'; choose one of these extensions" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_while_simulate_writes_leaves_the_old_file_and_its_sidecars(walk, tmp_path, monkeypatch, capsys):
    target = tmp_path / "walk.csv"
    assert main(["simulate", "straight", "--strides", "3", "--rate", "100", "--out", str(target)]) == EXIT_OK
    before = snapshot(tmp_path)
    real = pd.DataFrame.to_csv

    def interrupted(self, path=None, *args, **kwargs):
        real(self.iloc[: len(self) // 2], path, *args, **kwargs)  # half of the file is on disk ...
        raise KeyboardInterrupt  # ... when the user presses Ctrl-C

    monkeypatch.setattr(pd.DataFrame, "to_csv", interrupted)
    assert main(["simulate", "straight", "--strides", "5", "--rate", "100", "--out", str(target)]) == EXIT_INTERRUPTED
    assert snapshot(tmp_path) == before and no_temporaries(tmp_path)


def test_ctrl_c_while_run_writes_keeps_the_earlier_result(walk, tmp_path, monkeypatch):
    data = write(walk, tmp_path / "walk.csv")
    out = tmp_path / "out"
    assert main(["run", "yun2012", "--data", str(data), "--out", str(out)]) == EXIT_OK
    before = snapshot(out)
    real = archive._write_table
    calls = []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(archive, "_write_table", interrupted)
    assert main(["run", "yun2012", "--data", str(data), "--out", str(out)]) == EXIT_INTERRUPTED
    assert snapshot(out) == before and no_temporaries(out)
    Result.load(out)


def test_run_out_is_a_loadable_result_with_strict_json(walk, tmp_path, monkeypatch, capsys):
    data = write(walk, tmp_path / "walk.csv")
    out = tmp_path / "out"
    nan_metrics = {"path_length_m": 1.0, "armse_3d_m": math.nan, "strides": 3}
    # the one computation behind Result.metrics, metric_notes and checked_metrics (what save writes)
    monkeypatch.setattr(Result, "_checked_metrics", lambda self: (dict(nan_metrics), {}))
    assert main(["run", "yun2012", "--data", str(data), "--out", str(out)]) == EXIT_OK
    assert "Result.load" in capsys.readouterr().out
    text = (out / "metrics.json").read_text()
    payload = json.loads(text, parse_constant=lambda c: pytest.fail(f"bare {c} in metrics.json"))
    assert payload["metrics"]["armse_3d_m"] is None and "NaN" not in text
    names = {p.name for p in out.iterdir()}
    assert {"samples.csv", "steps.csv", "metrics.json", "result.json", "manifest.json"} <= names
    back = Result.load(out)
    assert str(data) in back.recording["input_files"] and len(back.samples) == walk.n


def test_steps_csv_columns_carry_units(tmp_path):
    rec = simulate(n_strides=4, rate=50.0)
    path = write(rec, tmp_path / "walk.csv")
    assert main(["run", "huang2016", "--data", str(path), "--out", str(tmp_path / "out")]) == 0
    cols = pd.read_csv(tmp_path / "out" / "steps.csv").columns
    unit = re.compile(r"_(s|m|m_s|rad|steps_min)$")
    assert all(unit.search(c) for c in cols if c != "events_from_rate"), list(cols)
    assert "fpa_rad" in cols and "heading_rad" in cols


def test_run_names_every_file_it_wrote_and_keeps_the_values_in_one_column(walk, tmp_path, capsys):
    data = write(walk, tmp_path / "walk.csv")  # with true steps: the result holds the reference's steps as a table
    out = tmp_path / "out"
    assert main(["run", "yun2012", "--data", str(data), "--out", str(out)]) == EXIT_OK
    printed = capsys.readouterr().out
    wrote = next(line for line in printed.splitlines() if line.startswith("wrote "))
    listed = wrote.removeprefix("wrote ").split(" to ")[0].split(", ")
    assert sorted(listed) == sorted(p.name for p in out.iterdir())
    assert any(name.startswith("table_") for name in listed)
    rows = [line for line in printed.splitlines() if line.startswith("  ")]
    assert any(len(line.split()[0]) > 32 for line in rows)  # a name longer than the usual column
    assert len({len(line) - len(line.lstrip()[len(line.split()[0]):].lstrip()) for line in rows}) == 1


@pytest.mark.slow  # a whole run through the command line (about 1.3 s)
def test_run_out_dot_slash_dash_writes_a_folder_named_dash(walk, tmp_path, monkeypatch, capsys):
    """``--out -`` is refused (standard output); ``--out ./-`` names a folder '-', although it is Path('-') once a
    Path, which Result.save refuses as it refuses the text '-'."""
    data = write(walk, tmp_path / "walk.csv")
    monkeypatch.chdir(tmp_path)
    assert main(["run", "yun2012", "--data", str(data), "--out", "./-"]) == EXIT_OK
    assert len(Result.load(tmp_path / "-").samples) == walk.n
