"""Recording files that mislead: unusual encodings and padding, links, datasets' own sidecars, multi-device exports,
sidecars with foreign columns, metadata that cannot be written.

Each is named (the file, the problem, the fix) or read right, never read as something it is not. Table-driven
like ``test_bad_input.py``: each case writes its files into a temporary folder and returns the action.
"""

from __future__ import annotations

import codecs
import io
import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy.io as sio
from hypothesis import given, settings
from hypothesis import strategies as st

from footzoo import ConfigError, FormatError, Pipeline, RecordingError
from footzoo.core.data import Recording
from footzoo.core.errors import FootzooWarning, OutputError
from footzoo.core.files import foreign_encoding, why_missing
from footzoo.core.yamlsafe import dump_text, load_text
from footzoo.io import load
from footzoo.io.canonical import write
from footzoo.io.metadata import plain_meta
from footzoo.sim import NoiseModel, simulate

ROOT = Path(__file__).resolve().parents[2]
KOROGLU = ROOT.parent / "shared" / "data" / "koroglu_gcp" / "SensorConnectData_31.csv"


@pytest.fixture(scope="module")
def walk() -> Recording:
    return simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))


@pytest.fixture(scope="module")
def text(walk, tmp_path_factory) -> bytes:
    return write(walk, tmp_path_factory.mktemp("w") / "w.csv").read_bytes()


def _file(d: Path, name: str, data: bytes) -> Path:
    p = d / name
    p.write_bytes(data)
    return p


def _link_loop(d: Path) -> Path:
    (d / "a.csv").symlink_to("b.csv")
    (d / "b.csv").symlink_to("a.csv")
    return d / "a.csv"


def _dangling(d: Path) -> Path:
    (d / "gone.csv").symlink_to(d / "nowhere" / "walk.csv")
    return d / "gone.csv"


def _steps_sidecar(d: Path, walk: Recording, table: str) -> Path:
    p = write(Recording(t=walk.t, acc=walk.acc, gyr=walk.gyr, meta={"name": "w"}), d / "w.csv")
    p.with_name("w.csv.meta.yaml").unlink()  # a hand-made steps sidecar, no hashes to vouch for it
    (d / "w.csv.steps.csv").write_text(table)
    return p


def _yaml_loop(d: Path) -> Path:
    (d / "c.yaml").symlink_to("c.yaml")
    return d / "c.yaml"


def _folder_sidecar(d: Path) -> Path:
    (d / "s.csv.meta.yaml").mkdir()
    return d / "s.csv"


def _trials(d: Path, walk: Recording, table: str | bytes) -> Path:
    p = d / "2017-11-22-11-22-03.mat"
    sio.savemat(p, {"imu": np.hstack([walk.acc, walk.gyr]), "ts": walk.t[None, :]})
    (d / "trials.csv").write_bytes(table if isinstance(table, bytes) else table.encode())
    return p


def _pyshoe(d: Path, walk: Recording, **variables) -> Path:
    p = d / "trial.mat"
    sio.savemat(p, {"imu": np.hstack([walk.acc, walk.gyr]), "ts": walk.t[None, :], "gt": walk.truth.pos * [1, 1, -1],
                    **variables})
    return p


def _sensorconnect(d: Path, walk: Recording, devices: list[str], gcp: dict | None = None) -> Path:
    cols = {"Time": walk.t}
    for dev in devices:
        for j, axis in enumerate("XYZ"):
            cols[f"{dev}:scaledAccel{axis}"] = walk.acc[:, j] / 9.80665
            cols[f"{dev}:scaledGyro{axis}"] = walk.gyr[:, j]
    p = d / "SensorConnectData_99.csv"
    pd.DataFrame(cols).to_csv(p, index=False)
    if gcp is not None:
        sio.savemat(p.with_suffix(".mat"), gcp)
    return p


