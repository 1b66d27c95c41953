"""Studies survive damage: checked cache entries, bad recordings failing their own cells, retries, storage, progress."""

import json
import shutil

import numpy as np
import pandas as pd
import pytest
import yaml

from footzoo import ConfigError, Pipeline
from footzoo.apps.cli import main
from footzoo.evaluation.validity import MetricWarning
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate
from footzoo.studies import CacheWarning, Study, read_trajectories, run_study
from footzoo.studies import runner as runner_mod
from footzoo.studies.cache import CACHE_FORMAT, read_entry

from ..conftest import ON_PROCESS_CLUSTER, made_once

BASE = {"name": "yun", "orientation": {"type": "fqa_complementary"}, "detector": {"type": "angular_rate_fsm"},
        "corrections": [{"type": "zvu_dedrift"}]}
SIM = {"simulate": {"path": "straight", "n_strides": 4, "rate": 50, "noise": {"scale": 1}}, "seeds": [0, 1]}
#: Figures are drawn only where a test is about them (drawing is most of a small study's time).
SMALL = {"name": "small", "base": BASE, "factors": {"detector.type": ["angular_rate_fsm", "windowed"]},
         "recordings": [SIM], "figures": "none"}


def entries(out):
    return sorted((out / "cache").glob("*.json"))


# --------------------------------------------------------------------------- damaged cache entries


def test_damaged_cache_entries_are_recomputed_and_reported(tmp_path):
    study = Study.from_dict(SMALL)
    first = run_study(study, out=tmp_path)
    files = entries(tmp_path)
    assert len(files) == 4 and first.attrs["computed"] == 4
    truncated, edited, foreign, swapped = files
    shutil.copy(truncated, swapped)  # a sound entry, but another cell's
    truncated.write_bytes(truncated.read_bytes()[:-200])
    header, payload = edited.read_bytes().split(b"\n", 1)
    record = json.loads(payload)
    record["metrics"]["path_length_m"] += 1.0  # a hand edit that keeps the JSON valid
    edited.write_bytes(header + b"\n" + json.dumps(record, sort_keys=True, separators=(",", ":")).encode())
    foreign.write_text(json.dumps({"metrics": {"path_length_m": 1.0}}))  # an old-format or foreign file
    with pytest.warns(CacheWarning, match="4 damaged cache entries"):
        second = run_study(study, out=tmp_path)
    problems = second.attrs["recomputed"]
    assert set(problems) == {f.stem for f in files}
    assert "truncated" in problems[truncated.stem] and "checksum mismatch" in problems[edited.stem]
    assert "not a footzoo cache entry" in problems[foreign.stem] and "another cell" in problems[swapped.stem]
    assert second.attrs["computed"] == 4 and second.attrs["cached"] == 0
    assert second.equals(first)  # recomputed, not reused
    log = (tmp_path / "cache_report.log").read_text()
    assert all(f"{f.stem}.json" in log for f in files)
    third = run_study(study, out=tmp_path)  # the entries are sound again
    assert third.attrs["cached"] == 4 and third.attrs["recomputed"] == {}


def test_an_entry_is_a_header_with_the_checksum_then_the_record(tmp_path):
    run_study(Study.from_dict(SMALL), out=tmp_path)
    f = entries(tmp_path)[0]
    header = json.loads(f.read_bytes().split(b"\n", 1)[0])
    assert header["format"] == CACHE_FORMAT and header["key"] == f.stem and len(header["sha256"]) == 64
    record, problem = read_entry(f, f.stem)
    assert problem is None and record["key"] == f.stem
    assert read_entry(f, "0" * 24) == (None, f"belongs to another cell (key {f.stem!r})")
    f.write_bytes(b"\x00\xff" * 10)
    assert read_entry(f, f.stem)[1].startswith("not a footzoo cache entry")


def test_an_unwritable_cache_does_not_lose_the_results(tmp_path, monkeypatch):
    def full_disk(path, key, record):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(runner_mod, "write_entry", full_disk)
    with pytest.warns(CacheWarning, match="could not write the cache entry .*No space left on device"):
        table = run_study(Study.from_dict(SMALL), out=tmp_path)
    assert table["error"].isna().all() and table.attrs["computed"] == 4


# --------------------------------------------------------------------------- bad recordings


