"""Result.save / Result.load (and a session's): lossless, self-describing, atomic, never over an input."""

from __future__ import annotations

import datetime as dt
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import footzoo
from footzoo import FormatError, Pipeline, Result, Session, SessionResult
from footzoo.core import archive
from footzoo.core.atomic import INCOMPLETE, TMP_INFIX
from footzoo.core.errors import OutputError
from footzoo.io import load
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate

BACKENDS = ["csv", pytest.param("parquet", marks=pytest.mark.skipif(not archive.parquet_available(),
                                                                   reason="pyarrow is not installed"))]


@pytest.fixture(scope="module")
def result() -> Result:
    rec = simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=4))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Pipeline.from_yaml("yun2012").run(rec)


def tricky() -> Result:
    """A result whose tables and values exercise every dtype and marker the archive has."""
    n = 5
    samples = pd.DataFrame({"t": np.arange(n) / 100.0 + 1_764_590_400.123456789, "qw": [1.0, np.nan, np.inf, -np.inf,
                                                                                        0.1 + 0.2],
                            "stance": [True, False, True, True, False]})
    steps = pd.DataFrame({
        "start_s": [0.5, np.nan, 1 / 3], "count": np.array([1, -2, 3], dtype=np.int64),
        "turn": [True, False, True], "label": ["1e3", "", None], "code": ["0x10", "true", "ünïcode, \"quoted\"\n"],
        "mixed": [True, 2.5, "x"], "maybe": pd.array([1, None, 3], dtype="Int64"),
        "flag": pd.array([True, None, False], dtype="boolean"), "kind": pd.Categorical(["a", "b", "a"]),
        "small": np.array([1.5, 2.5, 3.5], dtype=np.float32), "u": np.array([1, 2, 3], dtype=np.uint16),
    })
    diagnostics = {"stat": np.linspace(0, 1, n), "mask": np.array([True, False, True, False, True]),
                   "nested": {"tuple": (1, 2.5, "3"), "nan": math.nan, "inf": -math.inf, "none": None, "empty": [],
                              "$weird": 1, 7: "int key"},
                   "table": pd.DataFrame({"a": [1.0, 2.0]}, index=pd.Index(["x", "y"], name="row")),
                   "series": pd.Series([1, 2, 3], name="s"), "path": Path("/tmp/x"), "text": "1e3", "int": 3,
                   "flt": 0.1 + 0.2, "i8": np.int8(-3), "b": np.bool_(True), "matrix": np.eye(3)[None],
                   "words": np.array(["a", "bc"])}
    recording = {"name": "1e3", "place": "Gång 走路", "subject": "007", "rate": 100.0, "flag": True,
                 "gaps": {"start_s": [0.1, 0.2]},
                 "started": dt.datetime(2026, 1, 2, 3, 4, 5, 6, tzinfo=dt.timezone(dt.timedelta(hours=1))),
                 "day": dt.date(2026, 1, 2), "clock": dt.time(23, 59, 1), "raw": b"\xff\x00id",
                 "stamp": np.datetime64("2026-01-02T03:04:05.123456789"),
                 "lasted": dt.timedelta(days=1, seconds=3, microseconds=7), "lag": np.timedelta64(-250, "ms")}
    ref = footzoo.Truth(pos=np.arange(15.0).reshape(n, 3), stance=np.array([1, 0, 1, 1, 0], dtype=bool),
                        steps=steps[["start_s", "turn"]], closed_loop=True, stride_count=3,
                        footprints=np.ones((2, 2)), source="hand-made")
    return Result(samples=samples, steps=steps, config={"name": "x", "gravity": 9.81, "list": [1, [2, "3"]]},
                  versions={"footzoo": "0.3.0"}, recording=recording, diagnostics=diagnostics, reference=ref)


def assert_same_value(a, b, where="value"):
    if isinstance(a, pd.DataFrame):
        pd.testing.assert_frame_equal(a, b, check_exact=True, obj=where)
    elif isinstance(a, pd.Series):
        pd.testing.assert_series_equal(a, b, check_exact=True, obj=where)
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, where
        np.testing.assert_array_equal(a, b, err_msg=where)
    elif isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), (where, list(a), list(b))
        for k in a:
            assert_same_value(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, (list, tuple)):
        assert type(a) is type(b) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same_value(x, y, f"{where}[{i}]")
    elif isinstance(a, float) and math.isnan(a):
        assert isinstance(b, float) and math.isnan(b), where
    else:
        assert a == b and type(a) is type(b) or (isinstance(a, np.generic) and a.item() == b), (where, a, b)


