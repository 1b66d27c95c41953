"""Output folders: locked per study or run, and never left looking complete after an interruption.

* two studies (or runs) started on one output folder: the second is refused at once, naming the first
  and how to proceed; a lock left by a killed process is stale and taken over;
* Ctrl-C (SIGINT, sent to a real process at a chosen point) during a study, a ``run --out``, a
  ``simulate --out`` over an existing file: the earlier output stays whole, or the folder is marked
  incomplete (its completion marker, written last, is missing) and footzoo's readers refuse it;
* a second ``run --plot --out`` into a folder: the figures of the earlier run that this one does not
  draw go with the earlier result (the folder holds one run's outputs, listed in its manifest);
* a study whose report would replace a table no earlier study there wrote (a user's ``results.csv``):
  refused before any run.
"""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import yaml

from footzoo import Pipeline, Result
from footzoo.apps.cli import EXIT_DATA, EXIT_INTERRUPTED, EXIT_OK, main
from footzoo.core.atomic import INCOMPLETE, LOCK_NAME, TMP_INFIX, lock_holder
from footzoo.core.errors import CalibrationWarning, FormatError, OutputError
from footzoo.io import load
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate
from footzoo.studies import read_trajectories, run_study

from ..conftest import HARD_IRON_NOT_FITTED

# the runs are yun2012's on a straight simulated walk, which gives no hard-iron fit (expected warning)
pytestmark = pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
ROOT = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}

SLOW_DETECTOR = '''
"""angular_rate_fsm that says when it starts and then waits (a test of interrupted and concurrent writers)."""
import os
import pathlib
import time

import footzoo
from footzoo.detectors.angular_rate_fsm import AngularRateFSM


@footzoo.register
class SlowFSM(AngularRateFSM):
    """angular_rate_fsm after a pause of FOOTZOO_TEST_SLEEP s (it touches FOOTZOO_TEST_STARTED first)."""

    name = "test_slow_fsm"

    def detect(self, t, acc, gyr, ctx=None):
        started = os.environ.get("FOOTZOO_TEST_STARTED")
        if started:
            pathlib.Path(started).touch()
        time.sleep(float(os.environ.get("FOOTZOO_TEST_SLEEP", "0")))
        return super().detect(t, acc, gyr, ctx=ctx)
'''

#: A script that runs the command line with ``DataFrame.to_csv`` stopping after its first table: Ctrl-C lands
#: while the outputs are being written.
STOP_IN_WRITE = textwrap.dedent('''
    import os, pathlib, sys, time
    import pandas as pd
    real = pd.DataFrame.to_csv
    def stopping(self, *args, **kwargs):
        out = real(self, *args, **kwargs)
        pathlib.Path(os.environ["FOOTZOO_TEST_STARTED"]).touch()
        time.sleep(120)
        return out
    pd.DataFrame.to_csv = stopping
    from footzoo.apps.cli import main
    sys.exit(main(sys.argv[1:]))
''')


def _leftovers(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if TMP_INFIX in p.name)


def _digest(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and "cache" not in p.parts}


def _start(argv: list[str], started: Path, sleep: float = 120.0, script: str | None = None) -> subprocess.Popen:
    """The command line in a process of its own, and wait until it reports that it reached the chosen point."""
    cmd = [sys.executable, "-c", script, *argv] if script else [sys.executable, "-m", "footzoo", *argv]
    proc = subprocess.Popen(cmd, env={**ENV, "FOOTZOO_TEST_STARTED": str(started), "FOOTZOO_TEST_SLEEP": str(sleep)},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while not started.exists():
        if proc.poll() is not None:
            raise AssertionError(f"the process ended ({proc.returncode}) before the chosen point: {proc.stderr.read()}")
        if time.monotonic() > deadline:
            proc.kill()
            raise AssertionError("the process did not reach the chosen point")
        time.sleep(0.05)
    return proc


def _interrupt(proc: subprocess.Popen) -> tuple[int, str]:
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    return proc.returncode, err


@pytest.fixture(autouse=True)
def _unregistered():
    """The slow detector, loaded by a test's studies in this process from that test's own folder, leaves the registry
    with the test: the next test's copy (another file, another module) registers the name again."""
    from footzoo.plugins import registry

    registry._REGISTRY["detector"].pop("test_slow_fsm", None)
    yield
    registry._REGISTRY["detector"].pop("test_slow_fsm", None)


@pytest.fixture(scope="module")
def walk_file(tmp_path_factory) -> Path:
    return write(simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1)), tmp_path_factory.mktemp("w") / "w.csv")


def _study(folder: Path, name: str, detector: str) -> Path:
    (folder / "slow.py").write_text(SLOW_DETECTOR)
    spec = {"name": name, "plugins": ["slow.py"], "base": "yun2012",
            "factors": {"detector.type": [detector]},
            "recordings": [{"simulate": {"path": "straight", "n_strides": 3, "rate": 100, "noise": {"scale": 1}},
                            "seeds": [0]}],
            "metrics": ["path_length_m"], "figures": "none"}
    p = folder / f"{name}.yaml"
    p.write_text(yaml.safe_dump(spec))
    return p


