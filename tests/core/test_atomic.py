"""Atomic outputs: a file appears complete under its final name or not at all, and never replaces an input."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from footzoo.core import atomic
from footzoo.core.atomic import (
    TMP_INFIX,
    FileGroup,
    atomic_path,
    atomic_write,
    check_target,
    folder_lock,
    refuse_inputs,
    write_json,
    write_text,
)
from footzoo.core.errors import OutputError

ROOT = Path(__file__).resolve().parents[2]


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if TMP_INFIX in p.name)


def test_a_written_file_replaces_the_old_one_and_leaves_no_temporary(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")
    with atomic_write(p) as fh:
        fh.write("new")
        assert p.read_text() == "old"  # not visible before the block ends
    assert p.read_text() == "new" and leftovers(tmp_path) == []


@pytest.mark.parametrize("error", [RuntimeError, KeyboardInterrupt])
def test_an_error_or_ctrl_c_while_writing_keeps_the_old_file(tmp_path, error):
    p = tmp_path / "a.csv"
    p.write_text("t,acc_x\n0,1\n")
    with pytest.raises(error), atomic_write(p) as fh:
        fh.write("t,acc_x\n0,")
        raise error()
    assert p.read_text() == "t,acc_x\n0,1\n" and leftovers(tmp_path) == []


def test_an_error_before_a_first_write_creates_no_file(tmp_path):
    p = tmp_path / "new.csv"
    with pytest.raises(RuntimeError), atomic_path(p) as tmp:
        tmp.write_text("half")
        raise RuntimeError
    assert not p.exists() and leftovers(tmp_path) == []


def test_a_process_killed_while_writing_leaves_the_old_file_complete(tmp_path):
    """The process dies inside the block (no clean-up runs): the final name still holds the old content."""
    p = tmp_path / "samples.csv"
    p.write_text("old complete file\n")
    code = (f"import os\nfrom footzoo.core.atomic import atomic_write\n"
            f"with atomic_write({str(p)!r}) as fh:\n    fh.write('x' * 100000)\n    fh.flush()\n    os._exit(9)\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    assert subprocess.run([sys.executable, "-c", code], env=env).returncode == 9
    assert p.read_text() == "old complete file\n"
    assert len(leftovers(tmp_path)) == 1  # the dead process's temporary file, under a hidden name


def test_new_files_get_the_usual_permissions(tmp_path):
    old = os.umask(0o022)
    try:
        p = write_text(tmp_path / "x.txt", "x")
    finally:
        os.umask(old)
    assert p.stat().st_mode & 0o777 == 0o644


def test_a_group_commits_all_members_or_none(tmp_path):
    data, side = tmp_path / "w.csv", tmp_path / "w.csv.meta.yaml"
    data.write_text("old data")
    side.write_text("old side")
    with pytest.raises(RuntimeError), FileGroup() as group:
        group.path(data).write_text("new data")
        raise RuntimeError("the sidecar could not be made")
    assert (data.read_text(), side.read_text()) == ("old data", "old side")
    with FileGroup() as group:
        group.path(data).write_text("new data")
        group.path(side).write_text("new side")
    assert (data.read_text(), side.read_text()) == ("new data", "new side") and leftovers(tmp_path) == []


def test_a_stale_sidecar_is_removed_with_the_commit_only(tmp_path):
    data, steps = tmp_path / "w.csv", tmp_path / "w.csv.steps.csv"
    steps.write_text("stale")
    with pytest.raises(RuntimeError), FileGroup() as group:
        group.path(data).write_text("new")
        group.remove(steps)
        raise RuntimeError
    assert steps.exists()
    with FileGroup() as group:
        group.path(data).write_text("new")
        group.remove(steps)
    assert not steps.exists() and data.read_text() == "new"


def test_ctrl_c_during_the_renames_is_held_until_all_are_done(tmp_path, monkeypatch):
    real = os.replace
    calls = []

    def replace_then_interrupt(src, dst):
        real(src, dst)
        calls.append(dst)
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(atomic.os, "replace", replace_then_interrupt)
    a, b = tmp_path / "a", tmp_path / "b"
    with pytest.raises(KeyboardInterrupt), FileGroup() as group:
        group.path(a).write_text("A")
        group.path(b).write_text("B")
    assert a.read_text() == "A" and b.read_text() == "B"  # both in place before the interrupt is raised


def test_an_output_that_is_an_input_is_refused_however_it_is_spelt(tmp_path):
    data = tmp_path / "d" / "samples.csv"
    data.parent.mkdir()
    data.write_text("recording")
    (tmp_path / "link.csv").symlink_to(data)
    os.link(data, tmp_path / "hard.csv")
    spellings = [data, tmp_path / "d" / ".." / "d" / "samples.csv", tmp_path / "link.csv", tmp_path / "hard.csv"]
    for target in spellings:
        with pytest.raises(OutputError, match=r"would overwrite the input .*samples.csv.*choose another"):
            refuse_inputs([target], [data], "--out")
        with pytest.raises(OutputError, match="would overwrite the input"), FileGroup(inputs=[data]) as group:
            group.path(target)
    assert data.read_text() == "recording" and leftovers(tmp_path) == [] and leftovers(data.parent) == []
    refuse_inputs([tmp_path / "other.csv"], [data])  # a different (new) file is fine
    with pytest.raises(OutputError, match="would overwrite the input"):
        FileGroup(inputs=[data]).remove(tmp_path / "link.csv")


@pytest.mark.parametrize("target, fragment", [("", "empty path"), ("  ", "empty path"), (".", "is a directory"),
                                              ("no/such/dir/x.csv", "does not exist; create it first")])
def test_unusable_targets_are_refused_before_any_work(target, fragment, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError, match=fragment):
        check_target(target)


def test_strict_json_has_no_bare_nan(tmp_path):
    value = {"a": float("nan"), "b": [np.float64("inf"), np.int64(3), np.bool_(True)], "c": np.arange(2.0),
             "d": (1, 2), "e": tmp_path, "f": "1e3"}
    p = write_json(tmp_path / "m.json", value)

    def refuse(constant):
        raise AssertionError(f"bare {constant} in the JSON")

    back = json.loads(p.read_text(), parse_constant=refuse)
    assert back == {"a": None, "b": [None, 3, True], "c": [0.0, 1.0], "d": [1, 2], "e": str(tmp_path), "f": "1e3"}


def test_a_locked_folder_refuses_a_second_writer(tmp_path):
    with folder_lock(tmp_path / "study") as folder:
        with pytest.raises(OutputError, match=r"is being written by footzoo process \d+"), \
                folder_lock(folder):
            pass
    with folder_lock(tmp_path / "study"):  # released
        pass