def assert_same_result(a: Result, b: Result) -> None:
    pd.testing.assert_frame_equal(a.samples, b.samples, check_exact=True)
    pd.testing.assert_frame_equal(a.steps, b.steps, check_exact=True)
    for name in ("config", "versions", "recording", "diagnostics"):
        assert_same_value(getattr(a, name), getattr(b, name), name)
    for name in ("pos", "vel", "quat", "stance", "dist", "footprints", "steps", "stride_positions", "closed_loop",
                 "stride_count", "source"):
        x, y = getattr(a.reference, name), getattr(b.reference, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert_same_value(x, y, f"reference.{name}")


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_pipeline_result_comes_back_equal(result, tmp_path, backend):
    back = Result.load(result.save(tmp_path / "run", backend=backend))
    assert_same_result(result, back)
    assert json.dumps(back.metrics, sort_keys=True) == json.dumps(result.metrics, sort_keys=True)


@pytest.mark.parametrize("backend", BACKENDS)
def test_every_dtype_nan_boolean_and_number_like_text_survive(tmp_path, backend):
    res = tricky()
    with pytest.warns(footzoo.FootzooWarning, match="metrics could not be computed"):  # no positions in samples
        folder = res.save(tmp_path / "r", backend=backend)
    back = Result.load(folder)
    pd.testing.assert_frame_equal(back.samples, res.samples, check_exact=True)
    pd.testing.assert_frame_equal(back.steps, res.steps, check_exact=True)
    label = list(back.steps["label"])
    assert label[:2] == ["1e3", ""] and pd.isna(label[2])  # text stays text; empty and missing differ
    assert back.steps["label"].dtype == res.steps["label"].dtype
    assert back.steps["code"][2] == "ünïcode, \"quoted\"\n"
    assert back.recording["name"] == "1e3" and back.recording["subject"] == "007"
    assert_same_value(res.recording, back.recording, "recording")  # dates, times and bytes too, not dropped
    d = back.diagnostics
    assert d["nested"]["tuple"] == (1, 2.5, "3") and math.isnan(d["nested"]["nan"]) and d["nested"]["inf"] == -math.inf
    assert d["nested"]["$weird"] == 1 and d["nested"][7] == "int key" and d["nested"]["none"] is None
    pd.testing.assert_frame_equal(d["table"], res.diagnostics["table"], check_exact=True)
    pd.testing.assert_series_equal(d["series"], res.diagnostics["series"], check_exact=True)
    assert d["path"] == Path("/tmp/x") and d["text"] == "1e3" and d["flt"] == 0.1 + 0.2
    np.testing.assert_array_equal(d["words"], res.diagnostics["words"])
    assert_same_value(res.diagnostics["matrix"], d["matrix"])
    assert_same_result(Result(res.samples, res.steps, res.config, res.versions, res.recording,
                              {k: v for k, v in res.diagnostics.items() if k not in ("i8", "b")}, res.reference),
                       Result(back.samples, back.steps, back.config, back.versions, back.recording,
                              {k: v for k, v in d.items() if k not in ("i8", "b")}, back.reference))
    assert d["i8"] == -3 and d["b"] is True  # numpy scalars come back as Python numbers


def test_the_archive_describes_itself(result, tmp_path):
    folder = result.save(tmp_path / "run", backend="csv")
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["format"] == "footzoo-result" and manifest["format_version"] == archive.FORMAT_VERSION
    assert manifest["footzoo_version"] == footzoo.__version__ and manifest["backend"] == "csv"
    assert set(manifest["files"]) | {"manifest.json"} == {p.name for p in folder.iterdir()}
    assert all(info["holds"] for info in manifest["files"].values())
    samples = manifest["files"]["samples.csv"]
    assert samples["rows"] == len(result.samples) and samples["columns"]["stance"]["dtype"] == "bool"
    metrics = json.loads((folder / "metrics.json").read_text(), parse_constant=lambda c: pytest.fail(f"bare {c}"))
    assert set(metrics) == {"metrics", "metric_notes", "config", "versions", "recording"}
    assert "samples.csv: per-sample estimates" in archive.describe(folder)


def test_saving_again_replaces_the_earlier_result_and_removes_its_stale_files(result, tmp_path):
    folder = result.save(tmp_path / "run", backend="csv")
    (folder / "notes.txt").write_text("mine")
    if archive.parquet_available():
        result.save(folder, backend="parquet")
        names = {p.name for p in folder.iterdir()}
        assert "samples.parquet" in names and "samples.csv" not in names and "notes.txt" in names
    assert_same_result(result, Result.load(folder))


def test_a_file_footzoo_did_not_write_is_never_replaced(result, tmp_path):
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "samples.csv").write_text("the user's own table")
    with pytest.raises(OutputError, match=r"already holds samples.csv, which no earlier footzoo result"):
        result.save(folder, backend="csv")
    assert (folder / "samples.csv").read_text() == "the user's own table"
    assert sorted(p.name for p in folder.iterdir()) == ["samples.csv"]