@pytest.mark.slow
def test_a_second_study_on_a_busy_folder_is_refused_and_an_interrupted_one_leaves_it_marked_incomplete(tmp_path):
    out = tmp_path / "out"
    first = _study(tmp_path, "first", "angular_rate_fsm")
    run_study(first, out=out, quiet=True)
    assert (out / "outputs.json").exists() and not (out / INCOMPLETE).exists()
    before = read_trajectories(out)

    slow = _study(tmp_path, "slow", "test_slow_fsm")
    proc = _start(["ablate", str(slow), "--out", str(out), "--quiet"], tmp_path / "started")
    try:
        # the folder is busy: another study is refused at once, naming the one at work and how to proceed
        with pytest.raises(OutputError, match=r"is in use: study 'slow' \(process \d+ on .* since .*\) is writing "
                                              r"into it\. Wait until it has finished, or give this one another"):
            run_study(first, out=out, quiet=True)
        assert main(["ablate", str(first), "--out", str(out), "--quiet"]) == EXIT_DATA
        assert lock_holder(out)["owner"] == "study 'slow'"
        # and its report is marked incomplete while it runs: the earlier report is not taken for the new one
        with pytest.raises(FormatError, match="is incomplete: footzoo was interrupted while writing a study's report"):
            read_trajectories(out)
    finally:
        code, err = _interrupt(proc)
    assert code == EXIT_INTERRUPTED and "interrupted" in err and "Traceback" not in err
    assert not (out / "outputs.json").exists() and (out / INCOMPLETE).exists() and not (out / LOCK_NAME).exists()
    with pytest.raises(FormatError, match="is incomplete"):
        read_trajectories(out)
    assert _leftovers(out) == []
    run_study(first, out=out, quiet=True)  # run again: complete, with the first study's numbers
    assert (out / "outputs.json").exists() and not (out / INCOMPLETE).exists()
    assert read_trajectories(out).equals(before)