@dataclass
class Case:
    id: str
    make: Callable[[Path, Recording, bytes], Callable[[], object]]
    error: type[Exception]
    match: str


def _table(text: bytes) -> pd.DataFrame:
    return pd.read_csv(io.BytesIO(text))


def _put(df: pd.DataFrame, row: int, column: str, value: object) -> pd.DataFrame:
    df.loc[row, column] = value
    return df


def _lines(text: bytes, at: int, line: bytes | None) -> bytes:
    """``text`` with ``line`` inserted before its line ``at`` (0: the header)."""
    lines = text.split(b"\n")
    return b"\n".join(lines[:at] + ([line] if line is not None else []) + lines[at:])


TRIALS_HEAD = "trial,n_strides_manual_koroglu,bipedal_tag_koroglu\n"
CASES = [
    # encodings and padding
    Case("utf-16", lambda d, w, x: (lambda: load(_file(d, "r.csv", x.decode().encode("utf-16")))), FormatError,
         "r.csv: is UTF-16 text; footzoo reads UTF-8: convert it (iconv -f UTF-16 -t UTF-8"),
    Case("utf-16-no-bom", lambda d, w, x: (lambda: load(_file(d, "r.csv", x.decode().encode("utf-16-le")))),
         FormatError, "is UTF-16 text"),
    Case("utf-32", lambda d, w, x: (lambda: load(_file(d, "r.csv", x.decode().encode("utf-32")))), FormatError,
         "is UTF-32 text"),
    Case("utf-16-named-format", lambda d, w, x: (lambda: load(_file(d, "r.csv", x.decode().encode("utf-16")),
                                                              format="canonical")), FormatError, "is UTF-16 text"),
    Case("nul-start", lambda d, w, x: (lambda: load(_file(d, "r.csv", b"\0" * 512 + x))), FormatError,
         "starts with 512 NUL byte(s) (0x00), not text: the file was damaged while it was written"),
    Case("nul-run-inside", lambda d, w, x: (lambda: load(_file(d, "r.csv", x[:20000] + b"\0" * 300 + x[20000:]))),
         FormatError, "a run of 300 NUL bytes (0x00) at byte 20000 (line"),
    Case("config-utf-16", lambda d, w, x: (lambda: Pipeline.from_yaml(_file(
        d, "c.yaml", (ROOT / "configs" / "yun2012.yaml").read_text().encode("utf-16")))), ConfigError,
        "c.yaml: is UTF-16 text"),
    Case("config-nul-run", lambda d, w, x: (lambda: Pipeline.from_yaml(_file(
        d, "c.yaml", b"name: x\n\0\0\0\0" + (ROOT / "configs" / "yun2012.yaml").read_bytes()))), ConfigError,
        "a run of 4 NUL bytes (0x00) at byte 8 (line 2)"),
    # links
    Case("link-loop", lambda d, w, x: (lambda: load(_link_loop(d))), FormatError,
         "a.csv -> b.csv -> a.csv): it leads back to itself; point it at a real file"),
    Case("link-dangling", lambda d, w, x: (lambda: load(_dangling(d))), FormatError,
         "which does not exist (a dangling link); point it at a real file"),
    Case("config-link-loop", lambda d, w, x: (lambda: Pipeline.from_yaml(_yaml_loop(d))), ConfigError,
         "c.yaml' is a symbolic link in a loop"),
    # a steps sidecar that is not a stride table
    Case("steps-foreign-columns", lambda d, w, x: (lambda: load(_steps_sidecar(d, w, "foo,bar\n1,2\n3,4\n"))),
         FormatError, "w.csv.steps.csv: not a stride table: its columns ['foo', 'bar'] hold no stride times"),
    Case("steps-in-samples", lambda d, w, x: (lambda: load(_steps_sidecar(d, w, "start,end\n200,260\n300,360\n"))),
         FormatError, "column 'start' runs from 200 to 300, but the recording spans 0 to"),
    Case("steps-repeated-column", lambda d, w, x: (lambda: load(_steps_sidecar(
        d, w, "start_s,end_s,end_s\n1.0,2.0,2.5\n3.0,4.0,4.5\n"))), FormatError,
        "w.csv.steps.csv: column(s) ['end_s'] appear more than once; which one holds the reference is unclear"),
    Case("steps-text-times", lambda d, w, x: (lambda: load(_steps_sidecar(d, w, "start_s,end_s\n1.0,2.0\nlate,3\n"))),
         FormatError, "column 'start_s' holds text ('late'), not times in s"),
    # PyShoe's trials.csv and its variables
    Case("trials-no-trial-column", lambda d, w, x: (lambda: load(_trials(d, w, "name,n\n1,2\n"))), FormatError,
         "trials.csv: lacks the column(s) ['trial', 'n_strides_manual_koroglu', 'bipedal_tag_koroglu']"),
    Case("trials-count-text", lambda d, w, x: (lambda: load(_trials(
        d, w, TRIALS_HEAD + "2017-11-22-11-22-03,many,1\n"))), FormatError,
        "n_strides_manual_koroglu of trial '2017-11-22-11-22-03' is 'many', not a whole number"),
    Case("trials-listed-twice", lambda d, w, x: (lambda: load(_trials(
        d, w, TRIALS_HEAD + "2017-11-22-11-22-03,20,1\n2017-11-22-11-22-03,21,1\n"))), FormatError,
        "lists the trial '2017-11-22-11-22-03' 2 times"),
    Case("trials-latin1", lambda d, w, x: (lambda: load(_trials(d, w, b"trial,n\n\xe9\xff,1\n"))), FormatError,
         "trials.csv: cannot be read as a table"),
    Case("pyshoe-trial-error-short", lambda d, w, x: (lambda: load(_pyshoe(d, w, trial_error=np.ones(3)))),
         FormatError, "'trial_error' holds 3 value(s), expected 5"),
    Case("pyshoe-stance-wrong-length", lambda d, w, x: (lambda: load(_pyshoe(d, w, zv_vicon_opt=np.ones(7)))),
         FormatError, "'zv_vicon_opt' must hold 0 or 1 for each of the"),
    Case("pyshoe-gt-text", lambda d, w, x: (lambda: load(_pyshoe(d, w, gt="VICON"))), FormatError,
         "'gt' must hold numbers (the VICON position, N x 3 in m)"),
    Case("pyshoe-gt-short", lambda d, w, x: (lambda: load(_pyshoe(d, w, gt=w.truth.pos[:10]))), FormatError,
         "'gt' (the VICON position) has shape (10, 3), expected"),
    # Köroğlu's ground control points
    Case("koroglu-count-text", lambda d, w, x: (lambda: load(_sensorconnect(
        d, w, ["dev-1"], {"GCP_meters": np.zeros((3, 2)), "numberOfStrides": "twelve"}))), FormatError,
        "numberOfStrides must be"),
    Case("koroglu-gcp-shape", lambda d, w, x: (lambda: load(_sensorconnect(
        d, w, ["dev-1"], {"GCP_meters": np.zeros((3, 3)), "numberOfStrides": 3}))), FormatError,
        "GCP_meters has shape (3, 3); it must be K x 2 finite footprint positions (m)"),
    Case("koroglu-flag-empty", lambda d, w, x: (lambda: load(_sensorconnect(
        d, w, ["dev-1"], {"GCP_meters": np.zeros((3, 2)), "GCP_exist_and_correct": np.zeros((0, 0))}))),
        FormatError, "GCP_exist_and_correct must be one finite number, got 0 value(s)"),
    # several devices in one export
    Case("sensorconnect-two-devices", lambda d, w, x: (lambda: load(_sensorconnect(d, w, ["dev-1", "dev-2"]))),
         FormatError, "a multi-device export (2 devices: dev-1, dev-2); footzoo reads one sensor at a time: choose "
                      "one with device= (command line: --option device=dev-1)"),
    Case("sensorconnect-unknown-device", lambda d, w, x: (lambda: load(_sensorconnect(d, w, ["dev-1", "dev-2"]),
                                                                       device="dev-3")), FormatError,
         "no device 'dev-3' in this export; its devices are ['dev-1', 'dev-2']"),
    # the reference's columns
    Case("truth-column-missing", lambda d, w, x: (lambda: load(_file(d, "r.csv", pd.read_csv(
        io.BytesIO(x)).drop(columns="true_pos_e").to_csv(index=False).encode()))), RecordingError,
        "reference columns incomplete: found ['true_pos_n', 'true_pos_d'], need all of"),
    Case("truth-quaternion-zero", lambda d, w, x: (lambda: load(_file(d, "r.csv", _table(x).assign(
        true_qw=0.0, true_qx=0.0, true_qy=0.0, true_qz=0.0).to_csv(index=False).encode()))), RecordingError,
        "row 0 holds [0.0, 0.0, 0.0, 0.0], of length 0, not a unit quaternion"),
    # text where numbers belong, another encoding, another delimiter: each named where it is
    Case("header-repeated-inside", lambda d, w, x: (lambda: load(_file(d, "r.csv", _lines(x, 40, x.split(b"\n")[0])))),
         RecordingError, "r.csv: row 39 repeats the header line (two files joined into one?)"),
    Case("text-in-a-number-column", lambda d, w, x: (lambda: load(_file(d, "r.csv", _table(x).astype({"gyr_y": object})
                                                                        .pipe(_put, 25, "gyr_y", "ERR")
                                                                        .to_csv(index=False).encode()))),
         RecordingError, "column 'gyr_y' holds the text 'ERR' at row 25 (t = 0.250000 s), not a number"),
    Case("latin1-column-name", lambda d, w, x: (lambda: load(_file(d, "r.csv", _lines(x, 1, None).replace(
        b"\n", b",temp \xb0C\n", 1)))), FormatError,
        "r.csv: not UTF-8 text (byte 0xb0 at offset"),
    Case("latin1-deep-in-the-file", lambda d, w, x: (lambda: load(_file(d, "r.csv", x[:99999] + b"\xe9" + x[99999:]))),
         FormatError, "r.csv: not UTF-8 text (byte 0xe9 at offset 99999, line"),
    Case("space-separated", lambda d, w, x: (lambda: load(_file(d, "r.csv", _table(x).to_csv(
        index=False, sep=" ").encode()))), FormatError, "its values are separated by spaces, not commas"),
    Case("title-line-above-the-header", lambda d, w, x: (lambda: load(_file(d, "r.csv", b"# left foot sensor\n" + x))),
         FormatError, "a line without commas comes before what looks like its header ('t,acc_x,"),
    Case("title-line-above-a-tab-header", lambda d, w, x: (lambda: load(_file(d, "r.txt", b"Acquisition frequency: 100 "
                                                                       b"Hz\n" + x.replace(b",", b"\t")))),
         FormatError, "a line without tabs comes before what looks like its header ('t\\tacc_x"),
    # a sidecar that cannot be written
    Case("sidecar-is-a-folder", lambda d, w, x: (lambda: write(w, _folder_sidecar(d))), OutputError,
         "its sidecar s.csv.meta.yaml (its metadata, written next to it) cannot be written: s.csv.meta.yaml is a "
         "folder"),
]


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_a_misleading_file_is_named_with_the_fix(case, tmp_path, walk, text):
    action = case.make(tmp_path, walk, text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FootzooWarning)
        with pytest.raises(case.error) as info:
            action()
    assert case.match in str(info.value)


