"""Huang et al.'s foot progression angle: hand-built walks with known angles and turns, a yawed simulated sensor."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pytest

from footzoo import Pipeline
from footzoo.analysis.fpa import MAX_HEADING_OFFSET, MAX_PLAUSIBLE_FPA, HuangFPA, heading_offsets
from footzoo.core.conventions import quat_from_euler
from footzoo.core.errors import FootzooWarning
from footzoo.io import load
from footzoo.sim import remount, simulate

from ..conftest import data_file

STANCE, SWING, RATE = 60, 40, 100.0  # samples, samples, Hz
LENGTH = 1.3  # m


def walk(turns: list[float], fpa: float, side: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Time, attitude, positions (NED) and stance of a hand-built walk of ``len(turns)`` strides.

    Stride ``k`` (straight, ``LENGTH`` m) heads ``ψ_k = turns[0] + … + turns[k]`` (rad); footprint ``i``
    between strides ``i − 1`` and ``i`` lies on the line of progression ``(ψ_{i−1} + ψ_i) / 2`` (equal
    strides), and the foot stands turned from it by ``side · fpa`` (toe-out positive; ``side`` +1 right).
    """
    psi = np.cumsum(turns)
    line = np.concatenate([[psi[0]], (psi[:-1] + psi[1:]) / 2, [psi[-1]]])  # one per footprint
    yaw, pos, stance = [], [], []
    here = np.zeros(2)
    for i, direction in enumerate(line):
        foot = direction + side * fpa
        yaw += [foot] * STANCE
        pos += [np.append(here, 0.0)] * STANCE
        stance += [True] * STANCE
        if i == len(psi):
            break
        d = np.array([np.cos(psi[i]), np.sin(psi[i])])
        s = np.arange(1, SWING + 1) / (SWING + 1)
        yaw += list(foot + s * (line[i + 1] + side * fpa - foot))
        pos += [np.append(here + LENGTH * si * d, -0.1 * np.sin(np.pi * si)) for si in s]
        stance += [False] * SWING
        here = here + LENGTH * d
    yaw = np.asarray(yaw)
    quat = quat_from_euler(np.zeros_like(yaw), np.zeros_like(yaw), yaw)
    return np.arange(len(yaw)) / RATE, quat, np.asarray(pos), np.asarray(stance)


def fpa_of(turns: list[float], fpa: float, foot: str = "right", **options) -> HuangFPA:
    t, quat, pos, stance = walk(turns, fpa, 1.0 if foot == "right" else -1.0)
    return HuangFPA(foot=foot, **options).analyze(t, quat, pos, stance, {"name": "hand-built"})


@pytest.mark.parametrize("foot", ["right", "left"])
def test_a_straight_hand_built_walk_gives_its_angle_without_a_warning(foot):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = fpa_of([0.3] + [0.0] * 11, math.radians(8.0), foot)
    assert not a.turning_.any()
    np.testing.assert_allclose(a.heading_offset_[1:], 0.0, atol=1e-12)
    np.testing.assert_allclose(np.degrees(a.fpa_[1:]), 8.0, atol=1e-9)


def test_the_heading_vector_lags_a_steady_turn_by_half_of_it():
    """α = 1: the heading vector is the stride before the footprint, half a turn behind its line of progression."""
    turn = math.radians(20.0)
    a = fpa_of([turn] * 12, math.radians(5.0), alpha=1.0, max_heading_offset=math.pi)
    np.testing.assert_allclose(a.heading_offset_[1:-1], -turn / 2, atol=1e-12)
    assert a.heading_offset_[-1] == pytest.approx(0.0, abs=1e-12)  # the last footprint's line: the stride before it
    np.testing.assert_allclose(a.fpa_[1:-1], math.radians(5.0) + turn / 2, atol=1e-9)  # the turn leaks into the FPA


def test_heading_offsets_are_the_angle_to_the_chord_of_the_neighbouring_footprints():
    pos = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 0.0]])
    heading = np.array([np.nan, 0.0, math.pi / 2, 0.0])
    got = heading_offsets(pos, np.arange(4), heading)
    # footprint 1: chord (0,0)->(1,1) at 45°; footprint 2: (1,0)->(1,1) at 90°; footprint 3 did not move: NaN
    np.testing.assert_allclose(got[:3], [np.nan, -math.pi / 4, 0.0], atol=1e-12)
    assert np.isnan(got[3])


