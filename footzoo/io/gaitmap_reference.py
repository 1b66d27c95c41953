"""Reference stride lengths and foot progression angles from gaitmap's motion-capture sample.

``mocap_sample.csv`` holds markers L/R_TOE, L/R_FCC (heel) and L/R_FM5 in mm at
100 Hz, lab frame with z up; ``stride_events_sample.csv`` holds per stride
``start`` and ``end`` (minimum foot velocity, i.e. mid-stance), ``pre_ic`` (the
initial contact before ``start``), ``tc`` (toe-off) and ``ic`` (the initial
contact before ``end``), in IMU samples at 204.8 Hz. These become footzoo's
stride columns ``to_s`` (tc), ``largest_pitch_s`` (ic) and ``ms_start_s``/``ms_end_s`` (the
mid-stances). The event file's ``ic`` marks the foot's largest pitch (the heel→toe markers' pitch
peaks a median 1 ms from it), where the heel is still in the air; the contacts ``start_s`` and
``end_s`` are the heel marker's touch-downs after ``pre_ic`` and ``ic`` (:func:`heel_touchdowns`:
where its descent stops, a median 22 ms later; docs/gait-events.md). Per stride: the stride
length is the horizontal distance the heel marker moved from ``start`` to ``end`` (each position a 0.1 s mean around the
event); the line of progression is that displacement; the foot progression
angle of the stance at ``end`` is the angle of the heel→toe axis against it,
positive for toe-out (left foot: heel→toe turned counter-clockwise seen from
above; right foot: clockwise).

The stride length is gaitmap's (``SpatialParameterCalculation``, after Rampp et
al. 2015 and Kanzler et al. 2015: the horizontal distance between the first and
the last position of the stride) of the heel marker, and agrees with gaitmap's
own per-stride heel trajectories (``position_sample.csv``) to 0.6 mm. The events
are gaitmap's (``gaitmap.example_data.get_healthy_example_stride_events``:
extracted from the motion capture, converted to IMU samples; gaitmap warns that
``min_vel`` need not fall on the IMU's own minimum). footzoo's estimated stride
runs from the middle of one detected stance to the next and measures the sensor,
not the heel; on the straight strides of this walk neither difference moves the
reference by more than a centimetre (both instants moved by 0.1 s: at most
4 mm; the toe marker instead of the heel: at most 7 mm; tests/io/test_gaitmap_reference.py).
The events make one stride of the left
foot's 180° turn from 16.40 s to 18.68 s although the heel stands still for
0.7 s between two steps in it; :func:`footzoo.evaluation.metrics.match_strides` leaves
such a stride unpaired (its borders do not match any one estimated stride).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..core.errors import FormatError

IMU_RATE = 204.8
MOCAP_RATE = 100.0
#: The reference files read from the IMU file's folder.
REFERENCE_FILES = ("mocap_sample.csv", "stride_events_sample.csv", "position_sample.csv")


def has_reference(folder: str | Path) -> bool:
    """True when ``folder`` holds gaitmap's motion-capture reference files."""
    folder = Path(folder)
    return (folder / "mocap_sample.csv").exists() and (folder / "stride_events_sample.csv").exists()


#: The heel marker's descent has stopped once its vertical velocity is back above this (m/s, z up).
STOPPED_DESCENT = -0.02
#: The heel's fastest descent is searched this far (s) around the event file's IC.
DESCENT_SEARCH = 0.06
#: A fastest descent slower than this (m/s, down) is none: the heel did not come down from the air.
LEAST_DESCENT = 0.05


def heel_touchdowns(heel_up: np.ndarray, largest_pitch: np.ndarray, lag: float = 0.0) -> np.ndarray:
    """When the heel marker touches down after each of the event file's ICs (s, the IMU's clock).

    The marker's height ``heel_up`` (m, z up, 100 Hz) through a cubic spline: its fastest descent
    within :data:`DESCENT_SEARCH` of the IC, then the first instant (1 ms steps) its vertical velocity
    is back above :data:`STOPPED_DESCENT`: the heel rests on the floor (a kinematic contact from the
    markers). Where the markers do not cover the search, or the heel does not come down faster than
    :data:`LEAST_DESCENT` (no air phase to end), the event file's IC itself.
    """
    from scipy.interpolate import CubicSpline

    t = np.arange(len(heel_up)) / MOCAP_RATE
    velocity = CubicSpline(t, heel_up).derivative()
    out = np.array(largest_pitch, dtype=float)
    for i, ic in enumerate(out + lag):
        fine = ic + np.arange(-DESCENT_SEARCH, 0.1, 0.001)
        if fine[0] < t[0] or fine[-1] > t[-1]:
            continue
        v = velocity(fine)
        k = int(np.argmin(np.where(fine <= ic + DESCENT_SEARCH, v, np.inf)))
        stopped = np.flatnonzero(v[k:] >= STOPPED_DESCENT)
        if v[k] < -LEAST_DESCENT and len(stopped):
            out[i] = fine[k + stopped[0]] - lag
    return out