def test_case_ids_are_unique():
    assert len({c.id for c in CASES}) == len(CASES)


def test_a_utf8_bom_and_nul_padding_after_the_last_line_read_right(tmp_path, walk, text):
    ref = load(_file(tmp_path, "plain.csv", text))
    np.testing.assert_array_equal(load(_file(tmp_path, "bom.csv", codecs.BOM_UTF8 + text)).acc, ref.acc)
    with pytest.warns(FootzooWarning, match=r"ends with 4096 NUL bytes \(0x00\) after its last line .* ignored"):
        padded = load(_file(tmp_path, "padded.csv", text + b"\0" * 4096))
    np.testing.assert_array_equal(padded.acc, ref.acc)
    np.testing.assert_array_equal(padded.t, ref.t)


def test_one_device_of_a_multi_device_export_is_read_as_asked(tmp_path, walk):
    p = _sensorconnect(tmp_path, walk, ["dev-1", "dev-2"])
    df = pd.read_csv(p)
    df[[c for c in df.columns if c.startswith("dev-2")]] *= -1.0  # the second sensor differs
    df.to_csv(p, index=False)
    one, two = load(p, device="dev-1"), load(p, device="dev-2")
    np.testing.assert_allclose(one.gyr, walk.gyr, rtol=1e-12)
    np.testing.assert_allclose(two.gyr, -walk.gyr, rtol=1e-12)
    assert two.meta["device"] == "dev-2"


