"""A study on a recording with measured footprints (Köroğlu's kind): its trajectories drawn in their frame."""

from __future__ import annotations

import dataclasses

import matplotlib
import numpy as np
import pytest

from footzoo import Pipeline
from footzoo.evaluation.metrics import estimated_footprints
from footzoo.sim import simulate
from footzoo.studies.report import trajectories_figure
from footzoo.studies.runner import _on_footprints

matplotlib.use("Agg")

CONFIG = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"}, "corrections": [{"type": "zupt"}]}


def _turned(points: np.ndarray, angle: float, shift: tuple[float, float], mirror: bool) -> np.ndarray:
    """``points`` (N, 2+) rotated by ``angle`` (rad), their east axis flipped first when ``mirror``, then shifted."""
    p = np.asarray(points, float)[:, :2] * ([1.0, -1.0] if mirror else [1.0, 1.0])
    c, s = np.cos(angle), np.sin(angle)
    return p @ np.array([[c, -s], [s, c]]).T + np.asarray(shift)


@pytest.fixture(scope="module")
def walk():
    """A simulated walk and its run, the footprints given in other floor axes: turned 40°, mirrored, shifted."""
    rec = simulate(path="rectangle", length=6.0, width=3.0, rate=100.0)
    res = Pipeline.from_dict(CONFIG).run(rec)
    fp = _turned(estimated_footprints(res.steps), np.radians(40.0), (12.0, -3.0), mirror=True)
    rec = dataclasses.replace(rec, truth=dataclasses.replace(rec.truth, footprints=fp, pos=None))
    return rec, res, fp


def test_the_trajectory_goes_into_the_footprints_frame_by_the_metrics_alignment(walk):
    """By hand: the footprints are the run's own, turned, mirrored and shifted; so the stored trajectory is the
    run's positions moved the same way, to the micrometre (the cache rounds to 0.1 mm)."""
    rec, res, fp = walk
    out = _on_footprints(rec, res, res.pos, step=1)
    np.testing.assert_array_equal(out["footprints"], fp)
    on = out["trajectory_on_footprints"]
    np.testing.assert_allclose(on[:, 1:3], _turned(res.pos, np.radians(40.0), (12.0, -3.0), mirror=True),
                               atol=1e-4)
    np.testing.assert_allclose(on[:, 3], res.pos[:, 2], atol=1e-4)  # the height as estimated


def test_footprints_that_do_not_pair_move_nothing(walk):
    rec, res, fp = walk
    fewer = dataclasses.replace(rec, truth=dataclasses.replace(rec.truth, footprints=fp[:-2]))
    assert set(_on_footprints(fewer, res, res.pos, step=1)) == {"footprints"}
    assert _on_footprints(dataclasses.replace(rec, truth=None), res, res.pos, step=1) == {}
    holed = fp.copy()
    holed[3] = np.nan  # a footprint not measured: nothing to align on, and the run is not failed for it
    holey = dataclasses.replace(rec, truth=dataclasses.replace(rec.truth, footprints=holed))
    assert set(_on_footprints(holey, res, res.pos, step=1)) == {"footprints"}


def test_the_study_figure_draws_the_footprints_and_says_what_it_left_out(walk):
    rec, res, fp = walk
    paired = {"key": "a", "trajectory": np.column_stack([rec.t, res.pos]),
              **_on_footprints(rec, res, res.pos, step=1)}
    unpaired = {"key": "b", "trajectory": np.column_stack([rec.t, res.pos]), "footprints": fp}
    fig = trajectories_figure([paired, unpaired], {"a": "paired", "b": "unpaired"}, "walk")
    ax = fig.axes[0]
    crosses = [line for line in ax.lines if line.get_marker() == "x"]
    assert len(crosses) == 1 and len(crosses[0].get_xdata()) == len(fp)
    np.testing.assert_allclose(crosses[0].get_xdata(), fp[:, 1])  # east across, north up
    drawn = [line.get_label() for line in ax.lines if line.get_marker() != "x"]
    assert drawn == ["paired"]
    assert "measured footprints" in ax.get_title() and "1 run(s)" in ax.get_title()