def reference_strides(folder: str | Path, foot: str, lag: float = 0.0) -> pd.DataFrame:
    """Per-stride reference: events (s; contacts from the heel marker), ``stride_length_m``, ``fpa_rad``,
    ``heading_rad``, ``turn``.

    Parameters
    ----------
    folder : path
        Folder holding ``mocap_sample.csv`` and ``stride_events_sample.csv``.
    foot : {"left", "right"}
    lag : float
        Delay (s) of the motion capture against the IMU. Cross-correlating the
        foot's sagittal angular rate from the heel->toe markers with the gyro
        gives -2 ms for both feet (correlation 0.99), so the default is 0; the
        marker positions are 0.1 s means, which a 20 ms shift barely changes.
    """
    folder = Path(folder)
    try:
        mocap = pd.read_csv(folder / "mocap_sample.csv", header=[0, 1], index_col=0)
        events = pd.read_csv(folder / "stride_events_sample.csv")
    except FileNotFoundError as err:
        raise FormatError(f"gaitmap reference files missing in {folder}: {err}") from None
    side = "L" if foot == "left" else "R"
    heel = mocap[f"{side}_FCC"][["x", "y"]].to_numpy() / 1000.0
    toe = mocap[f"{side}_TOE"][["x", "y"]].to_numpy() / 1000.0
    sign = 1.0 if foot == "left" else -1.0
    mine = events[events.foot == foot]
    heel_up = mocap[f"{side}_FCC"]["z"].to_numpy() / 1000.0
    contact_end = heel_touchdowns(heel_up, mine["ic"].to_numpy() / IMU_RATE, lag)
    contact_start = heel_touchdowns(heel_up, mine["pre_ic"].to_numpy() / IMU_RATE, lag)

    def around(arr: np.ndarray, t: float) -> np.ndarray:
        k = int(round((t + lag) * MOCAP_RATE))
        return arr[max(k - 5, 0):k + 5].mean(axis=0)

    rows = []
    for i, (_, ev) in enumerate(mine.iterrows()):
        t0, t1 = ev.start / IMU_RATE, ev.end / IMU_RATE
        d = around(heel, t1) - around(heel, t0)
        axis = around(toe, t1) - around(heel, t1)
        prog = np.arctan2(d[1], d[0])
        fpa = sign * np.angle(np.exp(1j * (np.arctan2(axis[1], axis[0]) - prog)))
        rows.append({"start_s": contact_start[i], "to_s": ev.tc / IMU_RATE, "end_s": contact_end[i],
                     "largest_pitch_s": ev.ic / IMU_RATE, "ms_start_s": t0, "ms_end_s": t1,
                     "stride_length_m": float(np.hypot(*d)), "fpa_rad": float(fpa), "heading_rad": float(prog)})
    out = pd.DataFrame(rows)
    # a turn stride changes direction by more than 20° against its neighbours
    h = np.unwrap(out["heading_rad"].to_numpy())
    change = np.maximum(np.abs(np.diff(h, prepend=h[0])), np.abs(np.diff(h, append=h[-1])))
    out["turn"] = change > np.radians(20.0)
    return out


def reference_stride_positions(folder: str | Path, foot: str) -> pd.DataFrame | None:
    """Per-stride trajectories of ``position_sample.csv`` (motion capture, 100 Hz), or None without the file.

    gaitmap's file holds, per stride ``s_id`` of ``stride_events_sample.csv``, the
    position (m) zeroed at the stride's start (its first mid-stance), in a
    right-handed lab frame with z up. Returns ``stride`` (row of
    :func:`reference_strides` for this foot), ``t_s`` (IMU clock, s) and
    ``pos_x_m``, ``pos_y_m``, ``pos_up_m``.
    """
    folder = Path(folder)
    path = folder / "position_sample.csv"
    if not path.exists():
        return None
    pos = pd.read_csv(path)
    events = pd.read_csv(folder / "stride_events_sample.csv")
    ids = events.loc[events.foot == foot, "s_id"].to_numpy()
    start = events.loc[events.foot == foot, "start"].to_numpy() / IMU_RATE
    pos = pos[pos.iloc[:, 0] == f"{foot}_sensor"]
    row = pd.Series(np.arange(len(ids)), index=ids)
    keep = pos["s_id"].isin(ids).to_numpy()
    pos = pos[keep]
    stride = row[pos["s_id"].to_numpy()].to_numpy()
    return pd.DataFrame({"stride": stride, "t_s": start[stride] + pos["sample"].to_numpy() / MOCAP_RATE,
                         "pos_x_m": pos["pos_x"].to_numpy(), "pos_y_m": pos["pos_y"].to_numpy(),
                         "pos_up_m": pos["pos_z"].to_numpy()})

