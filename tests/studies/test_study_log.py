"""A study's and a tune's footzoo.log: every warning of the call, the runs' in their workers included, written
inside the folder's lock and before the completion marker (outputs.json lists it), so a folder that looks
complete never holds another run's log."""

from __future__ import annotations

import hashlib
import json
import re
import warnings

import pytest

from footzoo.core import atomic
from footzoo.core.atomic import INCOMPLETE, lock_holder
from footzoo.core.errors import CalibrationWarning, FootzooWarning, FormatError
from footzoo.core.warninglog import LOG
from footzoo.studies import Study, read_trajectories, run_study, runner, tune

#: yun2012 fits a hard-iron calibration that a straight simulated walk cannot give: each run says so in its worker
UNCALIBRATED = "hard_iron: magnetometer left uncalibrated"
SIM = {"path": "straight", "n_strides": 4, "rate": 50, "noise": {"scale": 1}}
WARNS = {"name": "warns", "base": "yun2012", "recordings": [{"simulate": SIM, "seeds": [0, 1]}],
         "metrics": ["strides"], "figures": "none"}
#: the same walks without a magnetometer calibration: no warning
CALM = {**WARNS, "name": "calm", "base": {"name": "calm", "orientation": {"type": "fqa_complementary"},
                                          "detector": {"type": "angular_rate_fsm"},
                                          "corrections": [{"type": "zvu_dedrift"}]}}


def texts(caught) -> set[str]:
    return {f"{type(w.message).__name__}: {w.message}" for w in caught}


def listed(out) -> dict[str, str]:
    """The files the folder's completion marker lists, with their SHA-256."""
    return json.loads((out / "outputs.json").read_text())["files"]


@pytest.mark.parametrize("jobs", [1, pytest.param(2, marks=pytest.mark.slow)])  # slow: two worker processes start
def test_the_log_lists_the_warnings_the_runs_gave_in_their_workers(tmp_path, jobs):
    with pytest.warns(CalibrationWarning, match=UNCALIBRATED) as caught:  # the caller gets them too
        run_study(Study.from_dict(WARNS), out=tmp_path, jobs=jobs)
    log = (tmp_path / LOG).read_text().splitlines()
    # one distinct warning per walk (their direction spreads differ), each given by one run
    named = rf"CalibrationWarning: \S+: {UNCALIBRATED}: the sensor turned too little"  # each names its recording
    assert len(log) == 2 and all(re.match(named, line) for line in log)
    # the caller gets them as one, alike but for their numbers, with the first as the example
    (shown,) = texts(caught)
    assert shown.startswith("CalibrationWarning: 2 run(s) gave 2 warnings like this one")
    assert any(shown.endswith(line.removeprefix("CalibrationWarning: ")) for line in log)
    assert listed(tmp_path)[LOG] == hashlib.sha256((tmp_path / LOG).read_bytes()).hexdigest()


def test_a_quiet_study_keeps_the_runs_warnings_in_its_log_only(tmp_path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        table = run_study(Study.from_dict(WARNS), out=tmp_path, quiet=True)
    assert not [w for w in caught if UNCALIBRATED in str(w.message)]
    log = (tmp_path / LOG).read_text().splitlines()
    assert sorted(log) == sorted(table.attrs["warnings"]) and len(log) == 2  # each given by one run


def test_the_log_is_in_place_before_the_marker_and_never_the_previous_study_s(tmp_path, monkeypatch):
    with pytest.warns(CalibrationWarning, match=UNCALIBRATED):
        run_study(Study.from_dict(WARNS), out=tmp_path)
    assert UNCALIBRATED in (tmp_path / LOG).read_text()

    at_marker = []

    def interrupted(folder, marker, text=None):  # Ctrl-C just as the next study writes its completion marker
        at_marker.append((tmp_path / LOG).read_text())
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "end_folder", interrupted)
    replaced = re.escape("the report of a study of base config(s) ['yun2012']; this study's (['calm']) replaces it")
    with pytest.raises(KeyboardInterrupt), pytest.warns(FootzooWarning, match=replaced):
        run_study(Study.from_dict(CALM), out=tmp_path)
    # the calm study's own log, written before its marker: its one warning (the report it replaces), not the
    # warns study's calibration warnings
    assert len(at_marker) == 1 and "replaces it" in at_marker[0] and UNCALIBRATED not in at_marker[0]
    assert (tmp_path / LOG).read_text() == at_marker[0]
    assert not (tmp_path / "outputs.json").exists() and (tmp_path / INCOMPLETE).exists()
    with pytest.raises(FormatError, match="is incomplete"):
        read_trajectories(tmp_path)
    monkeypatch.undo()
    with pytest.warns(FootzooWarning, match=replaced):  # the last complete report there is still the warns study's
        run_study(Study.from_dict(CALM), out=tmp_path)  # run again: complete, its log listed with the report
    log = (tmp_path / LOG).read_bytes()
    assert not (tmp_path / INCOMPLETE).exists() and log == at_marker[0].encode()
    assert listed(tmp_path)[LOG] == hashlib.sha256(log).hexdigest()
    run_study(Study.from_dict(CALM), out=tmp_path)  # and again: the folder's report is its own, nothing to say
    assert (tmp_path / LOG).read_text() == "no warnings\n"


