"""Recordings written as the text of each format (x-io, SensorConnect, gaitmap, canonical), for the readers' tests."""

from __future__ import annotations

import warnings

import numpy as np

from footzoo.core.conventions import GRAVITY
from footzoo.io import load


def xio_text(rec) -> str:
    head = "Time (s),Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),Accelerometer X (g)," \
           "Accelerometer Y (g),Accelerometer Z (g)"
    flip = np.array([1.0, -1.0, -1.0])
    rows = np.column_stack([rec.t, np.degrees(rec.gyr * flip), rec.acc * flip / GRAVITY])
    return head + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n"


def sensorconnect_text(rec) -> str:
    dev = "inertial-6253.76535"
    head = ",".join(["Time", *[f"{dev}:scaled{s}{a}" for s in ("Accel", "Gyro") for a in "XYZ"]])
    rows = np.column_stack([rec.t, rec.acc / GRAVITY, rec.gyr])
    return head + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n"


def gaitmap_text(rec, index=None) -> str:
    flip = np.array([1.0, -1.0, -1.0])  # FRD -> gaitmap's foot frame (x toe, y left, z up)
    acc, gyr = rec.acc * flip, np.degrees(rec.gyr * flip)
    cols = [(f"{foot}_sensor", f"{s}_{a}") for s in ("acc", "gyr") for a in "xyz" for foot in ("left",)]
    head = "sensor," + ",".join(c[0] for c in cols) + "\naxis," + ",".join(c[1] for c in cols)
    index = np.arange(rec.n) if index is None else index
    rows = [f"{i}," + ",".join(repr(float(v)) for v in (*acc[k], *gyr[k])) for k, i in enumerate(index)]
    return head + "\n" + "\n".join(rows) + "\n"


def canonical_text(rec) -> str:
    return rec.to_dataframe().to_csv(index=False, float_format="%.17g")


WRITERS = {"canonical": canonical_text, "xio": xio_text, "sensorconnect": sensorconnect_text,
           "gaitmap": gaitmap_text}


def quiet_load(path, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return load(path, **options)