@pytest.fixture
def folder_of_recordings(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    rec = simulate(n_strides=4, rate=50.0, noise=NoiseModel(seed=0))
    write(rec, data / "a_good.parquet")
    (data / "b_dangling.parquet").symlink_to(data / "nowhere.parquet")
    (data / "c_folder.parquet").mkdir()
    (data / "d_garbage.parquet").write_bytes(bytes(range(256)) * 4)
    return data


def test_a_link_in_a_loop_is_named_with_its_fix():
    import os
    import tempfile

    from footzoo.studies.study import RecordingSpec

    with tempfile.TemporaryDirectory() as d:
        os.symlink("b.csv", os.path.join(d, "a.csv"))
        os.symlink("a.csv", os.path.join(d, "b.csv"))
        problem = RecordingSpec("a", path=os.path.join(d, "a.csv")).problem()
    assert "is a symbolic link in a loop" in problem and "a.csv -> b.csv -> a.csv" in problem
    assert "point it at a real file" in problem


@pytest.mark.slow
def test_a_dangling_link_or_a_directory_fails_its_cells_not_the_study(tmp_path, folder_of_recordings):
    d = {**SMALL, "recordings": [{"path": str(folder_of_recordings / "*.parquet")}]}
    out = tmp_path / "out"
    table = run_study(Study.from_dict(d), out=out, jobs=2)
    by_rec = {rec: g for rec, g in table.groupby("recording")}
    assert set(by_rec) == {"a_good", "b_dangling", "c_folder", "d_garbage"}
    assert by_rec["a_good"]["error"].isna().all() and by_rec["a_good"]["metric"].notna().all()
    assert by_rec["b_dangling"]["error"].str.contains("dangling link").all()
    assert by_rec["c_folder"]["error"].str.contains("is a directory").all()
    assert by_rec["c_folder"]["error"].str.contains(r"\*\.csv", regex=True).all()  # the glob to give instead
    assert by_rec["d_garbage"]["error"].str.startswith("FormatError: ").all()
    assert table.attrs["failed"] == 6 and "failed runs" in (out / "summary.md").read_text()
    # the data changes: the link's target appears; its cells run again (new key), the others stay cached
    write(simulate(n_strides=5, rate=50.0, noise=NoiseModel(seed=1)), folder_of_recordings / "nowhere.parquet")
    again = run_study(Study.from_dict(d), out=out)
    assert again.attrs["computed"] == 2 + 2  # b_dangling now readable, and the new file nowhere.parquet
    assert again.attrs["cached"] == 2 + 2 + 2  # a_good, and the failures of c_folder and d_garbage (unchanged)
    good = again[again["recording"].isin(["a_good", "b_dangling", "nowhere"])]
    assert good["error"].isna().all()
    values = {rec: g.set_index(["detector.type", "metric"])["value"] for rec, g in good.groupby("recording")}
    # the link reads its target's data, but none of the sidecars beside the target (its true steps): fewer metrics,
    # the same values of those it has
    link, target = values["b_dangling"], values["nowhere"]
    assert set(link.index) < set(target.index)
    np.testing.assert_array_equal(link.to_numpy(), target.loc[link.index].to_numpy())
    assert not np.array_equal(link.to_numpy(), values["a_good"].loc[link.index].to_numpy())


@pytest.mark.slow
def test_a_cached_run_takes_the_labels_of_the_cell_that_reads_it(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    write(simulate(n_strides=4, rate=50.0, noise=NoiseModel(seed=0)), data / "first.parquet")
    d = {**SMALL, "recordings": [{"path": str(data / "*.parquet")}]}
    run_study(Study.from_dict(d), out=tmp_path / "out")
    for suffix in ("", ".meta.yaml", ".steps.csv"):  # the same content and sidecars: same key, cached
        shutil.copy(data / f"first.parquet{suffix}", data / f"second.parquet{suffix}")
    table = run_study(Study.from_dict(d), out=tmp_path / "out")
    assert table.attrs["cached"] == 4 and sorted(set(table["recording"])) == ["first", "second"]


@pytest.mark.slow
def test_failed_cells_are_retried_when_footzoos_code_changes_and_only_then(tmp_path, monkeypatch):
    d = {**SMALL, "factors": {"corrections": [[{"type": "zvu_dedrift"}], [{"type": "height_distance"}]]}}
    first = run_study(Study.from_dict(d), out=tmp_path)
    assert first.attrs["failed"] == 2
    same = run_study(Study.from_dict(d), out=tmp_path)
    assert same.attrs["computed"] == 0 and same.attrs["retried"] == []
    monkeypatch.setattr(runner_mod, "code_fingerprint", lambda: "an edited footzoo")
    retried = run_study(Study.from_dict(d), out=tmp_path)
    assert retried.attrs["computed"] == 2 and len(retried.attrs["retried"]) == 2 and retried.attrs["cached"] == 2
    assert retried.attrs["failed"] == 2  # still failing: the cause (no distance sensors) is in the data


def test_a_one_off_run_cell_checks_the_cache_too(tmp_path):
    from footzoo.studies import run_cell

    cell = Study.from_dict(SMALL).cells()[0]
    first = run_cell(cell, str(tmp_path))
    assert not first["cached"] and run_cell(cell, str(tmp_path))["cached"]
    f = next(tmp_path.glob("*.json"))
    f.write_text("{}")
    with pytest.warns(CacheWarning, match="not a footzoo cache entry"):
        again = run_cell(cell, str(tmp_path))
    assert not again["cached"] and again["metrics"] == first["metrics"]


# --------------------------------------------------------------------------- metric names


def test_unknown_metric_names_and_bad_job_counts_are_config_errors(tmp_path, capsys):
    with pytest.raises(ConfigError, match=r"unknown metric 'armse_3d' \(did you mean 'armse_3d_m'\?\); "
                                          r"valid metrics: \['duration_s', 'path_length_m'"):
        Study.from_dict({**SMALL, "metrics": ["strides", "armse_3d"]})
    with pytest.raises(ConfigError, match=r"jobs must be a number of worker processes .* got 0"):
        run_study(Study.from_dict(SMALL), jobs=0)
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({**SMALL, "metrics": ["stride_count"]}))
    assert main(["ablate", str(study), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "study.yaml: unknown metric 'stride_count'" in err and "valid metrics:" in err


# --------------------------------------------------------------------------- storage


def test_trajectories_are_stored_apart_from_the_table(tmp_path):
    table = run_study(Study.from_dict(SMALL), out=tmp_path)
    assert set(table.attrs) == {"computed", "cached", "failed", "recomputed", "retried", "causes", "refused",
                                "warnings", "pruned"}
    traj = read_trajectories(tmp_path)
    assert set(traj["run"]) == set(table["run"])
    # checked against a pipeline run outside the study: the stored points are its positions every 0.1 s
    cell = next(c for c in Study.from_dict(SMALL).cells() if c.levels["detector.type"] == "windowed")
    rec = cell.recording.load()
    pos = Pipeline.from_dict(cell.config).run(rec).pos
    mine = traj[traj["run"] == cell.key()]
    np.testing.assert_allclose(mine[["north_m", "east_m", "down_m"]].to_numpy(), pos[::5], atol=5e-5)
    np.testing.assert_allclose(mine["t_s"].to_numpy(), rec.t[::5], atol=5e-5)


def test_each_recording_is_loaded_once_and_shared_by_its_configs(monkeypatch):
    from footzoo.studies.study import RecordingSpec

    loads = []
    original = RecordingSpec.load

    def counting(self):
        loads.append(self.label)
        return original(self)

    monkeypatch.setattr(RecordingSpec, "load", counting)
    runner_mod._RECORDINGS.clear()
    d = {**SMALL, "factors": {"detector.type": ["angular_rate_fsm", "windowed"], "orientation.static_gain": [0.5, 1]}}
    table = run_study(Study.from_dict(d))
    assert table["error"].isna().all() and table.attrs["computed"] == 4 * 2
    assert sorted(loads) == ["sim_straight_s0", "sim_straight_s1"]


def test_chunks_cover_every_cell_once_and_hold_one_recording_each():
    d = {**SMALL, "factors": {"detector.type": ["angular_rate_fsm", "windowed", "shoe"]},
         "recordings": [{**SIM, "seeds": [0, 1, 2]}]}
    cells = Study.from_dict(d).cells()
    identity = {id(r): r.identity() for r in {id(c.recording): c.recording for c in cells}.values()}
    todo = list(range(len(cells)))
    for workers in (1, 2, 4):
        chunks = runner_mod._chunks(todo, cells, identity, workers)
        assert sorted(i for c in chunks for i in c) == todo
        assert all(len({cells[i].recording.label for i in c}) == 1 for c in chunks)
        assert len(chunks) == 3 if workers == 1 else len(chunks) >= 2 * workers  # several chunks per worker


# --------------------------------------------------------------------------- progress


def test_the_progress_bar_covers_loading_runs_and_report(tmp_path, monkeypatch):
    import tqdm

    seen = []

    class Recorder:
        def __init__(self, total, desc, unit):
            self.total, self.n, self.desc = total, 0, desc

        def set_description(self, desc):
            self.desc = desc

        def refresh(self):
            pass

        def update(self, n):
            self.n += n
            seen.append((self.desc, self.n, self.total))

        def close(self):
            seen.append(("closed", self.n, self.total))

    monkeypatch.setattr(tqdm, "tqdm", Recorder)
    run_study(Study.from_dict(SMALL), out=tmp_path, progress=True)
    phases = [d.split(": ")[-1] for d, _, _ in seen]
    assert phases[0] == "loading" and "running" in phases and phases[-2] == "report"
    assert seen[-1] == ("closed", seen[-1][2], seen[-1][2])  # 100 % exactly at the end
    assert all(n < total for d, n, total in seen[:-2])  # not full before the last report step
    assert sum(1 for p in phases if p == "report") == 4


@pytest.mark.slow
def test_outputs_are_rewritten_only_when_something_they_show_changed(tmp_path):
    study = Study.from_dict(SMALL)
    run_study(study, out=tmp_path)
    png = sorted(tmp_path.glob("trajectories_*.png"))[0]
    stamps = {f.name: f.stat().st_mtime_ns for f in tmp_path.iterdir() if f.is_file()}
    again = run_study(study, out=tmp_path)  # everything cached, outputs current: kept as they are
    assert again.attrs["cached"] == 4
    assert {f.name: f.stat().st_mtime_ns for f in tmp_path.iterdir() if f.is_file()} == stamps
    png.unlink()  # a missing output brings the report back
    run_study(study, out=tmp_path)
    assert png.exists()
    summary = (tmp_path / "summary.md").read_text()
    (tmp_path / "summary.md").write_text(summary.replace("|", "!"))  # an edited output, same size
    run_study(study, out=tmp_path)
    assert (tmp_path / "summary.md").read_text() == summary
    more = Study.from_dict({**SMALL, "recordings": [{**SIM, "seeds": [0, 1, 2]}]})
    table = run_study(more, out=tmp_path)  # a new result: the tables are written again
    assert len(pd.read_csv(tmp_path / "results.csv")) == len(table) > 0
    assert (tmp_path / "results.csv").stat().st_mtime_ns > stamps["results.csv"]


@pytest.mark.slow
def test_a_truncated_parquet_output_is_rebuilt(tmp_path):
    study = Study.from_dict(SMALL)
    first = run_study(study, out=tmp_path)
    parquet = tmp_path / "results.parquet"
    parquet.write_bytes(parquet.read_bytes()[:100])
    second = run_study(study, out=tmp_path)
    assert second.attrs["cached"] == 4
    back = pd.read_parquet(parquet)
    assert back.drop(columns="value").equals(first.drop(columns="value"))
    np.testing.assert_array_equal(back["value"].to_numpy(), first["value"].to_numpy())
    assert not list(tmp_path.glob(".staging-*"))


@pytest.mark.slow
def test_two_studies_on_one_output_folder_at_once(tmp_path):
    import subprocess
    import sys

    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({**SMALL, "recordings": [{**SIM, "seeds": [0, 1, 2]}]}))
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "footzoo", "ablate", str(study), "--out", str(out), "--quiet"]
    procs = [subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE) for _ in range(2)]
    for p in procs:
        _, err = p.communicate(timeout=600)
        assert p.returncode == 0, err.decode()
    assert all(read_entry(f, f.stem)[1] is None for f in entries(out)) and len(entries(out)) == 6
    table = run_study(Study.from_yaml(study), out=out)
    assert table.attrs["cached"] == 6 and table.attrs["recomputed"] == {}
    assert pd.read_csv(out / "results.csv").shape == table.shape


