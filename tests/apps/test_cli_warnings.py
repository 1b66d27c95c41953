"""``--quiet`` on every command: no warnings on the terminal, kept in the result and in the command's log."""

from __future__ import annotations

import json

import pytest

from footzoo import Result
from footzoo.apps.cli import LOG, build_parser, main
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate

from ..conftest import ALL_STANCE

#: A straight walk: yun2012's magnetometer calibration cannot fit it and says so (a CalibrationWarning).
WARNING = "hard_iron: magnetometer left uncalibrated"

# this module's subject: the command line shows and keeps that warning, so it is let through, not raised
pytestmark = pytest.mark.filterwarnings("always:.*hard_iron. magnetometer left uncalibrated:"
                                        "footzoo.core.errors.CalibrationWarning")


@pytest.fixture(scope="module")
def straight(tmp_path_factory):
    path = tmp_path_factory.mktemp("walk") / "walk.csv"
    write(simulate(path="straight", n_strides=6, rate=100.0, noise=NoiseModel(seed=0)), path)
    return path


@pytest.mark.parametrize("argv", [
    ["run", "yun2012"], ["simulate", "straight", "--out", "w.csv"], ["calibrate", "--data", "d", "--out", "f.yaml"],
    ["ablate", "study_quick"], ["study", "study_quick"], ["tune", "t.yaml"], ["list"], ["formats"], ["configs"],
    ["validate", "yun2012"], ["compile", "yun2012"],
])
def test_every_command_takes_quiet(argv):
    assert build_parser().parse_args([*argv, "--quiet"]).quiet is True
    assert build_parser().parse_args(argv).quiet is False


def test_run_quiet_shows_no_warning_and_keeps_them_in_the_result_and_the_log(straight, tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "yun2012", "--data", str(straight), "--out", str(out), "--quiet"]) == 0
    captured = capsys.readouterr()
    log = (out / LOG).read_text()
    assert f"CalibrationWarning: sim_straight: {WARNING}" in log  # the warning names the recording
    kept = Result.load(out).diagnostics["warnings"]
    assert any(WARNING in w for w in kept) and log.splitlines() == kept
    # not shown, but counted, with where they are
    assert WARNING not in captured.err and "strides" in captured.out
    assert f"footzoo: {len(kept)} warning(s) not shown (--quiet); they are kept in {out / LOG}" in captured.err


def test_run_without_quiet_shows_the_warnings_and_logs_them_too(straight, tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "yun2012", "--data", str(straight), "--out", str(out)]) == 0
    assert f"footzoo: warning: sim_straight: {WARNING}" in capsys.readouterr().err
    assert WARNING in (out / LOG).read_text()
    # a run with no warning leaves a log that says so, not the previous run's
    write(simulate(path="rectangle", n_strides=10, rate=100.0, noise=NoiseModel(seed=0)), tmp_path / "loop.csv")
    assert main(["run", "recommended", "--data", str(tmp_path / "loop.csv"), "--out", str(out)]) == 0
    assert (out / LOG).read_text() == "no warnings\n"


def test_run_quiet_without_a_folder_says_how_many_it_did_not_show(straight, capsys):
    assert main(["run", "yun2012", "--data", str(straight), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert WARNING not in err and "warning(s) not shown (--quiet)" in err


def test_a_quiet_study_logs_the_runs_warnings(straight, tmp_path, capsys):
    study = tmp_path / "study.yaml"
    study.write_text(f"name: s\nbase: yun2012\nrecordings: [{{path: {straight}}}]\nmetrics: [strides]\n")
    assert main(["ablate", str(study), "--out", f"{tmp_path / 'out'}/", "--quiet"]) == 0
    captured = capsys.readouterr()
    assert WARNING not in captured.err and f"results in {tmp_path / 'out'}/\n" in captured.out  # not 'out//'
    logged = (tmp_path / "out" / LOG).read_text().splitlines()
    assert any(WARNING in line for line in logged)
    # the terminal says how many the log holds, as a quiet run does
    assert f"{len(logged)} warning(s) not shown (--quiet); they are kept in {tmp_path / 'out' / LOG}" in captured.err
    assert LOG in json.loads((tmp_path / "out" / "outputs.json").read_text())["files"]  # part of the report


# its threshold of 10 rad/s takes every sample for stance, which the run says (expected)
@pytest.mark.filterwarnings(ALL_STANCE)
def test_a_quiet_tune_logs_the_runs_warnings(straight, tmp_path, capsys):
    tune_file = tmp_path / "tune.yaml"
    tune_file.write_text(f"name: t\nbase: yun2012\nfactors: {{detector.threshold: [10.0, 1.0]}}\n"
                         f"recordings: [{{path: {straight}, group: a}}, {{path: {straight}, group: b, label: again}}]\n"
                         "tune: {objective: armse_3d_m}\n")
    assert main(["tune", str(tune_file), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert WARNING not in err and f"not shown (--quiet); they are kept in {tmp_path / 'out' / LOG}" in err
    # one walk (read twice) and two settings: the same warning from 4 runs, once
    assert f"CalibrationWarning: 4 run(s): sim_straight: {WARNING}" in (tmp_path / "out" / LOG).read_text()


# the unknown foot's warning and the refused metrics' are this test's subject: let through, counted below
@pytest.mark.filterwarnings("always::footzoo.core.errors.FootzooWarning")
def test_a_refused_metric_is_warned_once_and_saving_the_result_warns_nothing_more(tmp_path, capsys):
    # huang2016 on a walk that names no foot and whose strides show no swing arc: the FPA metrics are refused
    # (NaN, a MetricWarning with the reason) during the run; saving the result keeps the reasons, silently
    walk = simulate(path="straight", n_strides=6, rate=100.0, noise=NoiseModel(seed=0))
    del walk.meta["foot"]
    straight = write(walk, tmp_path / "no_foot.csv")
    out = tmp_path / "run"
    assert main(["run", "huang2016", "--data", str(straight), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.count("metrics refused (NaN): fpa_mean_deg") == 1
    assert main(["run", "huang2016", "--data", str(straight), "--out", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err
    logged = (out / LOG).read_text()
    assert "metrics refused (NaN): fpa_mean_deg" in logged
    # every warning is in the log, none escaped it: the one line counts the log's
    assert f"footzoo: {len(logged.splitlines())} warning(s) not shown (--quiet); they are kept in {out / LOG}\n" == err
    assert "fpa_mean_deg" in Result.load(out).metric_notes
