"""Bad input: every case gives a footzoo error naming the problem (or a warning), never a crash or a wrong result.

Table-driven: each case builds its input in a temporary folder and returns a
callable; the test asserts the exception type and a fragment of the message.
The cases are grouped by class (readers, YAML, parameters, calibration files,
studies, stream, sensor sanity, command line).
"""

from __future__ import annotations

import contextlib
import copy
import functools
import math
import os
import subprocess
import sys
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import scipy.io as sio

from footzoo import ConfigError, FormatError, Pipeline, PluginError, RecordingError
from footzoo.analysis.foot_vector import FootVector
from footzoo.apps.cli import EXIT_DATA, EXIT_INTERNAL, EXIT_USAGE, main
from footzoo.config import library, load_yaml
from footzoo.core.data import Recording, Truth
from footzoo.core.errors import FootzooWarning, SensorWarning
from footzoo.corrections.height import load_calibration
from footzoo.io import load
from footzoo.io.canonical import write
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate
from footzoo.studies.study import Study

from ..conftest import ALL_STANCE, HARD_IRON_NOT_FITTED, STANCES_GUARDED

ROOT = Path(__file__).resolve().parents[2]
YUN = (ROOT / "configs" / "yun2012.yaml").read_text()
NGUYEN = ROOT / "configs" / "nguyen2016.yaml"
YUN_PATH = ROOT / "configs" / "yun2012.yaml"
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


@pytest.fixture(scope="module")
def walk() -> Recording:
    return simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=1))


def _csv(tmp: Path, rec: Recording, name: str = "walk.csv") -> Path:
    return write(rec, tmp / name)


def _text(tmp: Path, name: str, text: str | bytes) -> Path:
    p = tmp / name
    if isinstance(text, bytes):
        p.write_bytes(text)
    else:
        p.write_text(text, encoding="utf-8")
    return p


def _config(tmp: Path, text: str | bytes, name: str = "c.yaml") -> Callable[[], object]:
    p = _text(tmp, name, text)
    return lambda: Pipeline.from_yaml(p)


def _with(base: str, **sections: str) -> str:
    """The yun2012 config text with some top-level lines replaced or added."""
    lines, dropping = [], False
    for ln in base.splitlines():
        if not ln.startswith((" ", "\t")):
            dropping = any(ln.startswith(f"{k}:") for k in sections)
        if not dropping:
            lines.append(ln)
    return "\n".join(lines + [f"{k}: {v}" for k, v in sections.items()]) + "\n"


def _bomb(levels: int = 9) -> str:
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, levels):
        refs = ", ".join([f"*a{i - 1}"] * 9)
        lines.append(f"a{i}: &a{i} [{refs}]")
    return "\n".join(lines) + "\n"


def _pyshoe(tmp: Path, walk: Recording, gt_rows: int | None = None, imu_cols: int = 6) -> Path:
    n = walk.n
    imu = np.hstack([walk.acc, walk.gyr])[:, :imu_cols]
    gt = walk.truth.pos[: gt_rows if gt_rows is not None else n] * np.array([1.0, 1.0, -1.0])
    p = tmp / "trial.mat"
    sio.savemat(p, {"imu": imu, "ts": walk.t[None, :], "gt": gt})
    return p


def _truncated(p: Path) -> Path:
    """``p`` cut to its first half (an interrupted copy)."""
    p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])
    return p


_TEXT_COLUMN = "t,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n" + "".join(
    f'{k / 100},"0,1",0,-9.8,0,0,0\n' for k in range(300))


def _truth_ends_early(tmp: Path, walk: Recording) -> Path:
    df = walk.to_dataframe()
    df.loc[df.index[-50:], ["true_pos_n", "true_pos_e", "true_pos_d"]] = np.nan  # empty cells at the end
    df.to_csv(tmp / "short.csv", index=False)
    return tmp / "short.csv"


def _stance_text(tmp: Path, walk: Recording) -> Path:
    df = walk.to_dataframe()
    df["true_stance"] = np.where(df["true_stance"] == 1, "yes", "no")
    df.to_csv(tmp / "s.csv", index=False)
    return tmp / "s.csv"


def _with_meta(tmp: Path, walk: Recording, sidecar: str | bytes) -> Callable[[], object]:
    p = _csv(tmp, walk)
    side = p.with_name(p.name + ".meta.yaml")
    side.write_bytes(sidecar if isinstance(sidecar, bytes) else sidecar.encode())
    return lambda: load(p)


def _modified(walk: Recording, **changes) -> Callable[[], object]:
    def build():
        arrays = {"t": walk.t.copy(), "acc": walk.acc.copy(), "gyr": walk.gyr.copy()}
        for key, (index, value) in changes.items():
            arrays[key][index] = value
        return Recording(**arrays, meta={"name": "modified"})
    return build


def _study(tmp: Path, text: str) -> Callable[[], object]:
    (tmp / "yun.yaml").write_text(YUN)
    p = _text(tmp, "study.yaml", text)
    return lambda: Study.from_yaml(p)


PLUGIN_FILE = '''
import numpy as np
import footzoo
from footzoo.plugins.base import Detector


@footzoo.register
class Faulty(Detector):
    """A detector with a bug (a bad-input case)."""

    name = "{name}"

    def detect(self, t, acc, gyr, ctx=None):
        {body}
'''


def _faulty_plugin(tmp: Path, walk: Recording, name: str, body: str) -> Callable[[], object]:
    """A run of a config whose detector, from a plug-in file, has ``body`` as its detect."""
    from footzoo.plugins import registry

    (tmp / f"{name}.py").write_text(PLUGIN_FILE.format(name=name, body=body))
    config = {"plugins": [str(tmp / f"{name}.py")], "orientation": {"type": "madgwick", "use_magnetometer": False},
              "detector": {"type": name}, "corrections": [{"type": "zvu_dedrift"}]}

    def run():
        try:
            return Pipeline.from_dict(config).run(walk)
        finally:  # registered for this case only: a study of every registered combination must not meet it
            registry._REGISTRY["detector"].pop(name, None)
    return run


def _push(walk: Recording, *pushes) -> Callable[[], object]:
    def run():
        s = Stream(Pipeline.from_yaml(NGUYEN))
        for args in pushes:
            s.push(*args)
    return run