#: A study with figures of every kind (a factor of two levels each, a sweep, the ROC, trajectories).
FIGURES = {**{k: v for k, v in SMALL.items() if k != "figures"}, "sweep": {"points": 5},
           "factors": {**SMALL["factors"], "orientation.static_gain": [0.5, 1.05]}}


@pytest.fixture(scope="module")
def serial_outputs(tmp_path_factory):
    """:data:`FIGURES` run serially (once for all workers): the files the parallel runs must write alike."""
    folder = made_once(tmp_path_factory, "figures-serial", lambda tmp: run_study(Study.from_dict(FIGURES), out=tmp))
    files = {f.name: f.read_bytes() for f in folder.glob("*.png")}
    assert len(files) > 5 and "roc.png" in files
    return files, (folder / "summary.md").read_text()


@pytest.mark.slow
def test_figures_drawn_by_workers_are_the_serial_figures(tmp_path, serial_outputs):
    serial, summary = serial_outputs
    run_study(Study.from_dict(FIGURES), out=tmp_path / "parallel", jobs=2)
    parallel = {f.name: f.read_bytes() for f in (tmp_path / "parallel").glob("*.png")}
    assert serial.keys() == parallel.keys()
    assert all(serial[name] == parallel[name] for name in serial)
    assert (tmp_path / "parallel" / "summary.md").read_text() == summary


