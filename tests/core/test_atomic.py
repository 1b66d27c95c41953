"""Atomic outputs: a file appears complete under its final name or not at all, and never replaces an input."""

from __future__ import annotations

import errno
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
    INCOMPLETE,
    LOCK_NAME,
    TMP_INFIX,
    FileGroup,
    atomic_path,
    atomic_write,
    begin_folder,
    check_complete,
    check_target,
    end_folder,
    folder_lock,
    incomplete,
    lock_holder,
    previous_marker,
    refuse_inputs,
    write_json,
    write_text,
)
from footzoo.core.errors import FormatError, OutputError

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


def test_a_killed_writers_old_temporaries_are_removed_when_the_folder_is_locked_again(tmp_path):
    """Hidden temporaries a SIGKILL left (up to 17 MB each) no later run would remove: the next command that locks
    the folder removes those older than an hour, never a younger one (a writer may still be at work)."""
    old, young = tmp_path / f".samples.csv{atomic.TMP_INFIX}0a1b2c3d", tmp_path / f".steps.csv{atomic.TMP_INFIX}4e5f"
    for f in (old, young):
        f.write_text("partial")
    hour_ago = os.stat(old).st_mtime - atomic.STALE_TEMPORARY - 1
    os.utime(old, (hour_ago, hour_ago))
    with atomic.folder_lock(tmp_path):
        pass
    assert not old.exists() and young.exists()


def test_the_recording_writer_removes_its_own_old_temporaries(tmp_path):
    from footzoo.io.canonical import write
    from footzoo.sim import simulate

    stale = [tmp_path / f".walk.csv{atomic.TMP_INFIX}00", tmp_path / f".walk.csv.meta.yaml{atomic.TMP_INFIX}01"]
    other = tmp_path / f".notes.csv{atomic.TMP_INFIX}02"  # another file's: left alone
    for f in (*stale, other):
        f.write_text("partial")
        os.utime(f, (0, 0))
    write(simulate(n_strides=2, rate=50.0), tmp_path / "walk.csv")
    assert not any(f.exists() for f in stale) and other.exists()


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


def test_a_locked_folder_refuses_a_second_writer_naming_the_first(tmp_path):
    """Another thread (or process) asking for a held folder is refused at once with the holder's description."""
    import threading

    errors = []
    with folder_lock(tmp_path / "study", owner="study 'quick'") as folder:
        holder = lock_holder(folder)
        assert holder["owner"] == "study 'quick'" and holder["pid"] == os.getpid() and holder["host"]

        def second():
            try:
                with folder_lock(folder, owner="study 'other'"):
                    pass
            except OutputError as err:
                errors.append(str(err))

        thread = threading.Thread(target=second)
        thread.start()
        thread.join()
        with folder_lock(folder):  # the same thread may enter again (a tune runs its studies in its folder)
            pass
        assert (folder / LOCK_NAME).exists()
    assert len(errors) == 1 and "is in use: study 'quick' (process" in errors[0]
    assert "another output folder" in errors[0]
    assert not (tmp_path / "study" / LOCK_NAME).exists()  # released and removed
    with folder_lock(tmp_path / "study"):
        pass


def test_the_same_study_twice_shares_the_folder_and_another_is_refused(tmp_path):
    """Holders that give the same identity (one study started twice) share; the last one out removes the file."""
    import threading

    folder = tmp_path / "study"
    entered, leave, errors = threading.Event(), threading.Event(), []

    def hold(identity, owner):
        try:
            with folder_lock(folder, owner=owner, identity=identity):
                entered.set()
                leave.wait(30)
        except OutputError as err:
            errors.append(str(err))

    first = threading.Thread(target=hold, args=("study-A", "study 'a'"))
    first.start()
    assert entered.wait(30)
    second = threading.Thread(target=hold, args=("study-A", "study 'a'"))
    other = threading.Thread(target=hold, args=("study-B", "study 'b'"))
    second.start()
    other.start()
    other.join(30)
    assert len(errors) == 1 and "is in use: study 'a'" in errors[0]  # the other study, refused
    leave.set()
    first.join(30)
    second.join(30)
    assert len(errors) == 1 and not (folder / LOCK_NAME).exists()  # the same one joined; the last removed the file