def test_a_lock_left_by_a_killed_study_is_stale(tmp_path):
    out = tmp_path / "out"
    code = ("import time\nfrom footzoo.core.atomic import folder_lock\n"
            f"with folder_lock({str(out)!r}, owner=\"study 'killed'\"):\n    print('in', flush=True)\n"
            "    time.sleep(120)\n")
    proc = subprocess.Popen([sys.executable, "-c", code], env=ENV, stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "in"
    proc.kill()
    proc.wait()
    assert lock_holder(out)["owner"] == "study 'killed'"
    table = run_study(_study(tmp_path, "next", "angular_rate_fsm"), out=out, quiet=True, report=False, max_runs=0)
    assert table.attrs["failed"] == 0 and not (out / LOCK_NAME).exists()  # taken over, and released


@pytest.mark.slow
def test_ctrl_c_during_a_run_keeps_the_earlier_result_whole(tmp_path, walk_file):
    """Interrupted while the pipeline runs (a slow plug-in): nothing of the new run is written."""
    out = tmp_path / "run"
    assert main(["run", "yun2012", "--data", str(walk_file), "--out", str(out)]) == EXIT_OK
    before = _digest(out)
    (tmp_path / "slow.py").write_text(SLOW_DETECTOR)
    cfg = tmp_path / "slow.yaml"
    cfg.write_text((ROOT / "configs" / "yun2012.yaml").read_text().replace("type: angular_rate_fsm",
                                                                            "type: test_slow_fsm")
                   + "plugins: [slow.py]\n")
    proc = _start(["run", str(cfg), "--data", str(walk_file), "--out", str(out)], tmp_path / "started")
    code, err = _interrupt(proc)
    assert code == EXIT_INTERRUPTED and "Traceback" not in err
    assert _digest(out) == before and _leftovers(out) == [] and not (out / LOCK_NAME).exists()
    Result.load(out)


@pytest.mark.slow
@pytest.mark.parametrize("command", ["run", "simulate"])
def test_ctrl_c_while_the_outputs_are_written_leaves_the_earlier_ones(command, tmp_path, walk_file):
    """Interrupted between two files of one output (the first table written, the rest not): the earlier output
    is there as it was, with no temporary file, and reads back."""
    if command == "run":
        target = tmp_path / "run"
        argv = ["run", "yun2012", "--data", str(walk_file), "--out", str(target)]
    else:
        target = tmp_path / "sim" / "walk.csv"
        target.parent.mkdir()
        argv = ["simulate", "straight", "--strides", "3", "--out", str(target)]
    assert main(argv) == EXIT_OK
    folder = target if target.is_dir() else target.parent
    before = _digest(folder)
    proc = _start([*argv[:-1], str(target)] if command == "run" else [*argv[:3], "4", *argv[4:]],
                  tmp_path / "started", script=STOP_IN_WRITE)
    code, err = _interrupt(proc)
    assert code == EXIT_INTERRUPTED and "Traceback" not in err
    assert _digest(folder) == before and _leftovers(folder) == []
    if command == "run":
        Result.load(target)


def test_files_saved_with_a_result_go_with_it(tmp_path, walk_file):
    """What a second ``run --plot --out`` relies on: the files saved with a result (its figures) are listed in its
    manifest and replaced by the next save; the same name from elsewhere is never replaced."""
    with pytest.warns(CalibrationWarning, match="hard_iron: magnetometer left uncalibrated"):  # a straight walk
        result = Pipeline.from_yaml("yun2012").run(load(walk_file))
    out = tmp_path / "r"
    result.save(out, backend="csv", files={"trajectory.png": b"first", "fpa.png": b"first"})
    result.save(out, backend="csv", files={"trajectory.png": b"second"})
    assert (out / "trajectory.png").read_bytes() == b"second" and not (out / "fpa.png").exists()
    result.save(out, backend="csv")
    assert not (out / "trajectory.png").exists()
    (out / "fpa.png").write_bytes(b"mine")
    with pytest.raises(OutputError, match="already holds fpa.png, which no earlier footzoo result there wrote"):
        result.save(out, backend="csv", files={"fpa.png": b"third"})
    assert (out / "fpa.png").read_bytes() == b"mine" and Result.load(out).steps.equals(result.steps)


@pytest.mark.slow
def test_a_second_run_with_or_without_plot_keeps_only_its_own_figures(tmp_path, walk_file):
    out = tmp_path / "run"
    argv = ["run", "yun2012", "--data", str(walk_file), "--out", str(out)]
    assert main([*argv, "--plot"]) == EXIT_OK
    figures = sorted(p.name for p in out.glob("*.png"))
    assert "trajectory.png" in figures and "errors.png" in figures
    manifest = yaml.safe_load((out / "manifest.json").read_text())
    assert set(figures) <= set(manifest["files"])  # listed with the result they belong to
    assert main(argv) == EXIT_OK  # no figures this time: the earlier run's go with its result
    assert sorted(p.name for p in out.glob("*.png")) == []


def test_a_file_the_user_put_there_under_a_figure_name_is_not_replaced(tmp_path, walk_file, capsys):
    out = tmp_path / "run"
    out.mkdir()
    (out / "trajectory.png").write_bytes(b"my own figure")
    assert main(["run", "yun2012", "--data", str(walk_file), "--out", str(out), "--plot"]) == EXIT_DATA
    assert "already holds trajectory.png, which no earlier footzoo result there wrote" in capsys.readouterr().err
    assert (out / "trajectory.png").read_bytes() == b"my own figure"


def test_a_result_folder_marked_incomplete_is_refused_by_load(tmp_path, walk_file):
    out = tmp_path / "run"
    assert main(["run", "yun2012", "--data", str(walk_file), "--out", str(out)]) == EXIT_OK
    os.replace(out / "manifest.json", out / INCOMPLETE)  # what a process killed between the renames leaves
    with pytest.raises(FormatError, match="is incomplete: footzoo was interrupted while writing a result there"):
        Result.load(out)
    assert main(["run", "yun2012", "--data", str(walk_file), "--out", str(out)]) == EXIT_OK  # written again
    assert not (out / INCOMPLETE).exists()
    Result.load(out)


@pytest.mark.parametrize("name", ["results.csv", "summary.md"])
def test_a_study_does_not_replace_report_tables_it_did_not_write(name, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / name).write_text("mine,1\n")  # the user's own table, under a name a study's report uses
    before = _digest(out)
    with pytest.raises(OutputError, match=rf"already holds {name}, which no earlier study there wrote"):
        run_study(_study(tmp_path, "next", "angular_rate_fsm"), out=out, quiet=True, max_runs=0)  # before any run
    assert _digest(out) == before


def test_a_study_does_not_replace_the_log_of_a_saved_run(tmp_path, walk_file):
    """A run's folder lists its footzoo.log in its manifest.json: a study's log over it would be lost work."""
    out = tmp_path / "out"
    assert main(["run", "yun2012", "--data", str(walk_file), "--out", str(out), "--quiet"]) == EXIT_OK
    before = _digest(out)
    with pytest.raises(OutputError, match=r"holds a saved result \(its manifest.json, e.g. of footzoo run --out\) "
                                          r"whose footzoo.log the study's log would replace"):
        run_study(_study(tmp_path, "next", "angular_rate_fsm"), out=out, quiet=True, max_runs=0)
    assert _digest(out) == before
    Result.load(out)


def test_ctrl_c_while_the_command_line_starts_ends_with_one_line_and_code_130(monkeypatch, capsys):
    """The console script (and python -m footzoo) wraps even the command line's imports: no traceback."""
    import configparser

    from footzoo.apps import cli, entry

    def interrupted(argv=None):
        raise KeyboardInterrupt  # as a Ctrl-C while pandas is imported

    monkeypatch.setattr(cli, "main", interrupted)
    assert entry.main(["run", "yun2012"]) == EXIT_INTERRUPTED
    assert capsys.readouterr().err == "footzoo: interrupted\n"
    setup = configparser.ConfigParser()
    setup.read(Path(__file__).resolve().parents[2] / "setup.cfg")
    assert "footzoo = footzoo.apps.entry:main" in setup["options.entry_points"]["console_scripts"]
