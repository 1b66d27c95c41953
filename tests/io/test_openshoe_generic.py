"""The OpenShoe and generic (YAML-described) readers convert axes, units and time at the edge.

Synthetic fixtures: a simulated walk (FRD, SI, known truth) is written in each format with the
sensor in another frame and other units; the reader must give the walk back. Real files: an
OpenShoe measurement under ``../shared/data/openshoe`` (skipped when there is none) and x-io's
example walk described by a sidecar, which must read exactly as the dedicated x-io reader reads it.
"""

from __future__ import annotations

import re
import shutil
import warnings

import numpy as np
import pandas as pd
import pytest

from footzoo import FormatError, RecordingError
from footzoo.core.conventions import GRAVITY
from footzoo.core.errors import FootzooWarning
from footzoo.io import detect_format, load
from footzoo.io.axes import parse_axes
from footzoo.sim import NoiseModel, simulate

from ..conftest import DATA, data_file

TICKS = 78720  # 3DM-GX3 timer ticks per 250 Hz sample (19 660 800 Hz)


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=3, rate=250.0, noise=NoiseModel(seed=7), magnetometer=True)


# --------------------------------------------------------------------------- OpenShoe

def openshoe_text(rec, columns=17, restart_at=5, mag_missing=(7, 8)) -> str:
    """The walk as a first-generation OpenShoe data_inert.txt: sensor z up, acc in g, the device timer."""
    sensor_acc = rec.acc * [1, -1, -1] / GRAVITY  # FRD -> sensor (z up): 180° about x, in g
    sensor_gyr = rec.gyr * [1, -1, -1]
    sensor_mag = rec.mag * [1, -1, -1]
    head = ["", "Inertial data.", "", "Header:      a_x [g]:      a_y [g]:      a_z [g]: ar_x [rad/s]: ar_y [rad/s]: "
            "ar_z [rad/s]:      Counter: Checksum:     Nr:   Filtered ts[s]: Unfiltered ts[s]:      Pred. ts[s]: "
            "Freq. [Hz]:" + ("      m_x [G]:      m_y [G]:      m_z [G]:" if columns == 17 else "")]
    rows = []
    counter = 130_516_848
    for k in range(rec.n):
        counter = 6068 if k == restart_at else counter + (TICKS if k else 0)
        host = 1274434048.5 + k * 0.004 + (0.003 if k % 7 == 3 else 0.0)  # jittery host clock
        mag = ("          +nan          +nan          +nan" if k in mag_missing else
               "".join(f" {v:+.8f}" for v in sensor_mag[k]))
        rows.append(f"   0xcb {' '.join(f'{v:+.8f}' for v in sensor_acc[k])} "
                    f"{' '.join(f'{v:+.8f}' for v in sensor_gyr[k])} {counter:13d}    0x15fd {k + 1:7d} "
                    f"{host:.6f} {host:.6f} {host + 0.004:.6f}  250.000001" + (mag if columns == 17 else ""))
    return "\n".join(head + rows) + "\n"


def test_openshoe_first_generation_file_comes_back_in_frd_si(walk, tmp_path):
    p = tmp_path / "data_inert.txt"
    p.write_text(openshoe_text(walk))
    assert detect_format(p) == "openshoe"
    with pytest.warns(FootzooWarning, match=r"device timer restarted 1 time\(s\) \(the first after row 4\)"):
        rec = load(p)
    np.testing.assert_allclose(rec.acc, walk.acc, rtol=0, atol=1e-7)  # 8 decimals of g
    np.testing.assert_allclose(rec.gyr, walk.gyr, rtol=0, atol=1e-8)
    np.testing.assert_allclose(rec.t, np.arange(walk.n) * TICKS / 19_660_800)  # the device clock, not the host's
    assert rec.rate == pytest.approx(19_660_800 / TICKS)
    assert rec.acc[:20].mean(axis=0)[2] == pytest.approx(-GRAVITY, abs=0.2)  # z down at rest
    assert rec.meta["axes"] == "[x, -y, -z]" and rec.meta["time_base"].startswith("device timer")
    assert rec.meta["mag_interpolated"] == 2 and np.isfinite(rec.mag).all()
    keep = np.setdiff1d(np.arange(walk.n), [7, 8])
    np.testing.assert_allclose(rec.mag[keep], walk.mag[keep], rtol=0, atol=1e-7)