def test_a_tune_writes_its_log_with_its_tables_inside_its_lock(tmp_path, monkeypatch):
    study = {**WARNS, "name": "tuned", "factors": {"detector.threshold": [10.0, 1.0]},
             "recordings": [{"simulate": SIM, "seeds": [0], "group": "day1"},
                            {"simulate": SIM, "seeds": [1], "group": "day2"}]}
    commits = []
    commit = atomic.FileGroup.commit

    def watched(group):  # who holds the folder, and whether a log is there yet, at each commit
        commits.append(((lock_holder(tmp_path) or {}).get("owner"), (tmp_path / LOG).exists()))
        return commit(group)

    monkeypatch.setattr(atomic.FileGroup, "commit", watched)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tune(Study.from_dict(study), {"objective": "armse_3d_m"}, out=tmp_path, quiet=True)
    assert not [w for w in caught if UNCALIBRATED in str(w.message)]  # quiet: the runs' warnings in the log only
    assert commits[-1] == ("tune 'tuned'", False)  # the log comes with the tune's last commit, the lock held
    log = (tmp_path / LOG).read_text().splitlines()  # each walk's warning, given by the runs of both settings
    calibration = [line for line in log if re.match(rf"CalibrationWarning: 2 run\(s\): \S+: {UNCALIBRATED}", line)]
    # and the 10 rad/s threshold's: it takes every sample of both walks for stance
    stance = [line for line in log if line not in calibration]
    assert len(calibration) == 2 and len(stance) == 1 and "the detector 'angular_rate_fsm' takes 100.0%" in stance[0]
    assert {"tune_folds.csv", "tune_scores.csv", "best.yaml"} <= {p.name for p in tmp_path.iterdir()}


def test_a_rerun_from_the_cache_keeps_the_runs_warnings_in_its_log_without_repeating_them(tmp_path):
    with pytest.warns(CalibrationWarning, match=UNCALIBRATED):
        run_study(Study.from_dict(WARNS), out=tmp_path)
    first = (tmp_path / LOG).read_text().splitlines()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        table = run_study(Study.from_dict(WARNS), out=tmp_path)
    assert table.attrs["cached"] == 2 and not [w for w in caught if UNCALIBRATED in str(w.message)]
    log = (tmp_path / LOG).read_text().splitlines()
    assert log == [f"{line} (from 1 cached run: warned when it ran)" for line in first]  # the same two, marked
    assert listed(tmp_path)[LOG] == hashlib.sha256((tmp_path / LOG).read_bytes()).hexdigest()


@pytest.mark.parametrize("jobs", [1, pytest.param(2, marks=pytest.mark.slow)])  # slow: two worker processes start
def test_a_readers_warnings_go_with_the_runs_to_the_log_and_a_quiet_study_prints_none(tmp_path, capfd, jobs):
    """A reader that warns while a worker loads the file (a repeated time stamp, dropped): the warning goes back with
    each run, into the log, and a quiet study (``footzoo ablate/tune --quiet``) prints nothing of it."""
    import pandas as pd

    from footzoo.sim import simulate

    frame = simulate(**{k: v for k, v in SIM.items() if k != "noise"}).to_dataframe()
    pd.concat([frame.iloc[:50], frame.iloc[49:]]).to_csv(tmp_path / "walk.csv", index=False)  # one repeated stamp
    spec = {**CALM, "recordings": [{"path": str(tmp_path / "walk.csv"), "duplicates": "drop"}]}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        table = run_study(Study.from_dict(spec), out=tmp_path / "study", quiet=True, jobs=jobs)
    assert not [w for w in caught if "repeats the previous one" in str(w.message)]
    assert "repeats the previous one" not in capfd.readouterr().err
    assert any("dropped 1 row(s) whose time stamp repeats" in w for w in table.attrs["warnings"])
    assert "dropped 1 row(s) whose time stamp repeats" in (tmp_path / "study" / LOG).read_text()


def test_warnings_that_differ_only_in_numbers_and_recordings_are_shown_once_and_logged_each():
    from footzoo.core.errors import GuardWarning
    from footzoo.core.warninglog import WarningLog

    guard = "GuardWarning: {}: detector 'fsm' found no stance for {} s (longest of {} swing(s))"
    worker = {guard.format("walk_a", 2.2, 1): 2, guard.format("walk_b", 10.8, 3): 1,
              "FootzooWarning: walk_a: dropped 3 row(s)": 2}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with WarningLog() as log:
            runner._replay_warnings(worker, {}, log, quiet=False, labels=["walk_a", "walk_b"])
    shown = [(w.category, str(w.message)) for w in caught]
    assert len(shown) == 2
    category, message = shown[0]
    assert category is GuardWarning
    assert message.startswith("3 run(s) gave 2 warnings like this one") and message.endswith(guard.format(
        "walk_a", 2.2, 1).partition(": ")[2])
    assert shown[1] == (runner.FootzooWarning, "2 run(s): walk_a: dropped 3 row(s)")
    logged = log.texts()
    assert "GuardWarning: 2 run(s): walk_a: detector 'fsm' found no stance for 2.2 s (longest of 1 swing(s))" in logged
    assert guard.format("walk_b", 10.8, 3) in logged