def test_a_gaitmap_file_with_a_sensor_besides_the_feet_says_it_is_not_read(tmp_path, walk):
    cols = ["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"]
    sensors = ["left_sensor", "right_sensor", "hip_sensor"]
    rows = ["sensor," + ",".join(s for s in sensors for _ in cols), "axis," + ",".join(cols * len(sensors))]
    values = np.hstack([walk.acc, np.degrees(walk.gyr)])
    rows += [f"{k}," + ",".join(repr(float(v)) for v in np.tile(values[k], len(sensors))) for k in range(walk.n)]
    p = tmp_path / "imu_sample.csv"
    p.write_text("\n".join(rows) + "\n")
    with pytest.warns(FootzooWarning, match=r"sensor\(s\) \['hip_sensor'\] are not read: footzoo reads the feet"):
        rec = load(p, foot="left")
    assert rec.n == walk.n


def test_a_gaitmap_file_of_one_foot_is_read_as_that_foot(tmp_path, walk):
    """Before: 'a gaitmap file holds both feet; choose one with foot=...' for a file that holds the left foot only."""
    from ..io.texts import gaitmap_text

    p = tmp_path / "left_only.csv"
    p.write_text(gaitmap_text(walk))
    rec = load(p)
    np.testing.assert_allclose(rec.gyr, walk.gyr, atol=1e-12)
    with pytest.raises(FormatError, match=r"no 'right_sensor' columns; found \['left_sensor'\]"):
        load(p, foot="right")


