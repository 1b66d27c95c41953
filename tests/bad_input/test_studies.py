"""Bad study files: a bad simulate entry, two recordings with one name, a factor that cannot be set or repeats a
level; each refused before any run.
"""

from __future__ import annotations

import re

import pytest

import footzoo
from footzoo.io.canonical import write
from footzoo.sim import simulate

from ..conftest import HARD_IRON_NOT_FITTED


@pytest.fixture(scope="module")
def walk_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("walk") / "walk.csv"
    write(simulate(n_strides=4, rate=50.0), path)
    return path


@pytest.mark.parametrize("simulate_spec, message", [
    ({"path": "straigt"}, r"recordings\[0\]\.simulate: unknown path 'straigt'"),
    ({"path": "straight", "n_strides": -4}, r"n_strides must be a whole number in \[0, 100000\].*got -4"),
    ({"path": "straight", "n_stride": 4}, r"unknown option 'n_stride' \(did you mean 'n_strides'\?\)"),
    ({"path": "straight", "rate": 0}, r"rate must be a number in \(0, 20000\] Hz, got 0"),
])
def test_a_study_refuses_a_bad_simulate_entry_before_running(simulate_spec, message):
    from footzoo.studies import Study

    with pytest.raises(footzoo.ConfigError, match=message):
        Study.from_dict({"base": "yun2012", "recordings": [{"simulate": simulate_spec}]})


@pytest.mark.parametrize("entry, twice", [({"seeds": [1, 2, 1]}, "[1]"),
                                          ({"seeds": [0, 1000], "repeats": 2}, "[1000]")])
def test_a_seed_given_twice_is_named_not_called_two_recordings_of_one_name(entry, twice):
    """Before: 'both called sim_straight_s1 ... give each entry its own label', a fix that does not apply."""
    from footzoo.studies import Study

    noisy = {"path": "straight", "n_strides": 4, "noise": {"scale": 1}}
    with pytest.raises(footzoo.ConfigError, match=rf"recordings\[0\].seeds gives seed\(s\) {re.escape(twice)} more "
                                                  r"than once .*list each seed once"):
        Study.from_dict({"base": "yun2012", "recordings": [{"simulate": noisy, **entry}]})


def test_two_recordings_with_one_name_are_refused_and_labels_tell_them_apart(walk_csv, tmp_path):
    import shutil

    from footzoo.studies import Study

    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        shutil.copy(walk_csv, tmp_path / d / "walk.csv")
    same = [{"path": str(tmp_path / d / "walk.csv")} for d in ("a", "b")]
    with pytest.raises(footzoo.ConfigError, match=r"both called 'walk'.*give each entry its own label"):
        Study.from_dict({"base": "yun2012", "recordings": same})
    labelled = [{**r, "label": d} for r, d in zip(same, ("a", "b"), strict=True)]
    study = Study.from_dict({"base": "yun2012", "recordings": labelled})
    assert [r.label for r in study.recordings] == ["a", "b"]


@pytest.mark.parametrize("factors, message", [
    ({"detector.threshold.x": [1, 2]}, r"'detector\.threshold' is a value .* one level too deep"),
    ({"detector.threshold": [0.5, 0.5]}, r"lists the level 0\.5 more than once"),
    ({"detector.threshold": [1, 1.0]}, r"lists the level 1 more than once"),  # one number, written twice
    ({"corrections": [[{"type": "zvu_dedrift"}], [{"type": "ekf_zupt", "gyro_bias": False}],
                      [{"type": "ekf_zupt", "gyro_bias": False}]]}, r"lists the level .*ekf_zupt.* more than once"),
])
def test_a_factor_that_cannot_be_set_or_repeats_a_level_is_refused(factors, message, tmp_path):
    from footzoo.studies import Study, run_study

    with pytest.raises(footzoo.ConfigError, match=message):
        study = Study.from_dict({"base": "yun2012", "factors": factors,
                                 "recordings": [{"simulate": {"path": "straight", "n_strides": 4}}]})
        run_study(study, out=tmp_path / "out", quiet=True)


def test_a_study_or_a_tune_given_as_a_mapping_is_read_as_its_file_would_be(walk_csv, tmp_path, monkeypatch):
    """The mapping a study file holds (before: a TypeError from pathlib); its errors name the problem as a file's."""
    monkeypatch.chdir(walk_csv.parent)
    study = {"name": "m", "base": "yun2012", "factors": {"detector.threshold": [0.5, 0.6]},
             "recordings": [{"path": walk_csv.name, "group": "a"}]}
    with pytest.raises(footzoo.ConfigError, match=r"recordings\[0\]: no file matches 'gone\.csv'"):
        footzoo.run_study({**study, "recordings": [{"path": "gone.csv"}]}, out=tmp_path / "s")
    with pytest.raises(footzoo.ConfigError, match="unknown study key 'factor' \\(did you mean 'factors'"):
        footzoo.run_study({"factor": {}, **study}, out=tmp_path / "s")
    with pytest.raises(footzoo.ConfigError, match="a tune file is a study file with a 'tune:' block"):
        footzoo.tune(study, out=tmp_path / "t")
    with pytest.raises(footzoo.ConfigError, match="tune.direction must be one of"):
        footzoo.tune({**study, "tune": {"objective": "armse_3d_m", "direction": "up"}}, out=tmp_path / "t")


@pytest.mark.slow  # two runs of a pipeline (about 2 s)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)  # a straight walk: yun2012's hard-iron fit is left out (expected)
def test_a_study_given_as_a_mapping_runs(walk_csv, tmp_path, monkeypatch):
    monkeypatch.chdir(walk_csv.parent)
    study = {"name": "m", "base": "yun2012", "factors": {"detector.threshold": [0.5, 0.6]},
             "recordings": [{"path": walk_csv.name}]}
    table = footzoo.run_study(study, out=tmp_path / "s", quiet=True)
    assert set(table["detector.threshold"]) == {0.5, 0.6} and table.attrs["failed"] == 0


@pytest.mark.slow  # importing dask.distributed takes about 2 s
def test_a_scheduler_address_where_something_else_answers_is_named_not_a_raw_error():
    # a web server or a proxy at the address sends bytes that Dask reads as a huge frame size (a ValueError or a
    # MemoryError inside Dask, before the fix): a ConfigError that names the address and the usual ports
    import socket
    import threading

    pytest.importorskip("dask.distributed")
    from footzoo.studies.runner import _connect

    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]

    def answer():
        with server:
            for _ in range(8):  # Dask may retry; each connection gets bytes that are not Dask's protocol
                try:
                    conn, _ = server.accept()
                except OSError:
                    return
                with conn:
                    conn.sendall(b"\xff" * 64)

    threading.Thread(target=answer, daemon=True).start()
    with pytest.raises(footzoo.ConfigError, match=rf"scheduler tcp://127\.0\.0\.1:{port}: what answers there is not "
                                                  r"a Dask scheduler.*8786"):
        _connect(f"tcp://127.0.0.1:{port}")
    server.close()
