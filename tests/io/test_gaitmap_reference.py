"""gaitmap's motion-capture stride reference (footzoo.io.gaitmap_reference): its definition on a hand-built
walk, and on the real sample what the stride lengths do not depend on (skipped without ../shared/data)."""

import numpy as np
import pandas as pd
import pytest

from footzoo.io.gaitmap_reference import IMU_RATE, MOCAP_RATE, reference_stride_positions, reference_strides

from ..conftest import data_file

STANCE, SWING = 0.5, 0.6  # s
MARKERS = ("L_TOE", "R_TOE", "L_FCC", "R_FCC", "R_FM5", "L_FM5")


def write_walk(folder, stances_mm, toe_angle_deg):
    """A mocap file and a stride-event file of one foot per side standing on ``stances_mm`` (K, 2) in turn.

    The heel stands still for ``STANCE`` s at each point and moves in a straight line between them
    in ``SWING`` s; the toe marker is 200 mm ahead of the heel, turned ``toe_angle_deg`` (left foot:
    counter-clockwise seen from above, right foot: clockwise) from the direction of the stride that
    ended at the stance (the first stance: of the first stride).
    Events as gaitmap writes them (IMU samples at 204.8 Hz): ``start``/``end`` the middles of two
    stances, ``pre_ic`` and ``ic`` their first instants, ``tc`` the end of the first.
    """
    p = np.asarray(stances_mm, float)
    period = STANCE + SWING
    t = np.arange(0.0, len(p) * period + 0.5, 1.0 / MOCAP_RATE)
    k = np.minimum((t // period).astype(int), len(p) - 1)
    phase = np.clip((t - k * period - STANCE) / SWING, 0.0, 1.0)
    nxt = np.minimum(k + 1, len(p) - 1)
    heel = p[k] + phase[:, None] * (p[nxt] - p[k])
    heading = np.arctan2(*(np.diff(p, axis=0)[:, ::-1].T))
    heading = np.insert(heading, 0, heading[0])[k]  # at each stance, the direction of the stride arriving there
    cols, rows = [], []
    for name in MARKERS:
        sign = 1.0 if name.startswith("L") else -1.0
        if name.endswith("FCC"):
            xy = heel
        else:
            a = heading + sign * np.radians(toe_angle_deg)
            xy = heel + 200.0 * np.column_stack([np.cos(a), np.sin(a)])
        cols.append(name)
        rows.append(np.column_stack([xy, np.full(len(t), 40.0)]))
    table = np.hstack(rows)
    lines = ["," + ",".join(c for c in cols for _ in range(3)), "," + ",".join(["x", "y", "z"] * len(cols))]
    lines += [f"{i}," + ",".join(f"{v:.4f}" for v in row) for i, row in enumerate(table)]
    (folder / "mocap_sample.csv").write_text("\n".join(lines) + "\n")
    ev = []
    for foot in ("left", "right"):
        for i in range(len(p) - 1):
            mid0, mid1 = i * period + STANCE / 2, (i + 1) * period + STANCE / 2
            ev.append({"s_id": len(ev), "foot": foot, "start": mid0 * IMU_RATE, "end": mid1 * IMU_RATE,
                       "ic": (i + 1) * period * IMU_RATE, "tc": (i * period + STANCE) * IMU_RATE,
                       "min_vel": mid0 * IMU_RATE, "pre_ic": i * period * IMU_RATE})
    pd.DataFrame(ev).round().to_csv(folder / "stride_events_sample.csv", index=False)


@pytest.mark.parametrize("foot", ["left", "right"])
def test_a_hand_built_walk_gives_the_heel_displacement_between_the_minimum_velocity_events(tmp_path, foot):
    stances = [[0, 0], [1400, 0], [2700, 0], [4000, 0], [4000, 1200]]  # mm; the last stride turns by 90°
    write_walk(tmp_path, stances, toe_angle_deg=8.0)
    ref = reference_strides(tmp_path, foot)
    np.testing.assert_allclose(ref["stride_length_m"], [1.4, 1.3, 1.3, 1.2], atol=1e-6)
    np.testing.assert_allclose(np.degrees(ref["heading_rad"]), [0, 0, 0, 90], atol=1e-6)
    np.testing.assert_allclose(np.degrees(ref["fpa_rad"]), 8.0, atol=1e-4)  # toe-out positive on both feet
    assert ref["turn"].tolist() == [False, False, True, True]  # > 20° against a neighbour
    period = STANCE + SWING
    k = np.arange(4)
    np.testing.assert_allclose(ref["ms_start_s"], k * period + STANCE / 2, atol=1 / IMU_RATE)
    # the heel marker stays at one height (no descent to end): the contacts are the event file's ICs
    np.testing.assert_allclose(ref["start_s"], k * period, atol=1 / IMU_RATE)  # pre_ic
    np.testing.assert_allclose(ref["to_s"], k * period + STANCE, atol=1 / IMU_RATE)  # tc
    np.testing.assert_allclose(ref["end_s"], (k + 1) * period, atol=1 / IMU_RATE)  # ic
    np.testing.assert_allclose(ref["largest_pitch_s"], (k + 1) * period, atol=1 / IMU_RATE)  # ic


def test_heel_touchdown_is_where_the_markers_descent_stops():
    """Hand-made heel heights at 100 Hz: down at 0.3 m/s until 1.020 s, then resting; the file's IC at 1.000 s.

    The spline's vertical velocity is back above −0.02 m/s within a sample of the kink: 1.020 s ± 10 ms. A heel
    that does not come down (no air phase) and an IC the markers do not cover keep the file's IC.
    """
    from footzoo.io.gaitmap_reference import heel_touchdowns

    t = np.arange(0.0, 2.0, 0.01)
    z = 0.05 + 0.3 * np.clip(1.02 - t, 0.0, None)
    got = heel_touchdowns(z, np.array([1.0]))
    assert got[0] == pytest.approx(1.02, abs=0.01)
    assert heel_touchdowns(np.full(len(t), 0.05), np.array([1.0]))[0] == 1.0
    assert heel_touchdowns(z, np.array([1.97]))[0] == 1.97


def test_a_stance_instant_moved_within_the_stance_leaves_the_hand_built_length(tmp_path):
    """The heel stands still through the stance, so the instant inside it does not matter."""
    write_walk(tmp_path, [[0, 0], [1400, 0], [2800, 0]], toe_angle_deg=0.0)
    base = reference_strides(tmp_path, "left")["stride_length_m"].to_numpy()
    for lag in (-0.15, 0.15):  # within the 0.5 s stance, 0.1 s mean windows included
        np.testing.assert_allclose(reference_strides(tmp_path, "left", lag=lag)["stride_length_m"], base, atol=1e-9)


@pytest.mark.parametrize("foot", ["left", "right"])
def test_the_real_reference_is_gaitmaps_own_per_stride_heel_trajectory(foot):
    """The end point of gaitmap's per-stride trajectories (position_sample.csv) is the reference's length."""
    folder = data_file("gaitmap_example", "mocap_sample.csv").parent
    ref = reference_strides(folder, foot)
    last = reference_stride_positions(folder, foot).groupby("stride").last()
    assert len(last) == len(ref)
    own = np.hypot(last["pos_x_m"], last["pos_y_m"])
    np.testing.assert_allclose(own, ref["stride_length_m"].to_numpy()[last.index], atol=1e-3)  # measured 0.3 / 0.6 mm


@pytest.mark.parametrize("foot", ["left", "right"])
def test_the_real_lengths_depend_neither_on_the_stance_instant_nor_on_the_marker(foot):
    """What an estimate's stride could differ from the reference by, besides its own error, measured on the walk.

    The estimated stride runs from the middle of one detected stance to the next, up to 0.15 s from
    gaitmap's minimum-velocity instants, and measures the sensor, not the heel marker: on the straight
    strides neither moves the reference by more than a centimetre, against per-stride errors of 5 cm.
    """
    folder = data_file("gaitmap_example", "mocap_sample.csv").parent
    ref = reference_strides(folder, foot)
    straight = ~ref["turn"].to_numpy()
    base = ref["stride_length_m"].to_numpy()
    for lag in (-0.1, 0.1):
        moved = reference_strides(folder, foot, lag=lag)["stride_length_m"].to_numpy()
        assert np.abs(moved - base).max() < 0.005  # measured 2.9 / 4.2 mm
    mocap = pd.read_csv(folder / "mocap_sample.csv", header=[0, 1], index_col=0)
    toe = mocap[f"{foot[0].upper()}_TOE"][["x", "y"]].to_numpy() / 1000.0

    def at(t: float) -> np.ndarray:
        k = int(round(t * MOCAP_RATE))
        return toe[max(k - 5, 0):k + 5].mean(axis=0)

    toe_length = np.array([np.hypot(*(at(r.ms_end_s) - at(r.ms_start_s))) for r in ref.itertuples()])
    assert np.abs(toe_length - base)[straight].max() < 0.01  # measured 6.7 / 3.7 mm