def test_openshoe_without_magnetometer_columns_and_with_another_axis_map(walk, tmp_path):
    p = tmp_path / "data_inert.txt"
    p.write_text(openshoe_text(walk, columns=14, restart_at=-1))
    rec = load(p, axes="x, y, z")  # the sensor frame as it is: z up means the foot reads +g on z
    assert rec.mag is None
    np.testing.assert_allclose(rec.acc, walk.acc * [1, -1, -1], rtol=0, atol=1e-7)


def test_openshoe_board_export_without_time_stamps_needs_the_rate(walk, tmp_path):
    p = tmp_path / "data_inert.txt"
    rows = "\n".join(f"0  {' '.join(f'{v:f}' for v in a)}  {' '.join(f'{v:f}' for v in g)}  0 0  0  0 0 0  0  0 0 0"
                     for a, g in zip(walk.acc * [1, -1, -1], walk.gyr * [1, -1, -1], strict=True))
    p.write_text("dummy_header " * 32 + "\r\n" + rows.replace("\n", "\r\n") + "\r\n")  # as logging_inertial_data.m
    assert detect_format(p) == "openshoe"
    with pytest.raises(FormatError, match=r"no usable time stamps.*pass the sampling rate, e.g. rate=820"):
        load(p)
    rec = load(p, rate=250.0)  # m/s² from the board, already SI
    np.testing.assert_allclose(rec.acc, walk.acc, rtol=0, atol=1e-6)
    np.testing.assert_allclose(rec.t, np.arange(walk.n) / 250.0)


def test_openshoe_refuses_a_left_handed_axis_map(walk, tmp_path):
    p = tmp_path / "data_inert.txt"
    p.write_text(openshoe_text(walk, restart_at=-1))
    with pytest.raises(FormatError, match=r"axes: the axis map \[x, y, -z\] is left-handed.*e.g. \[x, -y, -z\]"):
        load(p, axes=["x", "y", "-z"])


