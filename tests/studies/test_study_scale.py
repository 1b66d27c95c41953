"""Large studies: run records without their trajectories in memory, the report streamed from the cache."""


import pandas as pd
import pytest

from footzoo.studies import Study, read_trajectories, report, run_study
from footzoo.studies.cache import HEAVY, light, with_heavy

from ..conftest import ON_PROCESS_CLUSTER

STUDY = {
    "name": "scale",
    "base": {"name": "yun", "orientation": {"type": "fqa_complementary"}, "detector": {"type": "angular_rate_fsm"},
             "corrections": [{"type": "zvu_dedrift"}]},
    "factors": {"orientation.static_gain": [0.5, 1.05]},
    "recordings": [{"simulate": {"path": "straight", "n_strides": 4, "rate": 50, "noise": {"scale": 1}},
                    "seeds": [0, 1, 2]}],
    "sweep": {"points": 5},
}


def test_a_record_in_memory_has_no_trajectory_once_its_entry_holds_it(tmp_path):
    full = {"key": "k", "metrics": {"a": 1.0}, "trajectory": [[0, 1, 2, 3]], "reference": [], "roc": [[1, 0, 0]]}
    assert light(full) is full  # no cache entry: the report still needs them
    assert set(light(full, keep=False)) == {"key", "metrics"}  # no report: nothing reads them
    stored = {**full, "entry": str(tmp_path / "k.json")}
    assert not set(HEAVY) & set(light(stored))


@pytest.mark.slow  # a study of many runs
def test_the_report_reads_trajectories_back_in_batches(tmp_path, monkeypatch):
    whole = run_study(Study.from_dict(STUDY), out=tmp_path / "whole")
    expected = read_trajectories(tmp_path / "whole")
    monkeypatch.setattr(report, "FRAME_BATCH", 2)  # six runs: three batches
    batched = run_study(Study.from_dict(STUDY), out=tmp_path / "batched")
    assert batched.equals(whole)
    pd.testing.assert_frame_equal(read_trajectories(tmp_path / "batched"), expected)
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "batched" / "roc.parquet"),
                                  pd.read_parquet(tmp_path / "whole" / "roc.parquet"))
    assert len(expected) > 0 and set(expected["run"]) == set(whole["run"])
    assert sorted(p.name for p in (tmp_path / "batched").glob("*.png")) == sorted(
        p.name for p in (tmp_path / "whole").glob("*.png"))
    # the records read back from the cache are the ones written
    runs = [{"key": k, "entry": str(tmp_path / "whole" / "cache" / f"{k}.json")} for k in whole["run"].unique()]
    assert all(len(r["trajectory"]) and len(r["roc"]) == 5 for r in with_heavy(runs))


@pytest.mark.slow
@ON_PROCESS_CLUSTER
def test_a_study_on_a_dask_cluster_writes_the_same_outputs(tmp_path, process_cluster):
    serial = run_study(Study.from_dict(STUDY), out=tmp_path / "serial")
    dask = run_study(Study.from_dict(STUDY), scheduler=process_cluster.scheduler_address, out=tmp_path / "dask")
    assert dask.equals(serial)
    pd.testing.assert_frame_equal(read_trajectories(tmp_path / "dask"), read_trajectories(tmp_path / "serial"))
    assert sorted(p.name for p in (tmp_path / "dask").glob("*.png")) == sorted(
        p.name for p in (tmp_path / "serial").glob("*.png"))