@pytest.mark.skipif(not KOROGLU.exists(), reason="the real recordings (../shared/data) are not here")
def test_the_real_sensorconnect_export_reads_as_before(tmp_path):
    rec = load(KOROGLU)
    assert "device" not in rec.meta and rec.truth.stride_count is not None


def test_unread_columns_of_a_canonical_file_are_named(tmp_path, text):
    df = pd.read_csv(io.BytesIO(text))
    df["temperature"] = 20.0
    df["true_speed"] = 1.0
    p = tmp_path / "extra.csv"
    df.to_csv(p, index=False)
    with pytest.warns(FootzooWarning, match=r"column\(s\) 'temperature', 'true_speed' .* are not read: the canonical"):
        rec = load(p)
    assert rec.truth.pos is not None


def test_non_scalar_metadata_is_written_and_what_cannot_be_is_named(tmp_path, walk):
    import datetime

    rec = Recording(t=walk.t, acc=walk.acc, gyr=walk.gyr, meta={
        "name": "m", "subject": {"age": 30, "height_m": 1.8}, "tags": ["a", "b"], "arr": np.arange(3.0),
        "when": datetime.date(2024, 1, 2), "pair": (1, 2), "f32": np.float32(1.5), "obj": object()})
    with pytest.warns(FootzooWarning, match=r"metadata obj \(object\) not written to m.csv.meta.yaml"):
        back = load(write(rec, tmp_path / "m.csv"))
    assert back.meta["subject"] == {"age": 30, "height_m": 1.8} and back.meta["tags"] == ["a", "b"]
    assert back.meta["arr"] == [0.0, 1.0, 2.0] and back.meta["when"] == "2024-01-02"
    assert back.meta["pair"] == [1, 2] and back.meta["f32"] == 1.5 and "obj" not in back.meta
    loop: dict = {"depth": 1}
    loop["me"] = loop  # a mapping that holds itself: named, not a RecursionError
    rec.meta = {"name": "m", "loop": loop}
    with pytest.warns(FootzooWarning, match=r"metadata loop \(dict\) not written .* a mapping that holds itself"):
        assert "loop" not in load(write(rec, tmp_path / "m.csv")).meta