def test_a_real_openshoe_measurement_reads_as_a_still_then_walking_foot():
    folder = DATA / "openshoe"
    files = sorted(folder.glob("*/data_inert*.txt")) if folder.is_dir() else []
    if not files:
        pytest.skip(f"no OpenShoe measurement in {folder} (an OpenShoe data_inert.txt under <name>/)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FootzooWarning)
        rec = load(files[0])
    still = rec.t < rec.t[0] + 0.5
    assert np.linalg.norm(rec.acc[still].mean(axis=0)) == pytest.approx(GRAVITY, rel=0.03)
    assert rec.acc[still].mean(axis=0)[2] < -0.8 * GRAVITY  # z down in FRD
    assert np.abs(rec.gyr[still]).max() < 0.1


# --------------------------------------------------------------------------- generic (YAML sidecar)

SIDECAR = """\
time: {column: "Time [ms]", unit: ms}
acc: {columns: [AccX, AccY, AccZ], unit: g}
gyr: {columns: [GyrX, GyrY, GyrZ], unit: deg/s}
mag: {columns: [MagX, MagY, MagZ], unit: uT}
axes: [y, x, -z]
delimiter: ";"
decimal: ","
skip_rows: 2
meta: {subject: S07, code: '1e3', foot: left}
closed_loop: true
"""


def generic_text(rec) -> str:
    """The walk as a European logger writes it: ';' and ',' decimals, ms, g, deg/s, sensor x/y swapped, z up."""
    # FRD = R · sensor with R rows [y, x, -z]: sensor x = FRD y, sensor y = FRD x, sensor z = -FRD z
    def sensor(v):
        return np.column_stack([v[:, 1], v[:, 0], -v[:, 2]])

    acc, gyr, mag = sensor(rec.acc) / GRAVITY, np.degrees(sensor(rec.gyr)), sensor(rec.mag)
    lines = ["Logger v2", "exported 2025-01-01", "Time [ms];AccX;AccY;AccZ;GyrX;GyrY;GyrZ;MagX;MagY;MagZ;Temp"]
    for k in range(rec.n):
        values = [rec.t[k] * 1e3, *acc[k], *gyr[k], *mag[k], 21.5]
        lines.append(";".join(repr(float(v)).replace(".", ",") for v in values))
    return "\n".join(lines) + "\n"


def test_a_time_column_in_minutes_is_declared_or_named(walk, tmp_path):
    p = tmp_path / "minutes.csv"
    pd.DataFrame({"T": walk.t / 60.0, **{f"a{i}": walk.acc[:, i] for i in range(3)},
                  **{f"w{i}": walk.gyr[:, i] for i in range(3)}}).to_csv(p, index=False)
    blocks = "acc: {columns: [a0, a1, a2], unit: m/s^2}\ngyr: {columns: [w0, w1, w2], unit: rad/s}\naxes: [x, y, z]\n"
    (tmp_path / "minutes.csv.footzoo.yaml").write_text("time: {column: T, unit: s}\n" + blocks)
    with pytest.raises(RecordingError, match=r"are the time stamps in min\?.*multiply t by 60.*unit: min"):
        load(p)
    (tmp_path / "minutes.csv.footzoo.yaml").write_text("time: {column: T, unit: min}\n" + blocks)
    np.testing.assert_allclose(load(p).t, walk.t, rtol=1e-12, atol=1e-12)


def test_a_described_csv_comes_back_in_frd_si(walk, tmp_path):
    p = tmp_path / "walk.csv"
    p.write_text(generic_text(walk))
    (tmp_path / "walk.csv.footzoo.yaml").write_text(SIDECAR)
    assert detect_format(p) == "generic"
    rec = load(p)
    np.testing.assert_allclose(rec.t, walk.t, rtol=1e-15, atol=1e-12)
    np.testing.assert_allclose(rec.acc, walk.acc, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(rec.gyr, walk.gyr, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(rec.mag, walk.mag, rtol=1e-13, atol=1e-12)
    assert rec.meta["subject"] == "S07" and rec.meta["code"] == "1e3" and rec.meta["foot"] == "left"
    assert rec.truth.closed_loop and rec.meta["axes"] == "[y, x, -z]"
    assert str(tmp_path / "walk.csv.footzoo.yaml") in rec.meta["input_files"]


def test_a_rotation_matrix_and_a_shared_description_without_header(walk, tmp_path):
    pitch = np.radians(30.0)  # the sensor pitched 30° nose-up on the foot: FRD = Ry(30°) · sensor
    R = np.array([[np.cos(pitch), 0, np.sin(pitch)], [0, 1, 0], [-np.sin(pitch), 0, np.cos(pitch)]])
    sensor_acc, sensor_gyr = walk.acc @ R, walk.gyr @ R  # sensor = Rᵀ · FRD, row vectors
    p = tmp_path / "raw.txt"
    p.write_text("\n".join(" ".join(repr(float(v)) for v in (*a, *g)) for a, g in zip(sensor_acc, sensor_gyr,
                                                                                        strict=True)) + "\n")
    desc = tmp_path / "lab.yaml"
    desc.write_text(f"time: {{rate: 250}}\nacc: {{columns: [0, 1, 2], unit: m/s^2}}\n"
                    f"gyr: {{columns: [3, 4, 5], unit: rad/s}}\naxes: {R.tolist()}\ndelimiter: ' '\nheader: false\n")
    rec = load(p, format="generic", sidecar=desc)
    np.testing.assert_allclose(rec.acc, walk.acc, atol=1e-12)
    np.testing.assert_allclose(rec.gyr, walk.gyr, atol=1e-12)
    np.testing.assert_allclose(rec.t, np.arange(walk.n) / 250.0)


@pytest.mark.parametrize("change, fragment", [
    ("axes: [x, y, -z]", r"axes: the axis map \[x, y, -z\] is left-handed"),
    ("axes: [x, x, z]", "sensor axis x is used twice"),
    ("axes: [[1, 0, 0], [0, 1, 0], [0, 0.5, 1]]", "is not a rotation"),
    ("axes: [x, -w, z]", "'-w' is not a sensor axis"),
    ("acc: {columns: [AccX, AccY, AccZ], unit: G}", r"acc.unit: 'G' is not supported; use one of"),
    ("acc: {columns: [AccX, AccY, AccZ]}", "acc.unit: missing"),
    ("time: {column: Time, unit: ms}", r"column\(s\) \['Time'\] named in walk.csv.footzoo.yaml are not in the file "
                                       r"\(did you mean 'Time \[ms\]'\?\)"),
    ("time: {column: 'Time [ms]', unit: minutes}", "'minutes' is not a time unit"),
    ("gyro: {columns: [GyrX, GyrY, GyrZ], unit: deg/s}", r"unknown key \(did you mean 'gyr'\?\)"),
    ("delimiter: ','", "the decimal mark cannot be the delimiter too"),
])
def test_a_wrong_description_is_refused_with_the_key_and_the_fix(walk, tmp_path, change, fragment):
    p = tmp_path / "walk.csv"
    p.write_text(generic_text(walk))
    key = change.split(":")[0]
    lines = [ln for ln in SIDECAR.splitlines() if not ln.startswith(f"{key}:")] + [change]
    (tmp_path / "walk.csv.footzoo.yaml").write_text("\n".join(lines) + "\n")
    with pytest.raises(FormatError, match=fragment):
        load(p)


def test_the_axis_map_parser_on_its_own():
    np.testing.assert_array_equal(parse_axes("x, -y, -z"), np.diag([1.0, -1.0, -1.0]))
    np.testing.assert_array_equal(parse_axes(["z", "x", "y"]), [[0, 0, 1], [1, 0, 0], [0, 1, 0]])  # cyclic: proper
    with pytest.raises(FormatError, match="left-handed"):
        parse_axes(["y", "x", "z"])  # a swap alone is a mirror


def test_the_xio_example_described_by_a_sidecar_reads_as_the_xio_reader_reads_it(tmp_path):
    src = data_file("xio_gait_tracking", "short_walk.csv")
    p = tmp_path / "walk.csv"
    shutil.copy(src, p)
    (tmp_path / "walk.csv.footzoo.yaml").write_text(
        "time: {column: Time (s), unit: s}\n"
        "acc: {columns: [Accelerometer X (g), Accelerometer Y (g), Accelerometer Z (g)], unit: g}\n"
        "gyr: {columns: [Gyroscope X (deg/s), Gyroscope Y (deg/s), Gyroscope Z (deg/s)], unit: deg/s}\n"
        "axes: [x, -y, -z]\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(FormatError, match=r"more than one reader recognises this file \(xio, generic\)"):
            load(p)
        described = load(p, format="generic", duplicates="drop")
        dedicated = load(src)
    np.testing.assert_array_equal(described.t, dedicated.t)
    np.testing.assert_array_equal(described.acc, dedicated.acc)
    np.testing.assert_array_equal(described.gyr, dedicated.gyr)


def test_date_time_stamps_and_column_positions_with_a_header(walk, tmp_path):
    stamps = pd.Timestamp("2025-03-01T09:30:00", tz="UTC") + pd.to_timedelta(np.round(walk.t * 1e6), unit="us")
    signals = {f"c{i}": v for i, v in enumerate(np.hstack([walk.acc, walk.gyr]).T)}
    df = pd.DataFrame({"when": stamps.strftime("%Y-%m-%dT%H:%M:%S.%f"), **signals})
    p = tmp_path / "w.csv"
    df.to_csv(p, index=False)
    (tmp_path / "w.csv.footzoo.yaml").write_text("time: {column: when, unit: datetime}\n"
                                                 "acc: {columns: [1, 2, 3], unit: m/s^2}\n"
                                                 "gyr: {columns: [c3, c4, c5], unit: rad/s}\naxes: x, y, z\n")
    rec = load(p)
    np.testing.assert_allclose(rec.t - rec.t[0], np.round(walk.t * 1e6) * 1e-6, rtol=0, atol=5e-7)
    assert rec.t[0] == pd.Timestamp("2025-03-01T09:30:00", tz="UTC").timestamp()
    np.testing.assert_array_equal(rec.acc, walk.acc)


@pytest.mark.parametrize("sep, key", [(";", '";"'), ("\t", '"\\t"')])
def test_a_description_without_the_files_delimiter_names_the_delimiter_to_add(walk, tmp_path, sep, key):
    p = tmp_path / "walk.csv"
    table = np.column_stack([walk.t, walk.acc, walk.gyr])
    np.savetxt(p, table, delimiter=sep, header=sep.join(["t", "ax", "ay", "az", "gx", "gy", "gz"]), comments="")
    desc = ("time: {column: t, unit: s}\nacc: {columns: [ax, ay, az], unit: m/s^2}\n"
            "gyr: {columns: [gx, gy, gz], unit: rad/s}\naxes: [x, y, z]\n")
    (tmp_path / "walk.csv.footzoo.yaml").write_text(desc)
    with pytest.raises(FormatError, match="the header line did not split.*add delimiter: " + re.escape(key)):
        load(p)
    (tmp_path / "walk.csv.footzoo.yaml").write_text(desc + f"delimiter: {key}\n")
    np.testing.assert_allclose(load(p).acc, walk.acc, rtol=1e-6)


def test_the_rate_option_replaces_the_descriptions_time(walk, tmp_path):
    """A shared description that declares the wrong rate (or none): ``rate=`` sets t = row / rate for one file."""
    p = tmp_path / "walk.csv"
    np.savetxt(p, np.column_stack([walk.acc, walk.gyr]), delimiter=",", header="ax,ay,az,gx,gy,gz", comments="")
    blocks = "acc: {columns: [ax, ay, az], unit: m/s^2}\ngyr: {columns: [gx, gy, gz], unit: rad/s}\naxes: [x, y, z]\n"
    (tmp_path / "lab.yaml").write_text("time: {rate: 120}\n" + blocks)
    (tmp_path / "untimed.yaml").write_text(blocks)  # no time at all: the option gives it
    rate = 1.0 / float(np.median(np.diff(walk.t)))
    for side in ("lab.yaml", "untimed.yaml"):
        rec = load(p, sidecar=tmp_path / side, rate=rate)
        np.testing.assert_allclose(rec.t, np.arange(walk.n) / rate)
    with pytest.raises(FormatError, match=r"rate=-3: must be the sampling rate in Hz"):
        load(p, sidecar=tmp_path / "lab.yaml", rate=-3)
    with pytest.raises(FormatError, match="untimed.yaml: time: missing"):
        load(p, sidecar=tmp_path / "untimed.yaml")


def test_a_file_without_its_description_is_told_what_to_describe(walk, tmp_path):
    p = tmp_path / "walk.csv"
    np.savetxt(p, np.column_stack([walk.acc, walk.gyr])[:10], delimiter=",", header="ax_g,ay_g,az_g,gx,gy,gz",
               comments="")
    with pytest.raises(FormatError, match=r"no description walk.csv.footzoo.yaml next to it.*the file begins "
                                          r"'ax_g,ay_g,az_g,gx,gy,gz': name its columns under time"):
        load(p, format="generic")
    # a description passed by path that is not there is named as such, not as one missing next to the file
    for side, what in ((tmp_path / "nowhere" / "lab.yaml", "does not exist"), (tmp_path, "is a folder")):
        with pytest.raises(FormatError, match=rf"walk.csv: its description sidecar=.*{what}; pass the path of a "
                                              "description file"):
            load(p, sidecar=side)