@dataclass
class Case:
    id: str
    make: Callable[[Path, Recording], Callable[[], object]]
    error: type[Exception]
    match: str
    warns: str | None = None  # the FootzooWarning the input gives before its error (a regex of its message)


CASES = [
    # ---------------------------------------------------------------- readers
    Case("xio-random-bytes", lambda d, w: (lambda: load(_text(d, "r.csv", bytes(range(256)) * 40), format="xio")),
         FormatError, "r.csv: starts with 1 NUL byte(s) (0x00), not text"),
    Case("xio-header-then-latin1", lambda d, w: (lambda: load(_text(
        d, "r.csv", b"Time (s),Gyroscope X (deg/s)\n1.0,caf\xe9\n"), format="xio")), FormatError, "not UTF-8 text"),
    Case("detect-random-bytes", lambda d, w: (lambda: load(_text(d, "r.csv", b"\xff\xfe\x00" * 500))),
         FormatError, "cannot tell the format"),
    Case("canonical-random-bytes", lambda d, w: (lambda: load(_text(d, "r.csv", b"t,acc_x,gyr_x\n\xff\x00\x81\n"))),
         FormatError, "r.csv: a run of 1 NUL bytes (0x00) at byte 15 (line 2): the file was damaged"),
    Case("canonical-random-bytes-cut", lambda d, w: (lambda: load(_text(d, "r.csv", b"t,acc_x,gyr_x\n\xff\x00\x81"))),
         FormatError, "r.csv: a run of 1 NUL bytes (0x00) at byte 15 (line 2)"),
    Case("canonical-latin1", lambda d, w: (lambda: load(_text(d, "r.csv", b"t,acc_x,gyr_x\n\xff\x81\n"))),
         FormatError, "r.csv: not UTF-8"),
    Case("parquet-garbage", lambda d, w: (lambda: load(_text(d, "r.parquet", b"PAR1 not really"))),
         FormatError, "cannot read"),
    Case("mat-garbage", lambda d, w: (lambda: load(_text(d, "r.mat", b"MATLAB 5.0 garbage" * 20))),
         FormatError, "MATLAB"),
    Case("gaitmap-garbage", lambda d, w: (lambda: load(_text(d, "g.csv", "sensor,left_sensor\n1,2\nx\n"), foot="left")),
         FormatError, "g.csv"),
    Case("directory-as-data", lambda d, w: (lambda: load(d)), FormatError, "is a directory"),
    Case("device-as-data", lambda d, w: (lambda: load("/dev/zero", format="canonical")), FormatError,
         "not a regular file"),
    Case("empty-file", lambda d, w: (lambda: load(_text(d, "e.csv", ""))), FormatError, "empty"),
    Case("missing-file", lambda d, w: (lambda: load(d / "nope.csv")), FormatError, "no such file"),
    Case("unknown-format", lambda d, w: (lambda: load(_csv(d, w), format="csvv")), FormatError,
         "unknown format 'csvv'"),
    Case("unknown-reader-option", lambda d, w: (lambda: load(_pyshoe(d, w), foo=1)), FormatError,
         "pyshoe reader: unknown option 'foo' (did you mean 'foot'?); its options are ['acc_unit', 'axes', "
         "'duplicates', 'foot', 'gyr_unit', 'max_gap', 'nan_policy']"),
    Case("csv-read-as-pyshoe", lambda d, w: (lambda: load(_csv(d, w), format="pyshoe")), FormatError,
         "cannot read it as a MATLAB .mat file"),
    Case("pyshoe-truncated", lambda d, w: (lambda: load(_truncated(_pyshoe(d, w)), format="pyshoe")), FormatError,
         "): the file is damaged or truncated, or not a MATLAB file; copy it again from its source"),
    Case("canonical-unknown-option", lambda d, w: (lambda: load(_csv(d, w), acc_units="g")), FormatError,
         "canonical reader: unknown option 'acc_units' (did you mean 'acc_unit'?)"),
    Case("invalid-meta-yaml", lambda d, w: _with_meta(d, w, "meta: {name: [unclosed\n"), FormatError,
         "not valid YAML"),
    Case("meta-yaml-not-mapping", lambda d, w: _with_meta(d, w, "- just\n- a list\n"), FormatError,
         "expected a mapping"),
    Case("meta-yaml-closed-loop-text", lambda d, w: _with_meta(d, w, "closed_loop: 'no'\n"), FormatError,
         "closed_loop must be true or false"),
    Case("meta-yaml-latin1", lambda d, w: _with_meta(d, w, "meta: {name: caf\xe9}\n".encode("latin-1")),
         FormatError, "not UTF-8"),
    Case("meta-yaml-alias-bomb", lambda d, w: _with_meta(d, w, _bomb()), FormatError, "alias"),
    Case("truth-shorter-than-imu", lambda d, w: (lambda: load(_pyshoe(d, w, gt_rows=w.n // 2))), FormatError,
         "'gt' (the VICON position) has shape (350, 3), expected (700, 3): one row per IMU sample"),
    Case("truth-shorter-direct", lambda d, w: (lambda: Recording(t=w.t, acc=w.acc, gyr=w.gyr,
                                                                  truth=Truth(pos=w.truth.pos[:-10]))),
         RecordingError, "truth must have one row per IMU sample"),
    Case("truth-ends-early-in-csv", lambda d, w: (lambda: load(_truth_ends_early(d, w))), RecordingError,
         "ground truth pos: the reference stops at sample"),
    Case("pyshoe-imu-wrong-shape", lambda d, w: (lambda: load(_pyshoe(d, w, imu_cols=4))), FormatError,
         "'imu' must be N x 6"),
    Case("gaitmap-rate-inf", lambda d, w: (lambda: load(_text(d, "g.csv", "sensor,left_sensor\n"), format="gaitmap",
                                                        foot="left", rate=float("inf"))), ConfigError, "finite"),
    Case("max-gap-negative", lambda d, w: (lambda: load(_csv(d, w), max_gap=-1.0)), ConfigError,
         "max_gap = -1.0 s is out of range: it must be > 0 s"),
    Case("acc-1e30", lambda d, w: _modified(w, acc=((50, 0), 1e30)), RecordingError,
         "beyond any body-worn IMU"),
    Case("gyr-1e30-not-called-deg-s", lambda d, w: _modified(w, gyr=((50, 2), -1e30)), RecordingError,
         "gyr_z is -1e+30 rad/s at sample 50"),
    Case("acc-nan", lambda d, w: _modified(w, acc=((7, 1), np.nan)), RecordingError, "non-finite"),
    Case("t-inf", lambda d, w: _modified(w, t=((-1,), np.inf)), RecordingError, "t has 1 non-finite"),
    Case("time-in-ms", lambda d, w: (lambda: Recording(t=w.t * 1e3, acc=w.acc, gyr=w.gyr)), RecordingError,
         "are the time stamps in ms"),
    Case("time-in-ns", lambda d, w: (lambda: Recording(t=w.t * 1e9 + 1.7e18, acc=w.acc, gyr=w.gyr)), RecordingError,
         "footzoo needs t in seconds"),
    Case("decimal-comma", lambda d, w: (lambda: load(_text(d, "c.csv", "t;acc_x;acc_y;acc_z;gyr_x;gyr_y;gyr_z\n"
                                                            "0;0,1;0;-9,8;0;0;0\n"), format="canonical")),
         RecordingError, "missing column(s)", warns=r"c\.csv: column\(s\) 't;acc_x;.*' are not read"),
    Case("text-column", lambda d, w: (lambda: load(_text(d, "c.csv", _TEXT_COLUMN))), RecordingError,
         "column 'acc_x' holds no numbers (first value '0,1')"),
    Case("truth-stance-text", lambda d, w: (lambda: load(_stance_text(d, w))), RecordingError,
         "column 'true_stance' must hold 0 or 1"),
    Case("recording-text-values", lambda d, w: (lambda: Recording(t=["a"] * 5, acc=w.acc[:5], gyr=w.gyr[:5])),
         RecordingError, "t must be numbers"),
    Case("recording-meta-not-dict", lambda d, w: (lambda: Recording(t=w.t, acc=w.acc, gyr=w.gyr, meta=[1])),
         RecordingError, "meta must be a dict"),
    Case("path-not-a-path", lambda d, w: (lambda: load(123)), FormatError, "must be a file path"),
    Case("dataframe-not-a-dataframe", lambda d, w: (lambda: Recording.from_dataframe([1, 2])), RecordingError,
         "expects a pandas DataFrame"),
    Case("unit-not-text", lambda d, w: (lambda: Recording.from_dataframe(w.to_dataframe(), acc_unit=["g"])),
         RecordingError, "acc_unit=['g'] is not supported"),
    # ---------------------------------------------------------------- YAML
    # the name and type fields hold text: anything else is an error, not a crash or a path
    *[Case(f"config-name-{i}", lambda d, w, v=v: _config(d, _with(YUN, name=v)), ConfigError,
           "name must be a non-empty text") for i, v in enumerate(["[a]", "5", "''", "../../etc", "'a:b'"])],
    Case("config-description-list", lambda d, w: _config(d, _with(YUN, description="[a, b]")), ConfigError,
         "description must be text"),
    *[Case(f"config-type-{i}", lambda d, w, v=v: _config(d, _with(YUN, detector=v)), ConfigError,
           "must be a plug-in's name (text)") for i, v in enumerate(["{type: [a]}", "{type: {a: 1}}", "{type: 3}"])],
    Case("config-invalid-yaml", lambda d, w: _config(d, "orientation: {type: [\n"), ConfigError, "not valid YAML"),
    Case("config-latin1", lambda d, w: _config(d, ("name: caf\xe9\n" + YUN).encode("latin-1")), ConfigError,
         "not UTF-8 text (byte 0xe9"),
    Case("config-alias-bomb", lambda d, w: _config(d, _bomb() + YUN), ConfigError, "aliases are expanded"),
    Case("config-recursive-alias", lambda d, w: _config(d, "a: &a [*a]\n" + YUN), ConfigError, "recursive"),
    Case("config-too-deep", lambda d, w: _config(d, "x: " + "[" * 200 + "]" * 200 + "\n" + YUN), ConfigError,
         "nested deeper"),
    Case("config-too-large", lambda d, w: _config(d, YUN + "#" + "x" * (1 << 20) + "\n"), ConfigError,
         "larger than"),
    Case("config-duplicate-key", lambda d, w: _config(d, YUN + "gravity: 9.8\n"), ConfigError,
         "duplicate key 'gravity'"),
    Case("config-duplicate-nested-key", lambda d, w: _config(d, _with(
        YUN, detector="{type: angular_rate_fsm, threshold: 0.6, threshold: 0.7}")), ConfigError,
        "duplicate key 'threshold'"),
    Case("config-python-tag", lambda d, w: _config(d, "x: !!python/object/apply:os.system ['true']\n" + YUN),
         ConfigError, "could not determine a constructor"),
    Case("config-directory", lambda d, w: (lambda: Pipeline.from_yaml(d)), ConfigError, "is a directory"),
    Case("config-device", lambda d, w: (lambda: load_yaml("/dev/zero")), ConfigError, "not a regular file"),
    Case("config-empty", lambda d, w: _config(d, ""), ConfigError, "empty"),
    Case("config-not-mapping", lambda d, w: _config(d, "- a\n- b\n"), ConfigError, "must be a mapping"),
    # --------------------------------------------------------- parameters (units, ranges, types)
    Case("bool-quoted-no", lambda d, w: _config(d, _with(
        YUN, orientation="{type: fqa_complementary, use_magnetometer: 'no'}")), ConfigError,
        "use_magnetometer must be true or false, got str 'no'"),
    Case("bool-quoted-false", lambda d, w: _config(d, _with(
        YUN, orientation="{type: madgwick, use_magnetometer: 'false'}")), ConfigError, "must be true or false"),
    Case("bool-yaml11-no", lambda d, w: _config(d, _with(
        YUN, orientation="{type: madgwick, use_magnetometer: no}")), ConfigError, "must be true or false"),
    Case("bool-ekf-off", lambda d, w: _config(d, _with(
        YUN, orientation="{type: ins}", detector="{type: dgp}", corrections="[{type: ekf_zupt, gyro_bias: off}]")),
        ConfigError, "gyro_bias must be true or false"),
    Case("threshold-inf", lambda d, w: _config(d, _with(YUN, detector="{type: angular_rate_fsm, threshold: .inf}")),
         ConfigError, "threshold must be a finite number"),
    Case("threshold-nan", lambda d, w: _config(d, _with(YUN, detector="{type: shoe, threshold: .nan}")),
         ConfigError, "must be a finite number"),
    Case("threshold-text-number", lambda d, w: _config(d, _with(YUN, detector="{type: shoe, threshold: '3e4'}")),
         ConfigError, "without quotes"),
    Case("gravity-98.1", lambda d, w: _config(d, _with(YUN, gravity="98.1")), ConfigError,
         "gravity = 98.1 m/s^2 is out of range"),
    Case("gravity-1.0", lambda d, w: _config(d, _with(YUN, gravity="1.0")), ConfigError, "[9.7, 9.9]"),
    Case("init-duration-half", lambda d, w: _config(d, _with(YUN, init="{duration: half}")), ConfigError,
         "init.duration must be a number, got str 'half'"),
    Case("init-duration-zero", lambda d, w: _config(d, _with(YUN, init="{duration: 0}")), ConfigError,
         "init.duration = 0 s is out of range"),
    Case("init-max-gyr-negative", lambda d, w: _config(d, _with(YUN, init="{max_gyr: -1}")), ConfigError,
         "init.max_gyr = -1 rad/s is out of range: it must lie in (0, 10] rad/s"),
    Case("init-duration-in-ms", lambda d, w: _config(d, _with(YUN, init="{duration: 500}")), ConfigError,
         "500 s is 500000 ms: duration is in s (the default 0.5 s is 500 ms); for 500 ms write 0.5"),
    Case("threshold-in-deg-per-s", lambda d, w: _config(d, _with(YUN, detector="{type: angular_rate_fsm, "
                                                                            "threshold: 35}")),
         ConfigError, "35 rad/s is 2005 °/s: threshold is in rad/s (the default 0.6 rad/s is 34.4 °/s)"),
    Case("gravity-in-g", lambda d, w: _config(d, _with(YUN, gravity="1.0")), ConfigError,
         "gravity is in m/s^2 (the default 9.81 m/s^2 is 1 g); for 1 g write 9.81"),
    Case("dip-tolerance-in-degrees", lambda d, w: _config(d, _with(
        YUN, orientation="{type: madgwick, mag_dip_tolerance: 5}")), ConfigError, "for 5 ° write 0.0873"),
    Case("min-duration-in-samples", lambda d, w: _config(d, _with(YUN, detector="{type: angular_rate_fsm, "
                                                                             "min_duration: 5}")),
         ConfigError, "for 5 ms write 0.005 (a count of samples? durations are in s: 5 samples at 100 Hz are 0.05 s)"),
    Case("foot-choice-misspelt", lambda d, w: _config(d, YUN + "analysis: [{type: huang_fpa, foot: rigth}]\n"),
         ConfigError, "foot must be one of ['auto', 'right', 'left'], got 'rigth' (did you mean 'right'?)"),
    Case("ekf-zero-rate-without-gyro-bias", lambda d, w: _config(d, _with(
        YUN, orientation="{type: ins}", detector="{type: dgp}",
        corrections="[{type: ekf_zupt, gyro_bias: false}]")), ConfigError,
        "corrections[0] (ekf_zupt): zero_rate measures the gyro bias: it needs gyro_bias: true"),
    Case("sexagesimal-is-text", lambda d, w: _config(d, _with(YUN, detector="{type: angular_rate_fsm, "
                                                                          "min_duration: 1:30}")),
         ConfigError, "min_duration must be a number, got str '1:30'"),
    Case("noise-zero-std", lambda d, w: _config(d, _with(
        YUN, orientation="{type: ins}", detector="{type: dgp}", corrections="[{type: ekf_zupt, velocity_std: 0}]")),
        ConfigError, "velocity_std = 0 m/s is out of range"),
    Case("noise-inf", lambda d, w: _config(d, _with(YUN, orientation="{type: ins}", corrections="[{type: zupt}]",
                                                    navigation="{attitude_noise: .inf}")),
         ConfigError, "navigation.attitude_noise must be a finite number"),
    Case("noise-huge", lambda d, w: _config(d, _with(YUN, orientation="{type: ins}", corrections="[{type: zupt}]",
                                                     navigation="{attitude_noise: 1e300}")),
         ConfigError, "navigation.attitude_noise = 1e+300 rad^2/s is out of range"),
    Case("noise-moved", lambda d, w: _config(d, _with(YUN, orientation="{type: ins, attitude_noise: 0.01}")),
         ConfigError, "is now set as navigation.attitude_noise"),
    Case("gain-huge", lambda d, w: _config(d, _with(YUN, orientation="{type: fqa_complementary, "
                                                                     "static_gain: 1e300}")),
         ConfigError, "static_gain = 1e+300 1/s is out of range"),
    Case("foot-vector-zero", lambda d, w: _config(d, YUN + "analysis: [{type: huang_fpa, foot_vector: [0, 0, 0]}]\n"),
         ConfigError, "foot_vector must not be all zeros"),
    Case("foot-vector-nan", lambda d, w: _config(d, YUN + "analysis: [{type: huang_fpa, foot_vector: [.nan, 0, 0]}]\n"),
         ConfigError, "foot_vector[0] must be a finite number"),
    Case("height-direction-zero", lambda d, w: _config(d, _with(
        YUN, orientation="{type: ins}", detector="{type: dgp}",
        corrections="[{type: height_distance, directions: [[0, 0, 0], [0, 0, 1]]}]")), ConfigError,
        "directions must not contain [0, 0, 0]"),
    # ---------------------------------------------------------- calibration files
    Case("foot-vector-file-zero", lambda d, w: (lambda: FootVector.load(
        _text(d, "fv.yaml", "foot_vector: [0, 0, 0]\n"))), ConfigError, "must not be all zeros"),
    Case("foot-vector-file-latin1", lambda d, w: (lambda: FootVector.load(
        _text(d, "fv.yaml", b"foot_vector: \xe9\n"))), ConfigError, "not UTF-8"),
    Case("foot-vector-file-list", lambda d, w: (lambda: FootVector.load(_text(d, "fv.yaml", "- 1\n- 2\n"))),
         ConfigError, "no 'foot_vector' entry"),
    Case("foot-vector-file-missing", lambda d, w: (lambda: FootVector.load(d / "none.yaml")), ConfigError,
         "does not exist"),
    Case("height-calibration-not-mapping", lambda d, w: (lambda: load_calibration(_text(d, "c.yaml", "[1, 2]\n"))),
         ConfigError, "is a mapping with positions"),
    Case("height-calibration-bomb", lambda d, w: (lambda: load_calibration(_text(d, "c.yaml", _bomb()))),
         ConfigError, "alias"),
    # ---------------------------------------------------------------- studies (parsing)
    Case("study-alias-bomb", lambda d, w: _study(d, _bomb() + "base: yun.yaml\nrecordings: [{simulate: {}}]\n"),
         ConfigError, "aliases are expanded"),
    Case("study-latin1", lambda d, w: _study(d, "name: \xe9tude\n".encode("latin-1")), ConfigError, "not UTF-8"),
    Case("study-duplicate-key", lambda d, w: _study(d, "base: yun.yaml\nbase: yun.yaml\nrecordings: []\n"),
         ConfigError, "duplicate key 'base'"),
    Case("study-recordings-not-list", lambda d, w: _study(d, "base: yun.yaml\nrecordings: {simulate: {}}\n"),
         ConfigError, "recordings must be a list"),
    Case("study-seeds-text", lambda d, w: _study(d, "base: yun.yaml\nrecordings: [{simulate: {}, seeds: abc}]\n"),
         ConfigError, "seeds must be a list of whole numbers"),
    Case("study-simulate-not-mapping", lambda d, w: _study(d, "base: yun.yaml\nrecordings: [{simulate: 3}]\n"),
         ConfigError, "simulate must be a mapping"),
    Case("study-sweep-text", lambda d, w: _study(d, "base: yun.yaml\nrecordings: [{simulate: {}}]\n"
                                                    "sweep: {points: many}\n"), ConfigError, "sweep.points"),
    Case("study-path-not-text", lambda d, w: _study(d, "base: yun.yaml\nrecordings: [{path: 3}]\n"), ConfigError,
         "path must be a file path or glob"),
    Case("stream-acc-in-g", lambda d, w: _push(w, *[(w.t[k], w.acc[k] / 9.80665, w.gyr[k]) for k in range(w.n)]),
         RecordingError, "this looks like g, not m/s²"),
    # ---------------------------------------------------------------- plug-ins (more: test_plugins.py)
    Case("plugin-raises", lambda d, w: _faulty_plugin(d, w, "test_case_raises", "return 1 / 0"), PluginError,
         "detector 'test_case_raises' (footzoo_plugin_"),
    Case("plugin-exits", lambda d, w: _faulty_plugin(d, w, "test_case_exits", "raise SystemExit(3)"), PluginError,
         "never exit the process"),
    Case("plugin-no-return", lambda d, w: _faulty_plugin(
        d, w, "test_case_no_return", "self.stance_ = self.statistic_ = np.zeros(len(t))"), PluginError,
         "returned None: end detect() with 'return self'"),
    Case("plugin-nan-stance", lambda d, w: _faulty_plugin(
        d, w, "test_case_nan_stance", "self.stance_ = np.full(len(t), np.nan); self.statistic_ = t; return self"),
         PluginError, "NaN is not stance"),
    Case("plugin-writes-input", lambda d, w: _faulty_plugin(
        d, w, "test_case_writes", "gyr[0] = 0.0; return self"), PluginError, "copy it first"),
    Case("plugin-file-exits-on-import", lambda d, w: (lambda: Pipeline.from_dict(
        {"plugins": [str(_text(d, "exits.py", "import sys\nsys.exit()\n"))], "orientation": {"type": "madgwick"},
         "detector": {"type": "shoe"}})), PluginError, "called sys.exit(None)"),
    # ---------------------------------------------------------------- stream
    Case("stream-7-samples", lambda d, w: _push(w, (w.t[0], w.acc[:7], w.gyr[:7])), RecordingError,
         "push them one at a time"),
    Case("stream-t-nan", lambda d, w: _push(w, (np.nan, w.acc[0], w.gyr[0])), RecordingError, "not finite"),
    Case("stream-t-inf", lambda d, w: _push(w, (w.t[0], w.acc[0], w.gyr[0]), (np.inf, w.acc[1], w.gyr[1])),
         RecordingError, "not finite"),
    Case("stream-acc-1e30", lambda d, w: _push(w, (w.t[0], [1e30, 0.0, -9.8], w.gyr[0])), RecordingError,
         "beyond any body-worn IMU"),
    Case("stream-gap-10s", lambda d, w: _push(w, (w.t[0], w.acc[0], w.gyr[0]), (w.t[0] + 10.0, w.acc[1], w.gyr[1])),
         RecordingError, "gap of 10 s"),
    Case("stream-backwards", lambda d, w: _push(w, (w.t[1], w.acc[1], w.gyr[1]), (w.t[0], w.acc[0], w.gyr[0])),
         RecordingError, "must arrive in order"),
    Case("stream-t-text", lambda d, w: _push(w, ("0.1", w.acc[0], w.gyr[0])), RecordingError,
         "t must be one time stamp"),
    Case("stream-dist-inf", lambda d, w: _push(w, (w.t[0], w.acc[0], w.gyr[0], None, [np.inf, 0.1])),
         RecordingError, "dist at t"),
    Case("stream-mag-shape", lambda d, w: _push(w, (w.t[0], w.acc[0], w.gyr[0], [1.0, 2.0])), RecordingError,
         "mag at t"),
    Case("stream-acc-complex", lambda d, w: _push(w, (w.t[0], w.acc[0] + 1j, w.gyr[0])), RecordingError,
         "must be 3 real numbers"),
    Case("stream-gyr-bool", lambda d, w: _push(w, (w.t[0], w.acc[0], [True, False, True])), RecordingError,
         "must be 3 real numbers"),
    Case("stream-pipeline-name", lambda d, w: (lambda: Stream("nguyen2016", rate=100.0)), ConfigError,
         "Stream needs a footzoo Pipeline, got str"),
    Case("stream-pipeline-none", lambda d, w: (lambda: Stream(None, rate=100.0)), ConfigError,
         "Stream needs a footzoo Pipeline"),
    # a pasted number of strides would simulate for hours: bounded, and whole
    Case("simulate-strides-huge", lambda d, w: (lambda: simulate(n_strides=10**8)), ConfigError,
         "n_strides must be a whole number in [0, 100000]"),
    Case("simulate-strides-float", lambda d, w: (lambda: simulate(n_strides=2.5)), ConfigError,
         "n_strides must be a whole number"),
    # a column named twice: pandas would rename the second and the first would be read silently
    Case("canonical-duplicate-column", lambda d, w: (lambda: load(_text(
        d, "r.csv", "".join(line + ",0\n" for line in _imu_text(w).splitlines()).replace(",0", ",acc_x", 1)))),
         FormatError, "['acc_x'] more than once"),
    Case("canonical-semicolons", lambda d, w: (lambda: load(_text(d, "r.csv", _imu_text(w).replace(",", ";")))),
         FormatError, "separated by semicolons"),
    Case("canonical-tabs", lambda d, w: (lambda: load(_text(d, "r.csv", _imu_text(w).replace(",", "\t")))),
         FormatError, "separated by tabs"),
    # the row's time is printed as a number, not as a numpy repr
    Case("canonical-nan-cell-time", lambda d, w: (lambda: load(_text(d, "r.csv", _imu_text(w, nan_row=3)))),
         RecordingError, "first at row 3 (t = 0.030000 s)"),
]


def _imu_text(w: Recording, nan_row: int | None = None) -> str:
    """The IMU columns of ``w`` as canonical CSV text (``nan`` in acc_x of ``nan_row``)."""
    rows = ["t,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z"]
    for k in range(len(w.t)):
        acc = ["nan" if k == nan_row else repr(float(w.acc[k, 0])), *map(repr, map(float, w.acc[k, 1:]))]
        rows.append(",".join([repr(float(w.t[k])), *acc, *map(repr, map(float, w.gyr[k]))]))
    return "\n".join(rows) + "\n"


def test_quoted_header_is_read(tmp_path, walk):
    """A header with quoted names ("t","acc_x",...) is valid CSV: it is read as the canonical format."""
    lines = _imu_text(walk).split("\n")
    lines[0] = ",".join(f'"{c}"' for c in lines[0].split(","))
    rec = load(_text(tmp_path, "q.csv", "\n".join(lines)))
    np.testing.assert_array_equal(rec.acc, load(_text(tmp_path, "p.csv", _imu_text(walk))).acc)


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input_gives_a_clear_footzoo_error(case, tmp_path, walk):
    action = case.make(tmp_path, walk)
    warned = pytest.warns(FootzooWarning, match=case.warns) if case.warns else contextlib.nullcontext()
    with warned, pytest.raises(case.error) as info:
        action()
    assert case.match in str(info.value)


def test_case_ids_are_unique():
    assert len({c.id for c in CASES}) == len(CASES)


@pytest.mark.skipif(IS_ROOT, reason="root reads every file")
def test_unreadable_file(tmp_path, walk):
    p = _csv(tmp_path, walk)
    p.chmod(0)
    with pytest.raises(FormatError, match="not readable"):
        load(p)


def test_alias_bomb_fails_fast_with_bounded_memory(tmp_path):
    p = _text(tmp_path, "bomb.yaml", _bomb(levels=12) + YUN)
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError, match="alias"):
            Pipeline.from_yaml(p)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20 * 2**20  # bytes: the expanded document would hold 9**12 strings


def test_yaml_12_scalars():
    from footzoo.core.yamlsafe import load_text

    assert load_text("a: yes\nb: 1:30\nc: 010\nd: 1e-3\ne: 2024-01-01\nf: True\ng: 0x10") == {
        "a": "yes", "b": "1:30", "c": 10, "d": 0.001, "e": "2024-01-01", "f": True, "g": 16}
    # merge keys may be overridden (not a duplicate)
    assert load_text("b: &b {x: 1, y: 2}\nd: {<<: *b, x: 3}")["d"] == {"x": 3, "y": 2}


# --------------------------------------------------------------------------- sensor sanity
def test_stream_unit_switched_after_the_start_is_warned(walk):
    """An accelerometer switched to g after a start in m/s² is named live (the start check passed)."""
    s = Stream(Pipeline.from_yaml(YUN_PATH), rate=walk.rate)
    switch = int(np.searchsorted(walk.t, walk.t[0] + 2.0))
    with pytest.warns(SensorWarning, match=r"≈ 1: in g\?"):
        for k in range(len(walk.t)):
            s.push(walk.t[k], walk.acc[k] / (9.81 if k >= switch else 1.0), walk.gyr[k])
        s.close()
    assert s.sensor["acc_scale"]["first"] >= switch


def test_gyro_glitch_is_flagged_with_its_sample(walk):
    gyr = walk.gyr.copy()
    k = int(np.searchsorted(walk.t, 2.5))
    gyr[k] += [0.0, 40.0, 0.0]  # one 40 rad/s sample: below the deg/s check
    expected = (rf"1 isolated gyroscope spike\(s\) standing more than 15 rad/s off the signal around them .* "
                rf"at sample\(s\) {k} \(t = .* s, \|ω\| = .* rad/s, 4\d\.\d rad/s off\)")
    with pytest.warns(SensorWarning, match=expected):
        rec = Recording(t=walk.t, acc=walk.acc, gyr=gyr, meta={"name": "glitch"})
    assert rec.meta["sanity"]["gyro_glitches"] == [k]


def test_saturated_axis_is_flagged_with_the_sample_range(walk):
    acc = walk.acc.copy()
    rail = 0.6 * np.abs(acc[:, 0]).max()
    acc[:, 0] = np.clip(acc[:, 0], -np.inf, rail)
    runs = np.flatnonzero(acc[:, 0] == rail)
    with pytest.warns(SensorWarning, match=rf"sensor saturated \(clipped\): acc_x at {rail:.6g} for \d+ samples"):
        rec = Recording(t=walk.t, acc=acc, gyr=walk.gyr, meta={"name": "clipped"})
    found = rec.meta["sanity"]["saturation"]
    assert [f["axis"] for f in found] == ["acc_x"]
    assert found[0]["runs"][0][0] == runs[0]
    assert found[0]["samples"] <= len(runs)


def test_clean_recordings_raise_no_sensor_warning(walk):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", SensorWarning)
        rec = Recording(t=walk.t, acc=walk.acc, gyr=walk.gyr)
        # the paper profile's angular rate has flat tops: noise-free, they repeat exactly but are not clipping
        flat = simulate(n_strides=4, rate=100.0, sampling="instantaneous")
    assert "sanity" not in rec.meta and "sanity" not in flat.meta


# --------------------------------------------------------------------------- command line
CLI_CASES = [
    # an empty config, study or destination is not the current folder
    *[(f"empty-{argv[0]}", (lambda a: lambda d, w: list(a))(argv), EXIT_USAGE, "an empty name")
      for argv in (["run", ""], ["validate", ""], ["ablate", ""], ["tune", ""], ["compile", ""])],
    ("configs-to-empty", lambda d, w: ["configs", "--copy", "recommended", "--to", ""], EXIT_USAGE,
     "argument --to: an empty path"),
    ("validate-a-recording", lambda d, w: ["validate", str(_text(d, "big.csv", "t,acc_x\n" + "0.0,1.0\n" * 150_000))],
     EXIT_USAGE, "a recording goes to --data"),
    ("data-directory", lambda d, w: ["run", "yun2012", "--data", str(d)], EXIT_DATA,
     "is a directory"),
    ("calibrate-dev-zero", lambda d, w: ["calibrate", "--data", "/dev/zero", "--out", str(d / "fv.yaml")], EXIT_DATA,
     "not a regular file"),
    ("out-under-a-file", lambda d, w: ["run", "yun2012", "--data", str(_csv(d, w)), "--out",
                                       str(_text(d, "f.txt", "x"))], EXIT_DATA, "is not a directory"),
    ("simulate-out-missing-folder", lambda d, w: ["simulate", "straight", "--out", str(d / "no" / "x.csv")],
     EXIT_DATA, "does not exist"),
    ("simulate-negative-rate", lambda d, w: ["simulate", "straight", "--rate", "-5", "--out", str(d / "s.csv")],
     EXIT_USAGE, "argument --rate: -5 Hz is out of range"),
    ("simulate-nan-noise", lambda d, w: ["simulate", "straight", "--noise-scale", "nan", "--out", str(d / "s.csv")],
     EXIT_USAGE, "argument --noise-scale"),
    ("config-gravity", lambda d, w: ["validate", str(_text(d, "g.yaml", _with(YUN, gravity="98.1")))], EXIT_USAGE,
     "gravity = 98.1"),
    ("config-latin1", lambda d, w: ["validate", str(_text(d, "l.yaml", b"name: caf\xe9\n"))], EXIT_USAGE,
     "not UTF-8"),
    ("data-impossible", lambda d, w: ["run", "yun2012", "--data", _impossible_csv(d, w)], EXIT_DATA,
     "beyond any body-worn IMU"),
]


def _impossible_csv(d: Path, w: Recording) -> str:
    df = w.to_dataframe()
    df.loc[9, "acc_z"] = 1e30
    df.to_csv(d / "x.csv", index=False)
    return str(d / "x.csv")


@pytest.mark.parametrize("argv, code, fragment", [c[1:] for c in CLI_CASES], ids=[c[0] for c in CLI_CASES])
def test_cli_bad_input_exit_code_and_no_traceback(argv, code, fragment, tmp_path, walk, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(argv(tmp_path, walk)) == code
    err = capsys.readouterr().err
    assert fragment in err
    assert "Traceback" not in err


@pytest.mark.skipif(IS_ROOT, reason="root writes everywhere")
def test_cli_read_only_out(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    assert main(["run", "yun2012", "--out", str(ro / "x")]) == EXIT_DATA
    assert "permission denied" in capsys.readouterr().err


def test_cli_internal_error_exit_1_and_debug_shows_traceback(monkeypatch, capsys):
    import footzoo.apps.cli as cli

    def boom(args):
        raise RuntimeError("kaboom")

    monkeypatch.setattr(cli, "cmd_list", boom)
    assert main(["list"]) == EXIT_INTERNAL
    err = capsys.readouterr().err
    assert "internal error: RuntimeError: kaboom" in err and "Traceback" not in err
    assert main(["list", "--debug"]) == EXIT_INTERNAL
    assert "Traceback" in capsys.readouterr().err


@pytest.mark.slow  # a new Python process per case
def test_cli_console_script_has_no_traceback(tmp_path):
    """The real process: stderr carries one footzoo line, the exit code is documented in --help."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    bad = _text(tmp_path, "bad.yaml", "orientation: {type: [\n")
    proc = subprocess.run([sys.executable, "-m", "footzoo", "validate", str(bad)], capture_output=True, text=True,
                          cwd=ROOT, env=env)
    assert proc.returncode == EXIT_USAGE
    assert proc.stderr.startswith("footzoo: error:") and "Traceback" not in proc.stderr
    helptext = subprocess.run([sys.executable, "-m", "footzoo", "--help"], capture_output=True, text=True, cwd=ROOT,
                              env=env).stdout
    assert "exit codes:" in helptext and "3    data error" in helptext and "4    plug-in error" in helptext


# --------------------------------------------------------------------------- parameters, from their declarations
def _declared() -> list[tuple[str, str, str, object]]:
    """(kind, plug-in, parameter, Declared) of every declared parameter of every registered plug-in."""
    from footzoo.plugins.registry import KINDS, available

    return [(kind, name, p, d) for kind in KINDS for name, cls in sorted(available(kind).items())
            if not name.startswith("test_") for p, d in cls.declaration().items()]


DECLARED = _declared()
PLUGINS = sorted({(kind, name) for kind, name, _, _ in DECLARED})


@pytest.mark.parametrize("kind, name", PLUGINS, ids=[n for _, n in PLUGINS])
def test_every_value_a_declaration_refuses_is_a_clear_config_error(kind, name):
    """Wrong types, NaN, ±inf and values just beyond each end, derived from each parameter's declaration: each is a
    ConfigError from ``build`` that names the place, the plug-in and the parameter (a new plug-in is covered too)."""
    from footzoo.plugins.registry import build

    where = f"{kind}s[0]" if kind in ("correction", "calibration") else kind
    for k, n, param, d in DECLARED:
        if (k, n) != (kind, name):
            continue
        for bad in d.param.invalid_values():
            with pytest.raises(ConfigError) as err:
                build(kind, {"type": name, param: bad}, where)
            message = str(err.value)
            assert message.startswith(f"{where} ({name}): ") and param in message, message
            if isinstance(bad, float) and math.isfinite(bad) and type(d.param).__name__ in ("Real", "Integer"):
                assert "is out of range: it must" in message, message
                assert d.param.unit in ("", "1") or f" {d.param.unit}" in message, message  # "1": dimensionless


@functools.cache
def _parsed(name: str) -> dict:
    return load_yaml(name)


def shipped(name: str) -> dict:
    """A fresh copy of the shipped config ``name`` (each parsed once: hundreds of cases below start from one)."""
    return copy.deepcopy(_parsed(name))


SETTINGS = [(key, d) for key, d in __import__("footzoo.runtime.validate", fromlist=["x"]).settings_declarations(
).items()]


@pytest.mark.parametrize("key, declared", SETTINGS, ids=[k for k, _ in SETTINGS])
def test_every_bad_setting_is_a_clear_config_error(key, declared):
    """The same for the settings blocks (gravity, init, navigation, guards): one mechanism."""
    for bad in declared.param.invalid_values():
        block, _, field = key.partition(".")
        cfg = shipped("yun2012")
        cfg[block] = {field: bad} if field else bad
        with pytest.raises(ConfigError) as err:
            Pipeline.from_dict(cfg)
        assert key in str(err.value), str(err.value)


def _edges() -> list[tuple[str, str, str, float]]:
    """Every (kind, plug-in, parameter, value) at an end of a declared numeric range (the nearest float inside)."""
    return [(kind, name, p, v) for kind, name, p, d in DECLARED if kind in ("orientation", "detector", "correction")
            and type(d.param).__name__ == "Real" for v in d.param.interval.inside()]


EDGES = _edges()


@pytest.fixture(scope="module")
def sensors_walk() -> Recording:
    return simulate(n_strides=4, rate=50.0, noise=NoiseModel(seed=1), distance_sensors=True)


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
# a detector at an edge of its range may find no stance on this walk; the guard marks some and says so (expected);
# or take every sample for stance, which the run says too (expected)
@pytest.mark.filterwarnings(STANCES_GUARDED)
@pytest.mark.filterwarnings(ALL_STANCE)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
@pytest.mark.parametrize("kind, name, param, value", EDGES, ids=[f"{n}.{p}={v:g}" for _, n, p, v in EDGES])
def test_parameters_at_the_edges_of_their_range_give_finite_estimates(kind, name, param, value, sensors_walk):
    """The declared ranges are safe: no NaN or crash at either end (or a clear footzoo error)."""
    yun, nguyen = (shipped(c) for c in ("yun2012", "nguyen2016"))
    if kind == "orientation":
        cfg = nguyen if name == "ins" else yun
        cfg["orientation"] = {"type": name, param: value}
    elif kind == "detector":
        cfg = yun
        cfg["detector"] = {"type": name, param: value}
    else:  # in the first shipped config that has the correction, else added to duong2015_zupt's zero-velocity update
        # (the compiled loops of the shipped configs: a correction added to a two-update config would compile anew)
        configs = (shipped(n) for n in library.names("pipeline"))
        cfg = next((c for c in configs if name in [u["type"] for u in c.get("corrections", [])]), None)
        if cfg is None:
            cfg = shipped("duong2015_zupt")
            cfg["corrections"].append({"type": name})
        cfg["corrections"] = [{**u, param: value} if u["type"] == name else u for u in cfg["corrections"]]
    pipeline = Pipeline.from_dict(cfg)
    try:
        result = pipeline.run(sensors_walk)
    except RecordingError as err:  # e.g. a 1 µm max_range leaves no valid range reading: said clearly
        assert "height_distance" in str(err)
        return
    assert np.isfinite(result.pos).all() and np.isfinite(result.quat).all()


def test_declared_parameters_were_found():
    from footzoo.plugins.registry import KINDS, available

    builtins = [cls for kind in KINDS for n, cls in available(kind).items() if not n.startswith("test_")]
    assert all(not cls.undeclared() for cls in builtins)  # every built-in parameter is declared
    assert len(DECLARED) >= 60 and len(EDGES) >= 80 and len(SETTINGS) == 17


# --------------------------------------------------------------------------- damaged result archives
@pytest.fixture(scope="module")
def saved(walk, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("archive") / "res"
    Pipeline.from_yaml(YUN_PATH).run(walk).save(folder)
    return folder


# the saved result is yun2012's on a straight simulated walk: no hard-iron fit (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
@pytest.mark.parametrize("stem", ["result.json", "arrays.npz", "samples.", "steps."])
@pytest.mark.parametrize("damage", ["truncated", "garbage"])
def test_damaged_result_archive_is_a_format_error(saved, tmp_path, stem, damage):
    """A truncated or overwritten file of a saved result is a FormatError naming the folder, not a parser's error."""
    import shutil

    from footzoo import Result

    folder = tmp_path / "res"
    shutil.copytree(saved, folder)
    victim = next(p for p in folder.iterdir() if p.name.startswith(stem))
    raw = victim.read_bytes()
    victim.write_bytes(raw[: len(raw) // 2] if damage == "truncated" else b"\xff\x00garbage")
    with pytest.raises(FormatError, match="the archive is damaged"):
        Result.load(folder)


def test_detector_without_its_optional_statistic_runs(tmp_path, walk):
    """``statistic_`` is an optional output of a detector: one that sets only ``stance_`` runs (it crashed)."""
    run = _faulty_plugin(tmp_path, walk, "test_case_no_statistic",
                         "self.stance_ = np.linalg.norm(gyr, axis=1) < 0.6\n        return self")
    result = run()
    assert np.isnan(result.diagnostics["detector_statistic"]).all()
    assert result.diagnostics["detector_stance"].any()
