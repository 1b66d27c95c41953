"""One chain of stages for a batch run and a stream: one assembly, one interface, batch code on a whole recording."""

import inspect
from pathlib import Path

import numpy as np
import pytest

import footzoo
from footzoo import ConfigError, Pipeline, Stream
from footzoo.calibration.hard_iron import HardIron
from footzoo.config import names
from footzoo.plugins.registry import available
from footzoo.runtime import chain, pipeline, stream
from footzoo.runtime.alignment import initial_attitude
from footzoo.runtime.stage import Stage
from footzoo.runtime.stages import (
    BatchNavigationStage,
    CalibrationStage,
    DetectorStage,
    KalmanStage,
    OrientationStage,
)
from footzoo.sim import NoiseModel, simulate

from ..conftest import HARD_IRON_NOT_FITTED

CONFIGS = names("pipeline")
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "plugins"
#: The stages each shipped config has, read off its YAML (calibration; orientation unless `ins` inside a Kalman
#: filter carries the attitude; a Kalman correction such as zupt, or batch corrections).
EXPECTED = {
    "duong2015": [DetectorStage, KalmanStage],
    "duong2015_zupt": [DetectorStage, KalmanStage],
    "duong2015_zupt_height": [DetectorStage, KalmanStage],
    "huang2016": [DetectorStage, OrientationStage, BatchNavigationStage],
    "nguyen2016": [DetectorStage, KalmanStage],
    "nguyen2016_ins_zvu": [DetectorStage, OrientationStage, BatchNavigationStage],
    "nguyen2016_ins_zvu_hdr": [DetectorStage, OrientationStage, BatchNavigationStage],
    "recommended": [DetectorStage, KalmanStage],
    "recommended_live": [DetectorStage, KalmanStage],
    "yun2012": [CalibrationStage, DetectorStage, OrientationStage, BatchNavigationStage],
}


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=4, profile="physical", rate=100.0, noise=NoiseModel(seed=3), distance_sensors=True,
                    clearance=0.1)


@pytest.fixture
def chains(monkeypatch):
    """The stage types of every chain built, by caller (the pipeline's and the stream's module)."""
    made = []

    def spy(module):
        def build(*args, **kwargs):
            built = chain.build_chain(*args, **kwargs)
            made.append((module.__name__, [type(s) for s in built.stages]))
            return built
        monkeypatch.setattr(module, "build_chain", build)

    spy(pipeline)
    spy(stream)
    return made


def test_every_stage_derives_from_the_one_interface():
    with pytest.raises(TypeError):
        Stage()  # abstract
    for cls in (CalibrationStage, DetectorStage, OrientationStage, KalmanStage, BatchNavigationStage):
        assert issubclass(cls, Stage) and not inspect.isabstract(cls), cls.__name__


def test_the_expected_stages_cover_every_shipped_config():
    assert sorted(EXPECTED) == sorted(CONFIGS)


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
@pytest.mark.parametrize("config", CONFIGS)
def test_a_batch_run_and_a_stream_get_their_stages_from_the_one_assembly(walk, chains, config):
    p = Pipeline.from_yaml(config)
    p.run(walk)
    if p.smoother == "rts":  # offline only: the same pipeline with the smoother that streams
        p.smoother = "stepwise"
    Stream(p, rate=walk.rate).run(walk, chunk=50)
    assert [who for who, _ in chains] == ["footzoo.runtime.pipeline", "footzoo.runtime.stream"]
    assert chains[0][1] == chains[1][1] == EXPECTED[config]


def test_a_batch_run_passes_the_recording_through_the_chain_without_copying_it(walk):
    p = Pipeline.from_yaml("nguyen2016")
    ctx = p.context(walk)
    whole = chain.recording_chunk(walk, ctx, p.init["duration"])
    assert whole["t"] is walk.t and whole["acc"] is walk.acc and whole["gyr"] is walk.gyr
    out = chain.build_chain(p, ctx, whole, whole=True).push(whole, finish=True)
    assert out["t"] is walk.t and out["acc"] is walk.acc and out["gyr"] is walk.gyr
    np.testing.assert_array_equal(out["init"], walk.t <= walk.t[0] + p.init["duration"])