def _check_dask_figures(serial_outputs, folder, scheduler) -> None:
    serial, summary = serial_outputs
    table = run_study(Study.from_dict(FIGURES), out=folder, scheduler=scheduler)
    dask = {f.name: f.read_bytes() for f in folder.glob("*.png")}
    assert serial.keys() == dask.keys()
    assert all(serial[name] == dask[name] for name in serial)
    assert (folder / "summary.md").read_text() == summary
    assert table.attrs["failed"] == 0


@pytest.mark.slow
def test_figures_drawn_on_a_dask_cluster_of_threads_are_the_serial_figures(tmp_path, serial_outputs):
    """The cluster's workers draw in memory (one figure at a time per process), the client writes the files."""
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=":0") as cluster:
        _check_dask_figures(serial_outputs, tmp_path / "dask", cluster.scheduler_address)


@pytest.mark.slow
@ON_PROCESS_CLUSTER
def test_figures_drawn_on_a_dask_cluster_of_processes_are_the_serial_figures(tmp_path, serial_outputs,
                                                                            process_cluster):
    _check_dask_figures(serial_outputs, tmp_path / "dask", process_cluster.scheduler_address)


# --------------------------------------------------------------------------- the files beside a recording


def test_a_changed_reference_or_description_beside_a_recording_runs_its_cells_again(tmp_path):
    """The cache key holds what reading a file uses besides it: a metadata sidecar that now says the walk is a
    closed loop gives the loop closure, not the cached NaN of the run before."""
    rec = simulate(path="straight", n_strides=4, rate=50, noise=NoiseModel(scale=1, seed=0))
    walk = tmp_path / "walk.csv"
    write(rec, walk)
    study = {"name": "beside", "base": BASE, "recordings": [{"path": str(walk)}], "metrics": ["loop_closure_xy_m"]}
    with pytest.warns(MetricWarning, match="not known to be a closed walk"):
        first = run_study(Study.from_dict(study), out=tmp_path / "out")
    assert first.attrs["computed"] == 1 and first["value"].isna().all()
    assert "closed walk" in first["note"].iloc[0]
    write(rec, walk, closed_loop=True)  # the same data; its sidecar now says closed_loop: true
    second = run_study(Study.from_dict(study), out=tmp_path / "out")
    assert second.attrs["computed"] == 1 and second.attrs["cached"] == 0
    assert np.isfinite(second["value"]).all()
    third = run_study(Study.from_dict(study), out=tmp_path / "out")  # nothing changed since
    assert third.attrs["cached"] == 1 and third.equals(second)