def test_an_input_is_never_replaced(tmp_path):
    rec = simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=5))
    data = write(rec, tmp_path / "samples.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = Pipeline.from_yaml("yun2012").run(load(data))
    before = data.read_bytes()
    with pytest.raises(OutputError, match="would overwrite the input"):
        res.save(tmp_path, backend="csv")
    assert data.read_bytes() == before and not list(tmp_path.glob(f"*{TMP_INFIX}*"))


def test_a_failure_while_saving_keeps_the_earlier_result(result, tmp_path, monkeypatch):
    folder = result.save(tmp_path / "run", backend="csv")
    before = {p.name: p.read_bytes() for p in folder.iterdir()}

    def broken(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(archive.np, "savez", broken)
    with pytest.raises(KeyboardInterrupt):
        result.save(folder, backend="csv")
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    with pytest.raises(KeyboardInterrupt):
        result.save(tmp_path / "new", backend="csv")
    assert not (tmp_path / "new").exists()  # a folder this save created goes with it


@pytest.mark.parametrize("make, fragment", [
    (lambda d: d / "none", "is not a folder"),
    (lambda d: "", "give the path of the folder Result.save wrote"),
    (lambda d: d, "holds no manifest.json"),
    (lambda d: (d / "manifest.json").write_text('{"format": "footzoo-session-result"}') and d,
     "use SessionResult.load"),
    (lambda d: (d / "manifest.json").write_text('{"format": "footzoo-result", "format_version": 99}') and d,
     "newer than this footzoo reads"),
    (lambda d: (d / "manifest.json").write_text('{"format": "footzoo-result", "format_version": 1, '
                                                '"files": {"samples.csv": {}}}') and d, "it is incomplete"),
    (lambda d: (d / "manifest.json").write_text("{not json") and d, "damaged"),
])
def test_what_is_not_a_result_is_refused_clearly(tmp_path, make, fragment):
    with pytest.raises(FormatError, match=fragment):
        Result.load(make(tmp_path))


def test_a_session_comes_back_equal(tmp_path):
    recs = {foot: simulate(n_strides=4, rate=100.0, foot=foot, noise=NoiseModel(seed=i))
            for i, foot in enumerate(("left", "right"))}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = Session(recs, name="walk 1e3").run(Pipeline.from_yaml("yun2012"))
    folder = res.save(tmp_path / "session", backend="csv")
    back = SessionResult.load(folder)
    assert back.name == "walk 1e3" and list(back.results) == ["left", "right"]
    for foot in res.results:
        assert_same_result(res.results[foot], back.results[foot])
    pd.testing.assert_frame_equal(back.steps, res.steps, check_exact=True)
    pd.testing.assert_frame_equal(back.bilateral, res.bilateral, check_exact=True)
    assert {"left", "right", "steps.csv", "bilateral.csv", "manifest.json"} <= {p.name for p in folder.iterdir()}
    with pytest.raises(FormatError, match="use Result.load for each foot"):
        SessionResult.load(folder / "left")


def _edit_csv(path: Path) -> None:
    """Change one number of a CSV table, as a hand edit in a spreadsheet would."""
    table = pd.read_csv(path)
    table.iloc[0, 0] = table.iloc[0, 0] + 1.0
    table.to_csv(path, index=False)


@pytest.mark.parametrize("name", ["steps.csv", "samples.csv", "result.json"])
def test_a_file_edited_after_the_save_is_named_when_loaded(result, tmp_path, name):
    folder = result.save(tmp_path / "run", backend="csv")
    manifest = json.loads((folder / "manifest.json").read_text())
    assert all(len(info["sha256"]) == 64 for info in manifest["files"].values())
    path = folder / name
    if name.endswith(".csv"):
        _edit_csv(path)
    else:
        path.write_text(path.read_text().replace('"steps_notes"', ' "steps_notes"'))
    with pytest.warns(footzoo.FootzooWarning, match=rf"Result.load: '.*{name}' changed after the result was saved.*"
                                                    r"Result.load\(path, verify=False\)"):
        back = Result.load(folder)
    assert len(back.steps) == len(result.steps)  # loaded as it is now
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Result.load(folder, verify=False)


def test_an_archive_saved_without_hashes_loads_as_before_and_a_truncated_table_is_still_refused(result, tmp_path):
    folder = result.save(tmp_path / "run", backend="csv")
    manifest = json.loads((folder / "manifest.json").read_text())
    for info in manifest["files"].values():
        del info["sha256"]
    (folder / "manifest.json").write_text(json.dumps(manifest))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert_same_result(result, Result.load(folder))
    folder = result.save(tmp_path / "again", backend="csv")
    text = (folder / "samples.csv").read_bytes()
    (folder / "samples.csv").write_bytes(text[: len(text) // 2])  # read as fewer rows: named now, silent before
    with pytest.warns(footzoo.FootzooWarning, match="samples.csv' changed after the result was saved"):
        assert len(Result.load(folder).samples) < len(result.samples)
    (folder / "manifest.json").rename(folder / INCOMPLETE)  # a save cut before its manifest: refused as before
    with pytest.raises(FormatError, match="incomplete"):
        Result.load(folder)


@pytest.mark.parametrize("path", ["-", Path("-"), " - "])
def test_dash_is_refused_as_text_and_as_a_path(result, tmp_path, monkeypatch, path):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError, match=r"'-' means standard output.*Path.cwd\(\) / '-'"):
        result.save(path)
    assert not any(tmp_path.iterdir())
    assert result.save(Path.cwd() / "-").name == "-"


@pytest.mark.parametrize("edit", ["short", "not hex", "number", "missing"])
def test_a_malformed_or_missing_hash_in_a_hashed_manifest_is_named(result, tmp_path, edit):
    folder = result.save(tmp_path / "run", backend="csv")
    manifest = json.loads((folder / "manifest.json").read_text())
    info = manifest["files"]["samples.csv"]
    if edit == "missing":
        del info["sha256"]
    else:
        info["sha256"] = {"short": info["sha256"][:40], "not hex": "z" * 64, "number": 12345}[edit]
    (folder / "manifest.json").write_text(json.dumps(manifest))
    with pytest.warns(footzoo.FootzooWarning, match=r"records no well-formed SHA-256 .* for '.*samples.csv'.*"
                                                    r"verify=False"):
        Result.load(folder)


@pytest.mark.parametrize("files", [["samples.csv"], None, {"samples.csv": "table"}])
def test_a_manifest_whose_files_are_not_a_mapping_is_a_format_error(result, tmp_path, files):
    folder = result.save(tmp_path / "run", backend="csv")
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["files"] = files
    (folder / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(FormatError, match=r"manifest.json: its 'files' entry is not a mapping.*save the result again"):
        Result.load(folder)


def test_a_load_while_another_save_commits_reads_one_result(result, tmp_path, monkeypatch):
    """The folder changes under the reader once (another process's save committing): read again, no mix, no
    warning; a folder that keeps changing is a FormatError saying so."""
    folder = result.save(tmp_path / "run", backend="csv")
    real = archive._result_fields
    calls = []

    def racing(where, files):
        calls.append(1)
        if len(calls) == 1:  # a save commits while this read is under way: new tables, then the new manifest
            (where / "manifest.json").write_bytes((where / "manifest.json").read_bytes())
            _edit_csv(where / "samples.csv")
            manifest = json.loads((where / "manifest.json").read_text())
            manifest["files"]["samples.csv"]["sha256"] = archive.sha256(where / "samples.csv")
            (where / "manifest.json").unlink()
            (where / "manifest.json").write_text(json.dumps(manifest))
        return real(where, files)

    monkeypatch.setattr(archive, "_result_fields", racing)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = Result.load(folder)
    assert len(calls) == 2 and back.samples.iloc[0, 0] == pd.read_csv(folder / "samples.csv").iloc[0, 0]
    monkeypatch.setattr(archive, "_stamp", lambda where: (object(), False))  # changes at every look
    monkeypatch.setattr(archive, "_result_fields", real)
    monkeypatch.setattr(archive.time, "sleep", lambda s: None)
    with pytest.raises(FormatError, match=r"another process saved into the folder while it was read"):
        Result.load(folder)


@pytest.mark.parametrize("name", ["x" * 300, "/".join(["d" * 200] * 25)])
def test_a_folder_name_the_file_system_refuses_is_an_output_error(result, tmp_path, monkeypatch, name):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError, match=r"cannot be used as a folder \(File name too long\); choose a shorter"):
        result.save(name)


def test_save_names_an_argument_of_the_wrong_kind(result, tmp_path):
    with pytest.raises(OutputError, match=r"Result.save: the folder is a path \(text or pathlib.Path\), got int 123"):
        result.save(123)
    with pytest.raises(OutputError, match=r"files= maps file names \(text\) to their content \(bytes\), got "
                                          r"'fig.png': str"):
        result.save(tmp_path / "r", files={"fig.png": "not bytes"})
    assert not (tmp_path / "r").exists()  # refused before anything is written


@pytest.mark.parametrize("version", [0, True, "1", None])
def test_a_manifest_with_a_format_version_footzoo_never_wrote_is_refused(result, tmp_path, version):
    import json
    import re

    folder = result.save(tmp_path / "r")
    manifest = folder / "manifest.json"
    data = json.loads(manifest.read_text())
    data["format_version"] = version
    manifest.write_text(json.dumps(data))
    with pytest.raises(FormatError, match=rf"format version {re.escape(repr(version))} is not one footzoo writes"):
        type(result).load(folder)
