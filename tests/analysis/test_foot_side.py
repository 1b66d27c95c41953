"""Which foot the sensor is on, read from the walk: hand-made walks, the FPA without a declared side, real walks."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

from footzoo import Pipeline, Result
from footzoo.analysis.foot_side import MIN_STRIDES, infer_foot, swing_arcs
from footzoo.analysis.strides import real_stances
from footzoo.core.errors import FootzooWarning
from footzoo.io import load
from footzoo.sim import NoiseModel, simulate

from ..conftest import DATA, data_file

STANCE, SWING = 50, 40  # samples


def walk(arcs: list[float], length: float = 1.4, turn: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Positions (NED) and stance of a hand-made walk: stride k swings with a lateral arc ``arcs[k]`` (m, + right).

    The foot stands, then swings to the next footprint ``length`` ahead along a sine-shaped arc; the
    direction of travel turns by ``turn`` (rad) at every footprint.
    """
    pos, stance = [], []
    here, heading = np.zeros(2), 0.0
    for a in [*arcs, None]:
        pos += [np.append(here, 0.0)] * STANCE
        stance += [True] * STANCE
        if a is None:
            break
        d = np.array([np.cos(heading), np.sin(heading)])
        right = np.array([-d[1], d[0]])
        s = np.arange(1, SWING + 1) / (SWING + 1)
        pos += [np.append(here + length * si * d + a * np.sin(np.pi * si) * right, -0.1 * np.sin(np.pi * si))
                for si in s]
        stance += [False] * SWING
        here, heading = here + length * d, heading + turn
    return np.array(pos), np.array(stance)


def test_the_swing_arc_of_a_hand_made_walk():
    pos, stance = walk([0.02] * 8)
    arc, straight = swing_arcs(pos, real_stances(stance, pos))
    # the mean of a·sin(π s) over the swing's samples: a · mean(sin(π s)) (hand-derived, s = k / 41)
    expected = 0.02 * np.mean(np.sin(np.pi * np.arange(1, SWING + 1) / (SWING + 1)))
    np.testing.assert_allclose(arc, expected, rtol=0, atol=1e-12)
    assert straight.tolist() == [False] + [True] * 6 + [False]  # the first and the last have no neighbour


@pytest.mark.parametrize("sign, side", [(1.0, "right"), (-1.0, "left")])
def test_an_outward_arc_names_the_side_with_its_evidence(sign, side):
    arcs = [sign * 0.02] * 10
    arcs[4] = -arcs[4]  # one stride the other way: 6 of 7 straight strides agree
    found = infer_foot(*walk(arcs))
    assert found.side == side and (found.agreeing, found.strides) == (7, 8)
    assert f"arcs to the {side} on 7 of 8 straight strides" in found.reason


def test_no_side_from_a_walk_that_does_not_tell():
    found = infer_foot(*walk([0.02, -0.02] * 5))  # half each way
    assert found.side is None and "at least 80% must agree" in found.reason
    found = infer_foot(*walk([0.02] * (MIN_STRIDES + 1)))  # too short: the first and last stride do not vote
    assert found.side is None
    assert f"swing arc ({MIN_STRIDES - 1} of {MIN_STRIDES + 1} strides are straight" in found.reason
    # walking in a circle of about 3.6 m radius (22° per stride): the curve, not the foot, bends the swing
    found = infer_foot(*walk([0.02] * 12, turn=np.radians(22)))
    assert found.side is None and found.strides == 0


def _huang(rec):
    """``recommended`` with Huang et al.'s FPA analysis (no magnetometer needed), run with the warnings caught."""
    cfg = Pipeline.from_yaml("recommended").to_dict()
    cfg["analysis"] = [{"type": "huang_fpa"}]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = Pipeline.from_dict(cfg).run(rec)
    return res, [str(w.message) for w in caught if issubclass(w.category, FootzooWarning)]


