"""Ablation studies: grids, every valid combination, parallel back ends, resumable cache, outputs."""

import subprocess
import sys
import time

import numpy as np
import pytest

from footzoo import ConfigError
from footzoo.apps.compat import check, combinations
from footzoo.studies import Study, run_study, set_dotted

SMALL = {
    "name": "small",
    "base": {"name": "yun", "orientation": {"type": "fqa_complementary"}, "detector": {"type": "angular_rate_fsm"},
             "corrections": [{"type": "zvu_dedrift"}]},
    "factors": {"detector.type": ["angular_rate_fsm", "windowed"], "orientation.static_gain": [0.5, 1.05]},
    "recordings": [{"simulate": {"path": "straight", "n_strides": 4, "rate": 50, "noise": {"scale": 1}},
                    "seeds": [0, 1]}],
}


def test_dotted_overrides_and_type_changes():
    cfg = {"detector": {"type": "dgp", "min_swing": 0.2}, "corrections": [{"type": "zvu_dedrift"}]}
    set_dotted(cfg, "detector.type", "shoe")
    assert cfg["detector"] == {"type": "shoe"}  # the old type's parameters are dropped
    set_dotted(cfg, "detector.threshold", 1e5)
    set_dotted(cfg, "corrections.0.type", "zupt")
    set_dotted(cfg, "orientation.static_gain", 2.0)
    assert cfg["detector"] == {"type": "shoe", "threshold": 1e5}
    assert cfg["corrections"] == [{"type": "zupt"}] and cfg["orientation"] == {"static_gain": 2.0}


def test_study_errors_name_the_problem(tmp_path):
    with pytest.raises(ConfigError, match=r"unknown study key 'factor' \(did you mean 'factors'\?\)"):
        Study.from_dict({**SMALL, "factor": {}})
    with pytest.raises(ConfigError, match="no file matches"):
        Study.from_dict({**SMALL, "recordings": [{"path": str(tmp_path / "*.mat")}]})
    with pytest.raises(ConfigError, match=r"no file matches 'lab/\*\.mat', neither from the working folder .* nor "
                                          r"from the study file's .*: fix the path"):
        Study.from_dict({**SMALL, "recordings": [{"path": "lab/*.mat"}]}, root=tmp_path)


def test_a_shipped_study_run_away_from_its_data_says_how_to_copy_it(tmp_path, monkeypatch):
    from footzoo.config.library import BUILTIN

    monkeypatch.chdir(tmp_path)  # not the repository's root: ../shared/data is not beside it
    spec = {**SMALL, "recordings": [{"path": "../shared/data/pyshoe_vicon/*.mat", "format": "pyshoe"}]}
    with pytest.raises(ConfigError, match=r"a shipped study finds its data from the repository's root; copy it next "
                                          r"to your data \(footzoo configs --copy"):
        Study.from_dict(spec, root=BUILTIN)
    assert len(Study.from_dict(SMALL).cells()) == 2 * 2 * 2


@pytest.mark.slow
def test_serial_joblib_and_dask_give_identical_tables():
    from dask.distributed import LocalCluster

    serial = run_study(Study.from_dict(SMALL))
    parallel = run_study(Study.from_dict(SMALL), jobs=2)
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=":0") as cluster:
        distributed = run_study(Study.from_dict(SMALL), scheduler=cluster.scheduler_address)
    assert len(serial) > 0 and serial["error"].isna().all()
    for other in (parallel, distributed):
        assert serial.drop(columns="value").equals(other.drop(columns="value"))
        np.testing.assert_array_equal(serial["value"].to_numpy(), other["value"].to_numpy())


@pytest.mark.slow
def test_an_interrupted_study_resumes_without_redoing_work(tmp_path):
    study = Study.from_dict(SMALL)
    first = run_study(study, out=tmp_path, max_runs=3)  # what a kill after three runs leaves
    assert first.attrs["computed"] == 3
    second = run_study(study, out=tmp_path)
    assert second.attrs["computed"] == 8 - 3 and second.attrs["cached"] == 3
    third = run_study(study, out=tmp_path)
    assert third.attrs["computed"] == 0
    assert second.equals(third)
    for name in ("results.csv", "results.parquet", "summary.md", "summary.tex"):
        assert (tmp_path / name).stat().st_size > 0
    assert list(tmp_path.glob("trajectories_*.png")) and list(tmp_path.glob("metric_*_by_detector_type.png"))


@pytest.mark.slow
def test_killing_the_command_line_run_keeps_finished_runs(tmp_path):
    study = tmp_path / "study.yaml"
    import yaml

    big = {**SMALL, "factors": {**SMALL["factors"], "orientation.dynamic_gain": [0.0, 0.1, 0.2]}}
    study.write_text(yaml.safe_dump(big))
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "footzoo", "ablate", str(study), "--out", str(out), "--quiet"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    while time.time() < deadline and len(list((out / "cache").glob("*.json"))) < 2:
        time.sleep(0.05)
    proc.kill()
    proc.wait()
    done = len(list((out / "cache").glob("*.json")))
    assert 2 <= done < 24
    table = run_study(Study.from_yaml(study), out=out)
    assert table.attrs["cached"] == done and table.attrs["computed"] == 24 - done


def test_a_failing_run_is_reported_and_the_study_goes_on():
    study = Study.from_dict({**SMALL, "factors": {"corrections": [[{"type": "zvu_dedrift"}],
                                                                  [{"type": "height_distance"}]]}})
    table = run_study(study)
    failed = table[table["error"].notna()]
    assert len(failed) == 2 and failed["error"].str.contains("distance-sensor columns").all()
    assert table["metric"].notna().sum() > 0


# the combinations include the plug-ins other test modules registered in this process; some are plain Python on
# purpose and run on the reference engine with this warning (expected)
@pytest.mark.filterwarnings("ignore:correction .test_[a-z_]+.. measurement model not compilable:"
                            "footzoo.core.errors.FootzooWarning")
@pytest.mark.slow
def test_every_valid_combination_gives_a_finite_trajectory():
    from footzoo import Pipeline
    from footzoo.sim import NoiseModel, simulate

    rec = simulate(n_strides=3, rate=50.0, profile="physical", noise=NoiseModel(seed=0), distance_sensors=True,
                   clearance=0.1)
    valid = rejected = 0
    for cfg in combinations(max_corrections=2):
        why = check(cfg)
        if why is not None:
            rejected += 1
            assert len(why) > 20  # a reason, not a bare failure
            continue
        valid += 1
        res = Pipeline.from_dict(cfg).run(rec)
        assert np.isfinite(res.pos).all() and np.isfinite(res.quat).all(), cfg
    assert valid > 200 and rejected > 0
