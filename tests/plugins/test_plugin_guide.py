"""The plug-in guide's two worked examples (docs/plugins.md, examples/plugins/) work as documented."""

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from footzoo import Pipeline
from footzoo.apps.testing import check_plugin
from footzoo.core.errors import FootzooWarning
from footzoo.evaluation.metrics import stance_scores
from footzoo.plugins.extensions import load_plugins
from footzoo.runtime.stream import Stream
from footzoo.sim import MagneticDisturbance, NoiseModel, simulate

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "plugins"


def _load(name):
    """The example module, loaded as a config's `plugins:` entry loads it."""
    info = load_plugins([str(EXAMPLES / f"{name}.py")], None)[0]
    return sys.modules[info["module"]]


@pytest.fixture(scope="module")
def detector():
    return _load("three_condition_detector").ThreeCondition


@pytest.fixture(scope="module")
def magu():
    return _load("magnetometer_heading_update").MagnetometerHeadingUpdate


def test_both_examples_pass_the_plugin_contract(detector, magu):
    check_plugin(detector)
    check_plugin(magu)


@pytest.mark.parametrize("rate", [100.0, 400.0])
def test_the_three_condition_detector_finds_the_simulated_stances(detector, rate):
    rec = simulate(n_strides=12, profile="physical", rate=rate, noise=NoiseModel(seed=2))
    d = detector().detect(rec.t, rec.acc, rec.gyr)
    scores = stance_scores(d.stance_, rec.truth.stance)
    assert scores["precision"] > 0.9 and scores["recall"] > 0.6, scores


def _drifting_walk(disturbance=None):
    # a 0.3 °/s gyro bias on every axis: a 9-state filter cannot see it and the heading drifts
    noise = NoiseModel(seed=4, gyr_bias=np.radians(0.3))
    return simulate(n_strides=40, profile="physical", rate=100.0, noise=noise, clearance=0.1, disturbance=disturbance)


def _heading_error(res, rec):
    return float(np.degrees(np.abs(np.angle(np.exp(1j * (res.samples["yaw"].to_numpy() - _true_yaw(rec)))))).max())


def _true_yaw(rec):
    w, x, y, z = rec.truth.quat.T
    return np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def test_the_magnetometer_heading_update_removes_the_heading_drift(magu):
    rec = _drifting_walk()
    base = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"}}
    plain = Pipeline.from_dict({**base, "corrections": [{"type": "zupt"}]}).run(rec)
    aided = Pipeline.from_dict({**base, "corrections": [{"type": "zupt"}, {"type": "magnetometer_heading"}]}).run(rec)
    assert _heading_error(plain, rec) > 6.0
    assert _heading_error(aided, rec) < 2.0
    end = lambda r: np.linalg.norm(r.pos[-1, :2] - rec.truth.pos[-1, :2])  # noqa: E731
    assert end(aided) < 0.25 * end(plain)


def test_a_disturbed_field_is_rejected_not_followed(magu):
    # a strong field along east over 10 m of the walk would turn the heading by ~30° if believed
    rec = _drifting_walk(MagneticDisturbance(field=(0.0, 0.25, 0.0), north=(15.0, 25.0), east=(-5.0, 5.0)))
    cfg = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"},
           "corrections": [{"type": "zupt"}, {"type": "magnetometer_heading"}]}
    assert _heading_error(Pipeline.from_dict(cfg).run(rec), rec) < 3.0


@pytest.mark.slow  # compiles the guide's correction for the live engine
def test_the_magnetometer_update_runs_live_like_the_batch(magu):
    rec = _drifting_walk()
    p = Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": "dgp", "min_swing": 0.2},
                            "corrections": [{"type": "zupt"}, {"type": "magnetometer_heading"}]})
    with warnings.catch_warnings():
        warnings.simplefilter("error", FootzooWarning)  # the compiled engine, no fallback
        batch = p.run(rec)
    live = Stream(p).run(rec)
    np.testing.assert_allclose(live["pos"], batch.pos, rtol=0, atol=1e-9 * np.abs(batch.pos).max())


def test_the_guide_yaml_loads_the_example_files_by_path(tmp_path):
    """The guide's YAML: `plugins:` lists the .py files (relative to the YAML file, or absolute)."""
    three, magu = EXAMPLES / "three_condition_detector.py", EXAMPLES / "magnetometer_heading_update.py"
    (tmp_path / "three.yaml").write_text(
        f"plugins: [{three}]\norientation: {{type: madgwick}}\n"
        "detector: {type: three_condition, gyro_max: 0.87}\ncorrections: [{type: zvu_dedrift}]\n")
    (tmp_path / "magu.yaml").write_text(
        f"plugins: [{magu}]\norientation: {{type: ins}}\ndetector: {{type: shoe}}\n"
        "corrections:\n  - {type: zupt}\n  - {type: magnetometer_heading, heading_std: 0.1}\n")
    rec = simulate(n_strides=6, profile="physical", rate=100.0, noise=NoiseModel(seed=1), clearance=0.1)
    for name, path in (("three", three), ("magu", magu)):
        res = Pipeline.from_yaml(tmp_path / f"{name}.yaml").run(rec)
        assert np.isfinite(res.pos).all()
        assert res.config["plugins"] == [str(path)]