def test_a_walk_that_turns_at_every_footprint_has_no_fpa_and_says_why():
    with pytest.warns(FootzooWarning, match=r"turns at 12 of 12 footprints.*straight walking.*NaN"):
        a = fpa_of([math.radians(40.0)] * 12, math.radians(8.0))
    assert np.isnan(a.fpa_).all() and a.turning_[1:].all()
    assert "turns at 12 of 12" in a.note_
    t = np.arange(len(walk([0.0] * 12, 0.0)[0])) / RATE
    steps = a.annotate(pd.DataFrame({"end_s": t[a.heel_strikes_[1:]]}), t)
    assert steps["fpa_rad"].isna().all() and "turns" in steps.attrs["notes"]["fpa_rad"]


def test_a_corner_drops_only_the_footprints_on_it_quietly():
    """12 straight strides, a 90° corner over three footprints, 12 straight: the corner's FPAs NaN, the rest kept."""
    corner = math.radians(30.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = fpa_of([0.0] * 12 + [corner] * 3 + [0.0] * 12, math.radians(-6.0), "left")
    offsets = np.degrees(np.abs(a.heading_offset_))
    assert a.turning_.sum() >= 3 and np.all(offsets[a.turning_] > math.degrees(MAX_HEADING_OFFSET))
    kept = np.isfinite(a.fpa_)
    assert kept.sum() >= 20
    np.testing.assert_allclose(np.degrees(a.fpa_[kept]), -6.0, atol=math.degrees(MAX_HEADING_OFFSET))
    np.testing.assert_allclose(np.degrees(a.fpa_[1:11]), -6.0, atol=1e-9)  # before the corner: exact


@pytest.fixture(scope="module")
def simulated():
    """A straight simulated walk, right foot, 8° toe-out, its sensor's x axis along the foot."""
    return simulate(n_strides=12, fpa=math.radians(8.0), foot="right", rate=100.0)


def _truth_fpa(rec) -> HuangFPA:
    truth = rec.truth
    return HuangFPA(foot="right").analyze(rec.t, truth.quat, truth.pos, truth.stance, {"name": "simulated"})


def test_a_sensor_along_the_foot_measures_the_simulated_angle(simulated):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = _truth_fpa(simulated)
    kept = a.fpa_[np.isfinite(a.fpa_)]
    assert len(kept) >= 10
    np.testing.assert_allclose(np.degrees(kept), 8.0, atol=0.05)


def test_a_sensor_turned_on_the_foot_is_named_with_its_fix(simulated):
    """The sensor turned 50° toward the foot's right (footzoo.sim.remount): the FPA measures its x axis, 8 + 50°."""
    yaw = math.radians(50.0)
    m = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    with pytest.warns(FootzooWarning, match=r"\+58°.*not along the foot.*calibrat.*foot_vector"):
        a = _truth_fpa(remount(simulated, m))
    kept = a.fpa_[np.isfinite(a.fpa_)]
    np.testing.assert_allclose(np.degrees(kept), 58.0, atol=0.05)
    # the foot's long axis in sensor axes, as the warning says: the foot's own angle again, quietly
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        b = HuangFPA(foot="right", foot_vector=[math.cos(yaw), -math.sin(yaw), 0.0]).analyze(
            simulated.t, remount(simulated, m).truth.quat, simulated.truth.pos, simulated.truth.stance, {})
    np.testing.assert_allclose(np.degrees(b.fpa_[np.isfinite(b.fpa_)]), 8.0, atol=0.05)


def _run_with_fpa(rec):
    cfg = Pipeline.from_yaml("recommended").to_dict()
    cfg["analysis"] = [{"type": "huang_fpa"}]
    return Pipeline.from_dict(cfg).run(rec)


def test_pyshoes_room_walk_turns_at_every_footprint_and_says_so():
    """The trial that read 28°–129° without a word: it circles the room, turning 36°–95° at each stride."""
    rec = load(data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat"))
    with pytest.warns(FootzooWarning, match=r"huang_fpa: recording '2017-11-22-11-22-03': the walk turns at"):
        res = _run_with_fpa(rec)
    assert res.steps["fpa_rad"].isna().all()
    assert "turns" in res.metric_notes["fpa_mean_deg"]


def test_gaitmaps_straight_walk_keeps_its_fpa_quietly():
    rec = load(data_file("gaitmap_example", "imu_sample.csv"), foot="left")
    with warnings.catch_warnings():
        warnings.simplefilter("error", FootzooWarning)
        res = _run_with_fpa(rec)
    fpa = res.steps["fpa_rad"].to_numpy()
    assert np.isfinite(fpa).sum() >= 25  # the turn's strides dropped, the straight ones kept
    assert abs(np.degrees(np.nanmedian(fpa))) < math.degrees(MAX_PLAUSIBLE_FPA)
