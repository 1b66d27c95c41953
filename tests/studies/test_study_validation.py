"""A study is validated whole before anything runs; failed runs report their distinct causes."""

import warnings

import numpy as np
import pytest
import yaml

from footzoo import ConfigError
from footzoo.apps.cli import main
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate
from footzoo.studies import Study, run_study
from footzoo.studies.study import MAX_CELLS

from ..conftest import HARD_IRON_NOT_FITTED

SIM = {"simulate": {"path": "straight", "n_strides": 4, "rate": 50, "noise": {"scale": 1}}, "seeds": [0]}
BASE = {"name": "small", "base": "yun2012", "recordings": [SIM]}


def test_a_factor_without_levels_is_an_error():
    with pytest.raises(ConfigError, match="factor 'detector.threshold' has no levels"):
        Study.from_dict({**BASE, "factors": {"detector.threshold": []}})


def test_a_huge_grid_is_refused_at_once_and_the_limit_can_be_raised():
    factors = {"a.x": list(range(1000)), "a.y": list(range(100)), "a.z": list(range(100))}
    with pytest.raises(ConfigError, match=r"10,000,000 runs .* more than the limit of 10,000.*max_cells"):
        Study.from_dict({**BASE, "factors": factors})
    study = Study.from_dict({**BASE, "factors": factors, "max_cells": 10**7})
    assert study.size == 10**7 and study.max_cells == 10**7  # counted, no cell built
    small = {"a.x": list(range(MAX_CELLS))}
    assert Study.from_dict({**BASE, "factors": small}).size == MAX_CELLS
    with pytest.raises(ConfigError, match="more than the limit of 100"):
        Study.from_dict({**BASE, "factors": small}, max_cells=100)


def test_a_misspelt_parameter_stops_the_study_before_any_run(tmp_path):
    study = Study.from_dict({**BASE, "factors": {"detector.treshold": [0.5, 1.0]}})
    with pytest.raises(ConfigError, match=r"(?s)2 of 2 config\(s\) invalid.*nothing was run.*"
                       r"unknown parameter 'treshold'.*did you mean 'threshold'") as err:
        run_study(study, out=tmp_path / "out")
    assert "(2 case(s), the first: base='yun2012', detector.treshold=0.5)" in str(err.value)  # the levels
    assert not list((tmp_path / "out").glob("cache/*.json"))


def test_a_misspelt_top_level_path_and_a_reader_option_are_caught(tmp_path):
    with pytest.raises(ConfigError, match="detectr"):
        run_study(Study.from_dict({**BASE, "factors": {"detectr.type": ["shoe"]}}))
    write(simulate(n_strides=4, rate=50.0, noise=NoiseModel(seed=0)), tmp_path / "walk.csv")
    bad = {**BASE, "recordings": [{"path": str(tmp_path / "walk.csv"), "acc_unti": "g"}]}
    with pytest.raises(ConfigError, match=r"unknown option 'acc_unti' \(did you mean 'acc_unit'\?\)"):
        run_study(Study.from_dict(bad))


def test_jobs_in_the_study_file():
    assert Study.from_dict({**BASE, "jobs": 2}).jobs == 2
    with pytest.raises(ConfigError, match="jobs must be a number of worker processes"):
        Study.from_dict({**BASE, "jobs": "two"})


def _study_file(tmp_path, d) -> str:
    p = tmp_path / "study.yaml"
    p.write_text(yaml.safe_dump(d))
    return str(p)