def test_an_unknown_side_leaves_the_fpa_nan_with_the_reason_and_the_rest_of_the_run(tmp_path):
    rec = simulate(n_strides=8, rate=100.0, noise=NoiseModel(seed=1))  # its swing is straight: the walk cannot tell
    declared = _huang(rec)[0]
    rec.meta.pop("foot", None)
    res, warned = _huang(rec)
    assert any("huang_fpa: recording" in w and "every FPA is NaN, the rest of the run is unaffected" in w
               for w in warned)
    assert res.steps["fpa_rad"].isna().all() and "fpa_rad" in res.steps.attrs["notes"]
    pd.testing.assert_frame_equal(res.steps.drop(columns="fpa_rad"), declared.steps.drop(columns="fpa_rad"))
    with pytest.warns(FootzooWarning, match="metrics refused"):
        m = res.metrics
    assert np.isnan(m["fpa_mean_deg"]) and "the foot side is unknown" in res.metric_notes["fpa_mean_deg"]
    assert m["strides"] == declared.metrics["strides"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # saving warns nothing more: the saved metrics keep the reason
        folder = res.save(tmp_path / "run")
    back = Result.load(folder)  # the reason is kept with the result
    assert "the foot side is unknown" in back.metric_notes["median_fpa_deg"]


@pytest.mark.parametrize("foot", ["left", "right"])
def test_gaitmap_feet_are_read_from_the_walk(foot):
    rec = load(data_file("gaitmap_example", "imu_sample.csv"), foot=foot)
    declared, _ = _huang(rec)
    rec.meta.pop("foot")
    res, warned = _huang(rec)
    # measured: 21 of 22 (left) and 24 of 24 (right) straight strides arc outward
    assert any(f"read as the {foot} foot from the walk: the swing arcs to the {foot}" in w for w in warned)
    np.testing.assert_array_equal(res.steps["fpa_rad"], declared.steps["fpa_rad"])  # the same FPA as declared


def ipol(trial: str, foot: str):
    """One foot of an ipol_gait trial (time = PacketCounter / 100 s)."""
    from footzoo import Recording

    df = pd.read_csv(data_file("ipol_gait", f"{trial}_{foot[0]}f.txt"), sep="\t", skiprows=1)
    return Recording(t=df["PacketCounter"].to_numpy(float) / 100.0, acc=df[["Acc_X", "Acc_Y", "Acc_Z"]].to_numpy(float),
                     gyr=df[["Gyr_X", "Gyr_Y", "Gyr_Z"]].to_numpy(float), meta={"name": f"{trial}_{foot}"})


@pytest.mark.slow
@pytest.mark.parametrize("trial", ["6-1", "7-4", "8-6"])
def test_ipol_walkers_feet_are_read_from_the_walk(trial):
    """One trial of each walker, both feet (benchmarks/foot_side.md: 36 of 36 recordings)."""
    if not (DATA / "ipol_gait").exists():
        pytest.skip("shared data not available: ipol_gait")
    pipeline = Pipeline.from_yaml("recommended")
    for foot in ("left", "right"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = pipeline.run(ipol(trial, foot))
        found = infer_foot(res.pos, res.stance)
        assert found.side == foot, found.reason
        assert found.agreement >= 0.9 and found.strides >= MIN_STRIDES


def test_pyshoe_circling_is_left_undecided_not_guessed():
    """PyShoe's trials circle a small room: no straight strides, so no side is named (never a wrong one)."""
    rec = load(data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = Pipeline.from_yaml("recommended").run(rec)
    found = infer_foot(res.pos, res.stance)
    assert found.side is None and found.strides < MIN_STRIDES


def test_the_foot_side_fix_is_the_one_that_applies_where_the_user_is(tmp_path):
    """In Python the loader's ``foot=``, on the command line ``--foot``, in a study the recording entry's ``foot:``."""
    from footzoo.analysis.fpa import HuangFPA
    from footzoo.core.usage import used_from

    pos, stance = walk([0.02, -0.02] * 5)  # half each way: the walk does not tell the side
    t, quat = np.arange(len(pos)) / 100.0, np.tile([1.0, 0.0, 0.0, 0.0], (len(pos), 1))
    fixes = {}
    for place in ("python", "command line", "study"):
        with used_from(place), pytest.warns(FootzooWarning, match="every FPA is NaN") as warned:
            HuangFPA().analyze(t, quat, pos, stance, {"name": "hand-made"})
        fixes[place] = str(warned[0].message)
    assert "footzoo.load(path, foot='right'|'left')" in fixes["python"] and "--foot" not in fixes["python"]
    assert "--foot right|left" in fixes["command line"] and "footzoo.load" not in fixes["command line"]
    assert "the recording entry's foot: key in the study" in fixes["study"]
    assert "--foot" not in fixes["study"] and "footzoo.load" not in fixes["study"]


@pytest.mark.slow
def test_a_study_names_the_recording_entrys_foot_key(tmp_path):
    import yaml

    from footzoo.io.canonical import write
    from footzoo.studies import run_study

    rec = simulate(n_strides=8, rate=100.0, noise=NoiseModel(seed=1))
    rec.meta.pop("foot", None)
    cfg = Pipeline.from_yaml("recommended").to_dict()
    cfg["analysis"] = [{"type": "huang_fpa"}]
    (tmp_path / "fpa.yaml").write_text(yaml.safe_dump(cfg))
    write(rec, tmp_path / "walk.csv")
    study = {"base": str(tmp_path / "fpa.yaml"), "recordings": [{"path": str(tmp_path / "walk.csv")}],
             "metrics": ["fpa_mean_deg"]}
    with pytest.warns(FootzooWarning) as warned:
        run_study(study, out=tmp_path / "out")
    assert any("the recording entry's foot: key in the study" in str(w.message) for w in warned)
    assert not any("--foot" in str(w.message) for w in warned)