def test_two_holders_of_one_study_leaving_at_once_remove_the_lock_file(tmp_path, monkeypatch):
    """Each leaver may see the other still holding the file; the last to look again removes it."""
    import threading

    folder, inside = tmp_path / "study", threading.Barrier(2, timeout=30)
    seen_by_both = threading.Barrier(2, timeout=30)  # both leavers test the lock before either closes
    real, leaving = atomic._try_lock, threading.local()

    def try_lock(fh, exclusive=True, wait=False):
        if exclusive and not wait and getattr(leaving, "first", False):  # each leaver's first look
            leaving.first = False
            seen_by_both.wait()
            return False  # as when both look at the same instant, each still seeing the other's lock
        return real(fh, exclusive, wait)

    monkeypatch.setattr(atomic, "_try_lock", try_lock)

    errors = []

    def hold():
        try:
            with folder_lock(folder, owner="study 'a'", identity="study-A"):
                inside.wait()
                leaving.first = True
        except Exception as err:  # noqa: BLE001 (reported below)
            errors.append(err)

    threads = [threading.Thread(target=hold) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    assert errors == [] and not (folder / LOCK_NAME).exists()


def test_the_same_study_started_while_the_first_writes_its_description_joins_it(tmp_path):
    """Between taking the lock and describing itself the first holder's file is empty: the second one waits and
    joins (it was refused as if another study held the folder)."""
    import fcntl
    import threading

    folder = tmp_path / "study"
    folder.mkdir()
    with open(folder / LOCK_NAME, "w", encoding="utf-8") as first:  # the first holder, not described yet
        fcntl.flock(first.fileno(), fcntl.LOCK_EX)
        joined, errors = threading.Event(), []

        def second():
            try:
                with folder_lock(folder, owner="study 'a'", identity="study-A"):
                    joined.set()
            except OutputError as err:
                errors.append(str(err))

        thread = threading.Thread(target=second)
        thread.start()
        assert not joined.wait(0.2)  # waiting for the description
        first.write(json.dumps({"owner": "study 'a'", "pid": os.getpid(), "identity": "study-A"}) + "\n")
        first.flush()
        fcntl.flock(first.fileno(), fcntl.LOCK_SH)  # described: the same study may join
        thread.join(10)
    assert errors == [] and joined.is_set()


def test_a_lock_held_by_another_process_is_refused_and_released_when_it_dies(tmp_path):
    folder = tmp_path / "out"
    code = ("import sys, time\nfrom footzoo.core.atomic import folder_lock\n"
            f"with folder_lock({str(folder)!r}, owner='study \\'first\\''):\n"
            "    print('locked', flush=True)\n    time.sleep(60)\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "locked"
        with pytest.raises(OutputError, match=rf"is in use: study 'first' \(process {proc.pid} on .* since .*\)"):
            with folder_lock(folder, owner="study 'second'"):
                pass
    finally:
        proc.kill()  # dies holding the lock: no clean-up runs
        proc.wait()
    assert (folder / LOCK_NAME).exists() and lock_holder(folder)["pid"] == proc.pid  # left behind by the dead process
    with folder_lock(folder, owner="study 'second'"):  # stale: taken over
        assert lock_holder(folder)["owner"] == "study 'second'"


def test_without_file_locks_a_dead_holder_is_stale_and_a_live_one_is_not(tmp_path, monkeypatch):
    """On a file system without locks (some network file systems) the lock file's process id decides."""
    monkeypatch.setattr(atomic, "_try_lock", lambda fh: None)
    folder = tmp_path / "out"
    folder.mkdir()
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    (folder / LOCK_NAME).write_text(json.dumps({"owner": "study 'gone'", "pid": int(dead.stdout),
                                                "host": atomic._host(), "started": "2024-01-01 10:00:00"}))
    with folder_lock(folder, owner="study 'new'"):
        assert lock_holder(folder)["owner"] == "study 'new'"
    (folder / LOCK_NAME).write_text(json.dumps({"owner": "study 'alive'", "pid": os.getppid(), "host": atomic._host()}))
    with pytest.raises(OutputError, match="study 'alive'.*If that process no longer runs.*delete"):
        with folder_lock(folder):
            pass
    (folder / LOCK_NAME).write_text(json.dumps({"owner": "study 'far'", "pid": 1, "host": "another-machine"}))
    with pytest.raises(OutputError, match="study 'far' \\(process 1 on another-machine\\)"):
        with folder_lock(folder):
            pass


def test_a_marked_group_sets_the_old_marker_aside_first_and_writes_the_new_one_last(tmp_path, monkeypatch):
    """The manifest of a folder output is its completion marker: a process killed between the renames leaves the
    folder without one (refused as incomplete), never the old manifest beside new files."""
    folder = tmp_path / "result"
    folder.mkdir()
    with FileGroup(marker=folder / "manifest.json") as group:
        group.path(folder / "a.csv").write_text("1")
        group.path(folder / "manifest.json").write_text('{"files": ["a.csv"]}')
    assert check_complete(folder, "manifest.json", "a result") == folder
    seen = []
    real = os.replace

    def replace(src, dst):
        seen.append((Path(dst).name, (folder / "manifest.json").exists(), (folder / INCOMPLETE).exists()))
        if Path(dst).name == "b.csv":
            raise KeyboardInterrupt  # the process "dies" here (a kill is not deferred)
        real(src, dst)

    monkeypatch.setattr(atomic.os, "replace", replace)
    with pytest.raises(KeyboardInterrupt), FileGroup(marker=folder / "manifest.json") as group:
        group.path(folder / "a.csv").write_text("2")
        group.path(folder / "b.csv").write_text("2")
        group.path(folder / "manifest.json").write_text('{"files": ["a.csv", "b.csv"]}')
    monkeypatch.undo()
    assert seen[0][0] == INCOMPLETE  # the old manifest set aside first...
    assert ("a.csv", False, True) in seen  # ...before any member replaced an old file
    assert not (folder / "manifest.json").exists() and incomplete(folder)
    with pytest.raises(FormatError, match=r"is incomplete: footzoo was interrupted while writing a result there"):
        check_complete(folder, "manifest.json", "a result")
    assert previous_marker(folder, "manifest.json") == {"files": ["a.csv"]}  # what the next write needs to know
    with FileGroup(marker=folder / "manifest.json") as group:  # written again: complete
        group.path(folder / "manifest.json").write_text('{"files": []}')
    assert not incomplete(folder) and check_complete(folder, "manifest.json", "a result")


def test_a_folder_output_is_incomplete_from_its_start_until_its_marker_is_written(tmp_path):
    folder = tmp_path / "study"
    folder.mkdir()
    with pytest.raises(FormatError, match="holds no outputs.json: it is not a report written by footzoo"):
        check_complete(folder, "outputs.json", "a report")
    end_folder(folder, "outputs.json", '{"digest": "one"}')
    assert begin_folder(folder, "outputs.json") == {"digest": "one"}
    assert incomplete(folder) and not (folder / "outputs.json").exists()
    assert begin_folder(folder, "outputs.json") == {"digest": "one"}  # an interrupted run's marker is kept
    end_folder(folder, "outputs.json", '{"digest": "two"}')
    assert not incomplete(folder) and previous_marker(folder, "outputs.json") == {"digest": "two"}


def _group_write(path: Path) -> None:
    with atomic.FileGroup(what="test") as group, group.open(path) as fh:
        fh.write("new")


@pytest.mark.parametrize("writer", [lambda p: atomic.write_text(p, "new"), lambda p: atomic.write_bytes(p, b"new"),
                                    lambda p: atomic.write_json(p, {"new": 1}), _group_write],
                         ids=["write_text", "write_bytes", "write_json", "FileGroup.open"])
def test_a_full_disk_while_writing_is_an_output_error_naming_the_file_and_the_old_file_is_kept(tmp_path, monkeypatch,
                                                                                                writer):
    target = tmp_path / "out.json"
    target.write_text("old")

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(atomic.os, "fsync", full)
    with pytest.raises(atomic.OutputError, match=r"out.json' cannot be written: no space left on the device; the old "
                                                 r"file is kept"):
        writer(target)
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["out.json"]


@pytest.mark.parametrize("layout, fix", [("file", "it is a file, and the output is a folder"),
                                         ("under_a_file", "choose a folder you can write to")])
def test_a_locked_folder_that_cannot_be_made_names_the_fix(tmp_path, layout, fix):
    (tmp_path / "taken").write_text("a user's file")
    target = tmp_path / "taken" if layout == "file" else tmp_path / "taken" / "out"
    with pytest.raises(OutputError, match=f"--out '{target}' cannot be created: .*; {fix}"):
        with folder_lock(target, "--out", owner="study 'x'"):
            pass
    assert (tmp_path / "taken").read_text() == "a user's file"