def test_the_companions_of_a_file_are_its_readers_and_its_sidecars(tmp_path):
    from footzoo.io import companion_files

    data = tmp_path / "trial.csv"
    names = [f.name for f in companion_files(data, format="gaitmap")]
    assert names == ["trial.csv.meta.yaml", "trial.csv.steps.csv", "mocap_sample.csv", "stride_events_sample.csv",
                     "position_sample.csv"]
    shared = tmp_path / "lab" / "lab.yaml"
    assert companion_files(data, sidecar=str(shared))[-1] == shared  # sidecar= implies the generic format
    assert companion_files(data, format="generic")[-1].name == "trial.csv.footzoo.yaml"
    assert companion_files(tmp_path / "2017-11-22-11-22-03.mat", format="pyshoe")[-1].name == "trials.csv"
    assert companion_files(tmp_path / "7-1_lf.txt", format="xsens")[-1].name == "7-1.json"
    assert [f.name for f in companion_files(data)] == ["trial.csv.meta.yaml", "trial.csv.steps.csv"]  # no such file
    data.write_text("t,ax\n")
    spec = Study.from_dict({"name": "s", "base": BASE, "recordings": [{"path": str(data), "format": "generic",
                                                                        "sidecar": str(shared)}]}).recordings[0]
    before = spec.identity()
    shared.parent.mkdir()
    shared.write_text("time: {rate: 100}\n")
    assert spec.identity() != before  # the shared description appeared
    changed = spec.identity()
    shared.write_text("time: {rate: 200}\n")
    assert spec.identity() != changed  # and was edited
