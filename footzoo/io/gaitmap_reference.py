"""Reference stride lengths and foot progression angles from gaitmap's motion-capture sample.

``mocap_sample.csv`` holds markers L/R_TOE, L/R_FCC (heel) and L/R_FM5 in mm at
100 Hz, lab frame with z up; ``stride_events_sample.csv`` holds per stride
``start`` and ``end`` (minimum foot velocity, i.e. mid-stance) in IMU samples at
204.8 Hz. Per stride: the stride length is the horizontal distance the heel
marker moved from ``start`` to ``end`` (each position a 0.1 s mean around the
event); the line of progression is that displacement; the foot progression
angle of the stance at ``end`` is the angle of the heel→toe axis against it,
positive for toe-out (left foot: heel→toe turned counter-clockwise seen from
above; right foot: clockwise).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import FormatError

IMU_RATE = 204.8
MOCAP_RATE = 100.0


def reference_strides(folder: str | Path, foot: str, lag: float = 0.02) -> pd.DataFrame:
    """Per-stride reference from the markers: ``start``, ``end`` (s), ``stride_length`` (m), ``fpa``, ``heading`` (rad).

    Parameters
    ----------
    folder : path
        Folder holding ``mocap_sample.csv`` and ``stride_events_sample.csv``.
    foot : {"left", "right"}
    lag : float
        Motion capture lags the IMU by about 20 ms (cross-correlation).
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

    def around(arr: np.ndarray, t: float) -> np.ndarray:
        k = int(round((t + lag) * MOCAP_RATE))
        return arr[max(k - 5, 0):k + 5].mean(axis=0)

    rows = []
    for _, ev in events[events.foot == foot].iterrows():
        t0, t1 = ev.start / IMU_RATE, ev.end / IMU_RATE
        d = around(heel, t1) - around(heel, t0)
        axis = around(toe, t1) - around(heel, t1)
        prog = np.arctan2(d[1], d[0])
        fpa = sign * np.angle(np.exp(1j * (np.arctan2(axis[1], axis[0]) - prog)))
        rows.append({"start": t0, "end": t1, "stride_length": float(np.hypot(*d)), "fpa": float(fpa),
                     "heading": float(prog)})
    out = pd.DataFrame(rows)
    # a turn stride changes direction by more than 20° against its neighbours
    h = np.unwrap(out["heading"].to_numpy())
    change = np.maximum(np.abs(np.diff(h, prepend=h[0])), np.abs(np.diff(h, append=h[-1])))
    out["turn"] = change > np.radians(20.0)
    return out