def test_a_non_causal_user_detector_runs_in_batch_through_the_chain(walk):
    """The plug-in guide's three-condition detector has no incremental protocol (median filter over the recording):
    one finished chunk is the whole recording, so the detector stage calls its batch ``detect``."""
    config = {"plugins": [str(EXAMPLES / "three_condition_detector.py")], "orientation": {"type": "ins"},
              "detector": {"type": "three_condition"}, "corrections": [{"type": "zupt"}]}
    p = Pipeline.from_dict(config)
    assert not p.detector.incremental()
    res = p.run(walk)
    own = available("detector")["three_condition"]().detect(walk.t, walk.acc, walk.gyr)
    np.testing.assert_array_equal(res.diagnostics["detector_stance"], own.stance_)
    np.testing.assert_array_equal(res.diagnostics["detector_statistic"], own.statistic_)
    assert np.isfinite(res.pos).all()
    with pytest.raises(ConfigError, match="does not implement the incremental protocol"):
        Stream(p)


def test_the_stages_reports_land_in_the_diagnostics(walk):
    p = Pipeline.from_yaml("nguyen2016")
    res = p.run(walk, covariance=True)
    d = res.diagnostics
    own = p.detector.clone().detect(walk.t, walk.acc, walk.gyr)  # the detector stage's statistic and stance
    np.testing.assert_array_equal(d["detector_statistic"], own.statistic_)
    np.testing.assert_array_equal(d["detector_stance"], own.stance_)
    stance, guard = p.guards.apply(walk.t, walk.gyr, own.stance_, p.context(walk))  # the guard's report
    np.testing.assert_array_equal(res.stance, stance)
    assert {k: v for k, v in d["guards"].items() if k in guard} == guard
    n = len(walk.t)  # the Kalman stage's: biases, variances, the position's standard deviation, the NIS summary
    assert d["gyro_bias"].shape == (n, 3) and d["acc_bias"].shape == (n, 3)
    assert d["P_diag"].shape[0] == n and d["pos_std"].shape == (n, 3)
    for j in range(3):  # each axis's standard deviation is the root of one of the variances
        assert any(np.allclose(d["pos_std"][:, j] ** 2, var, rtol=1e-12, atol=0) for var in d["P_diag"].T)
    assert d["consistency"] == footzoo.evaluation.metrics.nis_summary(d["nis"], d["nis_rows"])
    np.testing.assert_array_equal(res.samples["pos_std_n"].to_numpy(), d["pos_std"][:, 0])
    assert list(d)[:3] == ["detector_statistic", "detector_stance", "guards"] and list(d)[-2:] == ["sensor", "mounting"]


def test_the_calibration_stage_reports_its_fit_as_the_calibration_does():
    loop = simulate(path="rectangle", n_strides=24, profile="physical", rate=50.0, noise=NoiseModel(seed=1))
    p = Pipeline.from_yaml("yun2012")
    res = p.run(loop)
    fitted = HardIron().calibrate(loop.t, loop.acc, loop.gyr, loop.mag)  # the plug-in alone on the recording
    assert fitted.report_["applied"], fitted.report_
    assert res.diagnostics["calibration"] == [{"type": "hard_iron", **fitted.report_}]
    assert list(res.diagnostics)[-2:] == ["calibration", "mounting"]
    calibrated, reports = p.calibrate(loop)
    assert reports == res.diagnostics["calibration"]
    np.testing.assert_array_equal(calibrated.mag, fitted.mag_)
    # the alignment sees the calibrated magnetometer: the chain's initial attitude is the one of the calibrated start
    q0 = initial_attitude(loop.t, loop.acc, loop.gyr, fitted.mag_, **p.init)
    np.testing.assert_array_equal(res.quat[0], p.orient(calibrated, res.stance, q0)[0])
    # run takes the calibrated recording as it is: not calibrated a second time (a refit on calibrated signals)
    again = p.run(calibrated)
    np.testing.assert_array_equal(again.pos, res.pos)
    assert "calibration" not in again.diagnostics
