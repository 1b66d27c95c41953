"""The recording writer: it refuses an unknown extension and its own input, and never leaves a data file without its
sidecar.
"""

from __future__ import annotations

import pytest

from footzoo.core.atomic import TMP_INFIX
from footzoo.core.errors import OutputError
from footzoo.io import load
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate


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


def test_the_writer_replaces_its_own_recording_but_never_a_users_file(tmp_path):
    """``footzoo simulate --out notes.csv`` replaced a user's file of that name without a word (data loss)."""
    from footzoo.apps.cli import EXIT_DATA, main

    rec = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))
    notes = tmp_path / "notes.csv"
    notes.write_text("my notes, not a recording\n")
    with pytest.raises(OutputError, match=r"'.*notes.csv' exists and is not a recording footzoo wrote \(no "
                                          r"notes.csv.meta.yaml describes it as it is\): footzoo replaces only its own "
                                          r"outputs; choose another name, or delete or move the file first"):
        write(rec, notes)
    assert main(["simulate", "straight", "--strides", "3", "--out", str(notes)]) == EXIT_DATA
    assert notes.read_text() == "my notes, not a recording\n" and sorted(tmp_path.iterdir()) == [notes]
    own = write(rec, tmp_path / "walk.csv")
    assert write(simulate(n_strides=4, rate=100.0), own) == own  # footzoo's own recording is replaced, as before
    assert load(own).n > rec.n
    # a user's file under a sidecar's name, with no recording beside it, is not footzoo's either
    for side in ("lone.csv.meta.yaml", "lone.csv.steps.csv"):
        (tmp_path / side).write_text("mine\n")
        with pytest.raises(OutputError, match=rf"its sidecar {side} .* already exists without lone.csv, and footzoo "
                                              "did not write it: move it away, or choose another name"):
            write(rec, tmp_path / "lone.csv")
        assert main(["simulate", "straight", "--strides", "3", "--out", str(tmp_path / "lone.csv")]) == EXIT_DATA
        assert (tmp_path / side).read_text() == "mine\n" and not (tmp_path / "lone.csv").exists()
        (tmp_path / side).unlink()