def test_a_study_whose_every_run_failed_exits_non_zero_with_the_causes(tmp_path, capsys):
    (tmp_path / "garbage.csv").write_bytes(bytes(range(256)) * 4)
    path = _study_file(tmp_path, {**BASE, "recordings": [{"path": str(tmp_path / "garbage.csv")}]})
    code = main(["study", path, "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 3
    assert "every run failed; the distinct causes:" in err and "FormatError" in err


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_a_partly_failed_study_prints_the_distinct_causes(tmp_path, capsys):
    (tmp_path / "garbage.csv").write_bytes(bytes(range(256)) * 4)
    write(simulate(n_strides=4, rate=50.0, noise=NoiseModel(seed=0)), tmp_path / "walk.csv")
    path = _study_file(tmp_path, {**BASE, "recordings": [{"path": str(tmp_path / "*.csv")}]})
    assert main(["ablate", path, "--out", str(tmp_path / "out"), "--quiet"]) == 0
    captured = capsys.readouterr()
    assert "1 run failed; the distinct causes:" in captured.err and "(1 run)" in captured.err
    assert "2 runs (2 computed" in captured.out


def test_quiet_silences_the_runs_warnings():
    study = Study.from_dict(BASE)  # yun2012's hard-iron calibration warns on a straight walk
    with warnings.catch_warnings(record=True) as loud:
        warnings.simplefilter("always")
        run_study(study)
    assert any("hard_iron" in str(w.message) for w in loud)
    with warnings.catch_warnings(record=True) as quiet:
        warnings.simplefilter("always")
        table = run_study(study, quiet=True)
    assert not [w for w in quiet if "hard_iron" in str(w.message)]
    assert np.isfinite(table["value"]).any()


def test_calibrate_refuses_a_walk_and_takes_a_calibration_trial(tmp_path, capsys):
    from footzoo.sim import simulate_calibration

    write(simulate_calibration(mount_yaw=0.3, noise=NoiseModel(seed=1)), tmp_path / "cal.csv")
    write(simulate(n_strides=10, rate=100.0, noise=NoiseModel(seed=0)), tmp_path / "walk.csv")
    assert main(["calibrate", "--data", str(tmp_path / "cal.csv"), "--out", str(tmp_path / "fv.yaml")]) == 0
    assert (tmp_path / "fv.yaml").exists()
    capsys.readouterr()
    assert main(["calibrate", "--data", str(tmp_path / "walk.csv"), "--out", str(tmp_path / "fv2.yaml")]) == 3
    err = capsys.readouterr().err
    assert "is not a calibration trial" in err and "rad/s" in err and "departs from gravity" in err
    assert not (tmp_path / "fv2.yaml").exists()


def test_old_cache_entries_are_pruned(tmp_path):
    import os
    import time

    from footzoo.studies.cache import prune_cache

    cache = tmp_path / "cache"
    cache.mkdir()
    now = time.time()
    for name, age_days, size in (("fresh", 0, 100), ("old", 40, 100), ("older_kept", 50, 100), ("big", 10, 5000)):
        f = cache / f"{name}.json"
        f.write_bytes(b"x" * size)
        os.utime(f, (now - age_days * 86400, now - age_days * 86400))
    out = prune_cache(cache, keep={"older_kept"}, max_age_days=30)
    assert out == {"removed": 1, "kept": 3, "bytes": 5200}
    assert sorted(f.stem for f in cache.glob("*.json")) == ["big", "fresh", "older_kept"]
    # then by size: the least recently used entry not kept goes first ("big", 10 days), until 300 bytes
    assert prune_cache(cache, keep={"older_kept"}, max_age_days=None, max_bytes=300)["removed"] == 1
    assert sorted(f.stem for f in cache.glob("*.json")) == ["fresh", "older_kept"]
    assert prune_cache(cache, keep=set(), max_age_days=0)["kept"] == 0


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_a_study_prunes_other_studies_entries_on_request(tmp_path):
    out = tmp_path / "out"
    one = {**BASE, "recordings": [SIM]}
    two = {**BASE, "recordings": [{**SIM, "seeds": [5]}]}
    run_study(Study.from_dict(one), out=out, report=False)
    run_study(Study.from_dict(two), out=out, report=False)
    assert len(list((out / "cache").glob("*.json"))) == 2  # young entries stay by default
    table = run_study(Study.from_dict(two), out=out, report=False, prune={"max_age_days": 0})
    assert table.attrs["pruned"]["removed"] == 1 and table.attrs["cached"] == 1
    assert len(list((out / "cache").glob("*.json"))) == 1


def test_one_file_read_for_each_foot_is_named_after_the_foot(tmp_path):
    both = tmp_path / "imu_sample.csv"
    both.write_text("two feet\n")
    feet = [{"path": str(both), "foot": "left"}, {"path": str(both), "foot": "right"}]
    study = Study.from_dict({"name": "feet", "base": "yun2012", "recordings": feet})
    assert [r.label for r in study.recordings] == ["imu_sample_left", "imu_sample_right"]
    labelled = [{**feet[0], "label": "L"}, feet[1]]  # a given label is kept
    assert [r.label for r in Study.from_dict({"name": "f", "base": "yun2012", "recordings": labelled}).recordings] \
        == ["L", "imu_sample"]
    with pytest.raises(ConfigError, match="both called 'imu_sample_left'"):  # the same foot twice is still refused
        Study.from_dict({"name": "f", "base": "yun2012", "recordings": [feet[0], feet[0]]})


def test_a_recording_given_as_a_path_alone_is_read_as_that_file(tmp_path):
    for name in ("a.csv", "b.csv"):
        (tmp_path / name).write_text("t\n")
    study = Study.from_dict({"name": "p", "base": "yun2012", "recordings": [str(tmp_path / "a.csv"), "b.csv"]},
                            root=tmp_path)  # an absolute path, and one relative to the study file
    assert [(r.label, r.path, r.format) for r in study.recordings] == [
        ("a", str(tmp_path / "a.csv"), None), ("b", str(tmp_path / "b.csv"), None)]
    with pytest.raises(ConfigError, match=r"recordings\[0\] must be a file path or glob, \{path: GLOB\} with optional "
                                          r"format:.*got 3"):
        Study.from_dict({"name": "p", "base": "yun2012", "recordings": [3]})