def test_a_results_metrics_json_keeps_nested_metadata():
    """metrics.json (a run's summary for other tools) holds the recording's metadata as plain JSON, nested too."""
    from types import SimpleNamespace

    from footzoo.core.archive import _metrics_payload

    result = SimpleNamespace(checked_metrics=lambda: ({"strides": 3.0}, {}), config={}, versions={}, recording={
        "name": "m", "subject": {"age": 30}, "tags": ["a"], "arr": np.arange(2.0), "t0": float("nan")})
    assert _metrics_payload(result)["recording"] == {"name": "m", "subject": {"age": 30}, "tags": ["a"],
                                                     "arr": [0.0, 1.0], "t0": None}


def test_why_a_named_path_is_missing():
    assert why_missing("/no/such/file.csv") == "does not exist"


@pytest.mark.skipif(os.name == "nt", reason="symbolic links need privileges on Windows")
def test_why_a_link_is_missing(tmp_path):
    (tmp_path / "x").symlink_to("x")
    assert "in a loop (" in why_missing(tmp_path / "x")


PLAIN = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-10**9, 10**9), st.floats(allow_nan=False), st.text(max_size=8)),
    lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(min_size=1, max_size=5), c, max_size=3), max_leaves=8)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.dictionaries(st.text(alphabet="abcdef_", min_size=1, max_size=6), st.one_of(
    PLAIN, st.tuples(st.integers(), st.text(max_size=3)), st.builds(object),
    st.lists(st.floats(-1e3, 1e3), max_size=5).map(np.array)), max_size=5))
def test_property_metadata_is_kept_as_plain_yaml_or_named(meta):
    kept, dropped = plain_meta(meta)
    assert set(kept) | {d.split(" (")[0] for d in dropped} == set(meta)
    assert load_text(dump_text(kept), "meta") == kept  # what is kept reads back equal


@settings(max_examples=80, deadline=None, derandomize=True)
@given(st.text(alphabet="t,acc_xyzgr0123456789.-e\n é;\t", min_size=1, max_size=40),
       st.sampled_from(["utf-8", "utf-8-sig", "utf-16", "utf-16-le", "utf-32"]), st.integers(0, 3))
def test_property_foreign_encodings_are_named_and_utf8_is_not(text, encoding, nuls):
    """A table's text: UTF-8 (with or without its mark) passes, UTF-16 and UTF-32 are named, a start of NULs too."""
    data = b"\0" * (nuls * 4) + text.encode(encoding)
    problem = foreign_encoding(data)
    if nuls:
        assert problem is not None and ("NUL" in problem or "UTF" in problem)
    elif encoding.startswith("utf-8"):
        assert problem is None
    elif encoding in ("utf-16", "utf-32"):
        assert problem is not None and encoding.upper() in problem
