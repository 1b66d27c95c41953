"""Every reader takes ``axes``, ``acc_unit`` and ``gyr_unit`` (a sensor mounted otherwise, a logger set to other units);
``sidecar`` chooses the generic format.

Synthetic fixtures: a simulated walk (FRD, SI) is written in each format as a sensor mounted with
another proper rotation would record it, in units other than the format's; each reader, told the
map and the units, must give the walk back. The map is written in footzoo's one notation
(``[z, x, y]``), which every message names and every option parser reads.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.io as sio

from footzoo import FormatError, RecordingError
from footzoo.apps.cli import _reader_option
from footzoo.core.conventions import GRAVITY, axis_map_text
from footzoo.io import READERS, detect_format, load
from footzoo.io.axes import axes_fix, parse_axes
from footzoo.io.registry import BUILTIN
from footzoo.sim import NoiseModel, simulate

from .test_openshoe_generic import openshoe_text

#: The sensor's mounting in the fixtures: FRD x is the sensor's z, FRD y its x, FRD z its y (a cyclic turn).
MOUNT = "[z, x, y]"


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=3, rate=200.0, noise=NoiseModel(seed=5), magnetometer=True)


def sensor(values: np.ndarray) -> np.ndarray:
    """FRD rows as the sensor mounted with :data:`MOUNT` reads them: ``v_sensor = Mᵀ v_FRD`` (rows: ``v M``)."""
    return values @ parse_axes(MOUNT)


def table(*columns: np.ndarray) -> str:
    return "\n".join(",".join(repr(float(v)) for v in row) for row in np.column_stack(columns)) + "\n"


def write_canonical(rec, path):
    head = "t,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n"
    path.write_text(head + table(rec.t, sensor(rec.acc) / GRAVITY, np.degrees(sensor(rec.gyr))))
    return path, {"acc_unit": "g", "gyr_unit": "deg/s"}


def write_xio(rec, path):
    head = ("Time (s),Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),Accelerometer X (g),"
            "Accelerometer Y (g),Accelerometer Z (g)\n")
    path.write_text(head + table(rec.t, sensor(rec.gyr), sensor(rec.acc)))  # rad/s and m/s² under the g/deg/s names
    return path, {"acc_unit": "m/s^2", "gyr_unit": "rad/s"}


def write_sensorconnect(rec, path):
    dev = "inertial-6253.76535"
    head = ",".join(["Time", *[f"{dev}:scaled{s}{a}" for s in ("Accel", "Gyro", "Mag") for a in "XYZ"]]) + "\n"
    path.write_text(head + table(rec.t, sensor(rec.acc), np.degrees(sensor(rec.gyr)), sensor(rec.mag)))
    return path, {"acc_unit": "m/s^2", "gyr_unit": "deg/s"}


def write_gaitmap(rec, path):
    cols = [("left_sensor", f"{s}_{a}") for s in ("acc", "gyr") for a in "xyz"]
    head = "sensor," + ",".join(c[0] for c in cols) + "\naxis," + ",".join(c[1] for c in cols) + "\n"
    index = np.round(rec.t * 204.8)  # gaitmap's time base is the sample index at its rate
    path.write_text(head + table(index, sensor(rec.acc) / GRAVITY, sensor(rec.gyr)))
    return path, {"acc_unit": "g", "gyr_unit": "rad/s", "foot": "left", "rate": 200.0}


def write_pyshoe(rec, path):
    path = path.with_suffix(".mat")
    sio.savemat(path, {"imu": np.hstack([sensor(rec.acc) / GRAVITY, np.degrees(sensor(rec.gyr))]),
                       "ts": rec.t[None, :]})
    return path, {"acc_unit": "g", "gyr_unit": "deg/s"}


def write_openshoe(rec, path):
    path = path.with_name("data_inert.txt")
    # openshoe_text writes its input as a z-up sensor would (file = F · input, F = [x, -y, -z]): the map is M · F
    path.write_text(openshoe_text(type(rec)(t=rec.t, acc=sensor(rec.acc), gyr=sensor(rec.gyr), mag=sensor(rec.mag)),
                                  restart_at=-1))
    return path, {"gyr_unit": "rad/s"}


def write_generic(rec, path):
    path.write_text("T,AX,AY,AZ,GX,GY,GZ\n" + table(rec.t, sensor(rec.acc) * 1000 / GRAVITY, sensor(rec.gyr)))
    path.with_name(path.name + ".footzoo.yaml").write_text(
        "time: {column: T, unit: s}\nacc: {columns: [AX, AY, AZ], unit: g}\n"
        "gyr: {columns: [GX, GY, GZ], unit: deg/s}\naxes: [x, y, z]\n")
    return path, {"acc_unit": "mg", "gyr_unit": "rad/s"}  # the options replace the description's axes and units


def write_xsens(rec, path):
    path = path.with_suffix(".txt")
    rows = np.column_stack([np.arange(rec.n), sensor(rec.acc) / GRAVITY, np.degrees(sensor(rec.gyr)), sensor(rec.mag)])
    head = "PacketCounter\tAcc_X\tAcc_Y\tAcc_Z\tGyr_X\tGyr_Y\tGyr_Z\tMag_X\tMag_Y\tMag_Z\n"
    path.write_text("Acquisition frequency: 200 Hz\n" + head
                    + "\n".join("\t".join(repr(float(v)) for v in row) for row in rows) + "\n")
    return path, {"acc_unit": "g", "gyr_unit": "deg/s"}


WRITERS = {"canonical": write_canonical, "xio": write_xio, "pyshoe": write_pyshoe, "gaitmap": write_gaitmap,
           "sensorconnect": write_sensorconnect, "openshoe": write_openshoe, "xsens": write_xsens,
           "generic": write_generic}


def test_every_builtin_reader_declares_axes_and_the_unit_options():
    assert set(WRITERS) == set(BUILTIN)  # a new reader gets a fixture here
    for name in BUILTIN:
        assert {"axes", "acc_unit", "gyr_unit"} <= set(READERS[name].options), name


@pytest.mark.parametrize("fmt", list(WRITERS))
def test_a_sensor_mounted_otherwise_in_other_units_comes_back_in_frd_si(fmt, walk, tmp_path):
    path, options = WRITERS[fmt](walk, tmp_path / "walk.csv")
    assert detect_format(path) == fmt
    axes = MOUNT if fmt != "openshoe" else axis_map_text(parse_axes(MOUNT) @ parse_axes("[x, -y, -z]"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # openshoe's interpolated magnetometer rows
        rec = load(path, axes=axes, **options)
    tol = 1e-7 if fmt == "openshoe" else 1e-9  # openshoe_text writes 8 decimals
    np.testing.assert_allclose(rec.acc, walk.acc, rtol=0, atol=tol * GRAVITY)
    np.testing.assert_allclose(rec.gyr, walk.gyr, rtol=0, atol=tol)
    assert rec.meta["axes"] == axes
    if fmt == "gaitmap":
        assert rec.meta["foot"] == "left"


@pytest.mark.parametrize("fmt", list(WRITERS))
def test_a_wrong_axis_map_or_unit_is_refused_with_the_option_named(fmt, walk, tmp_path):
    path, options = WRITERS[fmt](walk, tmp_path / "walk.csv")
    with pytest.raises(FormatError, match=r"axes: the axis map \[x, y, -z\] is left-handed"):
        load(path, axes="[x, y, -z]", **options)
    with pytest.raises((FormatError, RecordingError), match=r"acc_unit='ft/s\^2' is not supported"):
        load(path, **{**options, "acc_unit": "ft/s^2"})


def test_the_notation_is_one_and_its_spellings_read_alike():
    rows = parse_axes("[x, -y, -z]")
    for spelling in ("x, -y, -z", "(x, -y, -z)", "x,-y,-z", "x −y −z", ["x", "-y", "-z"],
                     "[[1, 0, 0], [0, -1, 0], [0, 0, -1]]"):
        np.testing.assert_array_equal(parse_axes(spelling), rows)
    # the command line's spellings: quoted with brackets, or bare without
    for arg in ("axes=[x, -y, -z]", "axes=x,-y,-z"):
        name, value = _reader_option(arg)
        assert name == "axes"
        np.testing.assert_array_equal(parse_axes(value), rows)
    assert axis_map_text(rows) == "[x, -y, -z]"
    pitched = parse_axes([[np.cos(0.5), 0, -np.sin(0.5)], [0, 1, 0], [np.sin(0.5), 0, np.cos(0.5)]])
    np.testing.assert_allclose(parse_axes(axis_map_text(pitched)), pitched, atol=1e-6)  # a matrix reads back too
    assert axes_fix(rows) == ("--option 'axes=[x, -y, -z]' on the command line, "
                              'footzoo.load(path, axes="[x, -y, -z]") in Python')


def test_a_sidecar_option_implies_the_generic_format(walk, tmp_path, capsys):
    from footzoo.apps.cli import main

    path, _ = write_generic(walk, tmp_path / "trial.txt")
    shared = tmp_path / "lab.yaml"
    path.with_name(path.name + ".footzoo.yaml").rename(shared)  # one description for many files, not next to them
    with pytest.raises(FormatError, match="cannot tell the format"):
        load(path)
    rec = load(path, sidecar=shared, axes=MOUNT, acc_unit="mg", gyr_unit="rad/s")
    assert rec.meta["format"] == "generic" and str(shared) in rec.meta["input_files"]
    np.testing.assert_allclose(rec.gyr, walk.gyr, rtol=0, atol=1e-9)
    assert detect_format(path, {"sidecar": shared}) == "generic"
    args = ["run", "yun2012", "--data", str(path), "--option", f"sidecar={shared}", "--option", f"axes={MOUNT}",
            "--option", "acc_unit=mg", "--option", "gyr_unit=rad/s"]
    assert main(args) == 0, capsys.readouterr().err
    assert "strides" in capsys.readouterr().out


def test_a_description_without_axes_says_what_axes_means_and_where_the_format_is(walk, tmp_path):
    path, units = write_generic(walk, tmp_path / "trial.txt")
    side = path.with_name(path.name + ".footzoo.yaml")
    side.write_text("".join(line for line in side.read_text().splitlines(keepends=True) if not line.startswith("axes")))
    with pytest.raises(FormatError, match=r"axes: missing: .*forward-right-down.*axes: \[x, y, z\].*"
                                          r"docs/readers/generic\.md"):
        load(path)
    rec = load(path, axes=MOUNT, **units)  # the option that gives the axes instead
    np.testing.assert_allclose(rec.gyr, walk.gyr, rtol=0, atol=1e-9)
