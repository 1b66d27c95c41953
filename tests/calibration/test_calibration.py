"""In-situ calibration stage and the hard-iron block, against hand-made spheres and the simulator's biases."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
import yaml

import footzoo
from footzoo import Pipeline, Recording, register
from footzoo.apps.testing import check_plugin
from footzoo.calibration import HardIron, fit_hard_iron
from footzoo.core.conventions import quat_to_matrix
from footzoo.core.errors import CalibrationWarning, ConfigError, PluginError
from footzoo.plugins.base import Calibration
from footzoo.plugins.registry import build
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate

FIELD = np.array([0.22, 0.05, 0.42])  # NED field (G), inclination about 62°
OFFSET = np.array([0.031, -0.018, 0.012])


def random_rotations(n: int, rng: np.random.Generator) -> np.ndarray:
    """n uniformly random rotation matrices (body -> NED) from random unit quaternions."""
    q = rng.standard_normal((n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return quat_to_matrix(q)


def sphere_readings(n: int = 2000, noise: float = 0.0, seed: int = 1) -> np.ndarray:
    """Body-frame readings of FIELD at random attitudes, plus OFFSET (and white noise)."""
    rng = np.random.default_rng(seed)
    r = random_rotations(n, rng)
    body = np.einsum("nji,j->ni", r, FIELD)  # R^T m_ned
    return body + OFFSET + noise * rng.standard_normal((n, 3))


@pytest.fixture
def scratch_registry(monkeypatch):
    """Test plug-ins registered inside a test are gone after it (the registry is process-wide)."""
    import footzoo.plugins.registry as registry

    registry.available("calibration")  # built-ins loaded first
    monkeypatch.setitem(registry._REGISTRY, "calibration", dict(registry._REGISTRY["calibration"]))


@pytest.fixture(scope="module")
def loop():
    """A simulated rectangle walk (turns) with the paper's magnetometer bias 0.0012 G on every axis."""
    return simulate(path="rectangle", profile="physical", clearance=0.15, noise={"scale": 1}, rate=100)


def test_an_exact_sphere_gives_its_centre_and_radius():
    fit = fit_hard_iron(sphere_readings())
    np.testing.assert_allclose(fit.offset, OFFSET, atol=1e-12)
    assert fit.radius == pytest.approx(np.linalg.norm(FIELD), rel=1e-12)
    assert fit.inliers == 2000
    assert fit.spread == pytest.approx(1 / 3, abs=0.03)  # directions all over the sphere


def test_noise_leaves_the_offset_within_its_standard_error():
    fit = fit_hard_iron(sphere_readings(noise=0.002, seed=3))
    assert np.all(np.abs(fit.offset - OFFSET) < 4 * fit.offset_std)
    assert np.all(fit.offset_std < 2e-4)


def test_magnetic_disturbances_are_left_out_of_the_fit():
    m = sphere_readings(noise=0.001, seed=4)
    m[::8] *= 1.3  # one sample in eight near iron: a stronger field
    clean = fit_hard_iron(sphere_readings(noise=0.001, seed=4))
    fit = fit_hard_iron(m)
    assert fit.inliers <= len(m) - len(m[::8])
    np.testing.assert_allclose(fit.offset, clean.offset, atol=3e-4)
    assert np.linalg.norm(fit.offset - OFFSET) < 5e-4


def test_the_simulators_hard_iron_bias_is_found_on_a_loop(loop):
    fit = fit_hard_iron(loop.mag)
    np.testing.assert_allclose(fit.offset, NoiseModel().mag_bias, rtol=0.1)
    assert fit.spread > HardIron().min_spread


def test_a_straight_walk_is_left_uncalibrated_with_the_reason():
    rec = simulate(n_strides=8, profile="physical", noise={"scale": 1}, rate=100)
    with pytest.warns(CalibrationWarning, match="turned too little"):
        out = HardIron().calibrate(rec.t, rec.acc, rec.gyr, rec.mag)
    assert out.report_["applied"] is False and "min_spread" in out.report_["reason"]
    # passed through, not copied (the view footzoo passes plug-ins is read-only: the recording cannot change)
    assert np.shares_memory(out.mag_, rec.mag) and np.array_equal(out.mag_, rec.mag)


def test_a_pipelines_calibration_warning_names_the_recording():
    """In a run (a study, a session) the warning says which recording was left uncalibrated."""
    rec = simulate(n_strides=4, profile="physical", noise={"scale": 1}, rate=100)
    rec.meta["name"] = "subject7_walk"
    with pytest.warns(CalibrationWarning, match=r"^subject7_walk: hard_iron: magnetometer left uncalibrated"):
        footzoo.Pipeline.from_yaml("yun2012").calibrate(rec)


def test_readings_turned_about_one_axis_only_are_refused_not_a_crash():
    ang = np.linspace(0, 4 * np.pi, 500)  # yaw only, noise-free: the readings lie on one circle
    c, s_ = np.cos(ang), np.sin(ang)
    m = np.column_stack([c * FIELD[0] + s_ * FIELD[1], -s_ * FIELD[0] + c * FIELD[1], np.full_like(ang, FIELD[2])])
    with pytest.warns(CalibrationWarning, match="turned too little"):
        out = HardIron().calibrate(ang, np.zeros((500, 3)), np.zeros((500, 3)), m + OFFSET)
    assert out.report_["applied"] is False and out.mag_ is not None


def test_soft_iron_or_a_disturbed_room_is_refused():
    m = sphere_readings(seed=5) - OFFSET
    m = m * [1.3, 1.0, 0.75] + OFFSET  # strong soft iron: an ellipsoid, which no offset calibrates
    with pytest.warns(CalibrationWarning, match="no sphere"):
        out = HardIron().calibrate(np.arange(len(m)) * 0.01, np.zeros_like(m), np.zeros_like(m), m)
    assert out.report_["applied"] is False and out.mag_ is not None
    mild = sphere_readings(seed=5) - OFFSET
    mild = mild * [1.01, 1.0, 0.99] + OFFSET  # a percent of soft iron: the offset still fits
    assert HardIron().calibrate(np.arange(len(m)) * 0.01, np.zeros_like(m), np.zeros_like(m), mild).report_["applied"]


def test_a_known_offset_is_removed_as_given_and_no_magnetometer_passes_through(loop):
    out = HardIron(offset=[0.1, 0.2, 0.3]).calibrate(loop.t, loop.acc, loop.gyr, loop.mag)
    np.testing.assert_array_equal(out.mag_, loop.mag - [0.1, 0.2, 0.3])
    none = HardIron().calibrate(loop.t, loop.acc, loop.gyr, None)
    assert none.mag_ is None and none.report_ == {"applied": False, "reason": "no magnetometer"}
    assert np.shares_memory(none.acc_, loop.acc) and np.array_equal(none.acc_, loop.acc)
    assert np.shares_memory(none.gyr_, loop.gyr) and np.array_equal(none.gyr_, loop.gyr)


def test_hard_iron_follows_the_plugin_contract():
    check_plugin(HardIron)


def test_bad_parameters_are_refused_with_the_name():
    with pytest.raises(ConfigError, match="offset"):
        build("calibration", {"type": "hard_iron", "offset": [1, 2]})
    with pytest.raises(ConfigError, match="min_spread"):
        HardIron(min_spread=0.5).check_params()


def test_the_pipeline_calibrates_a_copy_and_reports_it(loop):
    rec = copy.deepcopy(loop)
    cfg = yaml.safe_load(footzoo.config.path("yun2012").read_text())
    res = Pipeline.from_dict(cfg).run(rec)
    np.testing.assert_array_equal(rec.mag, loop.mag)  # the caller's recording is unchanged
    (report,) = res.diagnostics["calibration"]
    assert report["type"] == "hard_iron" and report["applied"] is True
    assert res.config["calibration"] == [HardIron().spec()]
    raw = Pipeline.from_dict({k: v for k, v in cfg.items() if k != "calibration"}).run(rec)
    assert "calibration" not in raw.diagnostics
    # Yun et al.'s claim, on the simulator's truth: the calibrated magnetometer closes the loop better
    assert res.metrics["loop_closure_3d_m"] < 0.8 * raw.metrics["loop_closure_3d_m"]


def test_calibration_config_errors_are_clear():
    base = {"orientation": {"type": "madgwick"}, "detector": {"type": "shoe"}}
    with pytest.raises(ConfigError, match="calibration must be a list"):
        Pipeline.from_dict({**base, "calibration": {"type": "hard_iron"}})
    with pytest.raises(ConfigError, match="did you mean 'hard_iron'"):
        Pipeline.from_dict({**base, "calibration": [{"type": "hard_iorn"}]})
    with pytest.raises(ConfigError, match="Calibration"):
        Pipeline(None, None, calibration=["hard_iron"])  # type: ignore[arg-type]


def test_validate_lists_a_bad_calibration_with_the_other_problems():
    from footzoo.runtime.validate import config_errors

    errors = config_errors({"orientation": {"type": "madgwik"}, "detector": {"type": "shoe"},
                            "calibration": [{"type": "hard_iron", "min_spread": 2}]})
    assert len(errors) == 2
    assert any("calibration[0]" in e and "min_spread" in e for e in errors)


def test_a_stream_fits_a_calibration_online_and_its_fit_reproduces_the_batch(loop):
    """Live, hard_iron is fitted on the stream's first seconds; the batch run given that fit gives the same numbers."""
    pipe = Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": "dgp"},
                               "corrections": [{"type": "zupt"}], "calibration": [{"type": "hard_iron"}]})
    s = Stream(pipe, rate=loop.rate, warmup=loop.t[-1] - loop.t[0] - 1.0)
    live = s.run(loop, chunk=25)
    assert s.fits[0]["type"] == "hard_iron" and s.fits[0]["applied"]
    batch = pipe.with_fits(s.fits).run(loop)
    np.testing.assert_allclose(live["pos"], batch.pos, rtol=0, atol=1e-9)
    with pytest.raises(ConfigError, match="give one fit per calibration"):
        pipe.with_fits([])


def test_a_user_calibration_that_breaks_the_contract_is_named(loop, scratch_registry):
    @register
    class Truncate(Calibration):
        """Returns too few samples (a broken plug-in for this test)."""

        name = "test_truncate"
        paper = "none"

        def calibrate(self, t, acc, gyr, mag):
            self.acc_, self.gyr_, self.mag_, self.report_ = acc[:-1], gyr, mag, {}
            return self

    pipe = Pipeline.from_dict({"orientation": {"type": "madgwick"}, "detector": {"type": "shoe"},
                               "calibration": [{"type": "test_truncate"}]})
    with pytest.raises(PluginError, match=r"test_truncate.*calibrate\(\) set acc_ of shape \(\d+, 3\)"):
        pipe.run(loop)


def test_a_user_calibration_correcting_the_gyro_reaches_every_stage(scratch_registry):
    rec = simulate(n_strides=6, profile="physical", noise=NoiseModel(scale=0.0, biases=()), rate=100)
    bias = np.array([0.02, -0.01, 0.015])
    biased = Recording(t=rec.t, acc=rec.acc, gyr=rec.gyr + bias, mag=rec.mag, truth=rec.truth)

    @register
    class KnownGyroBias(Calibration):
        """Subtracts a known gyro bias (rad/s) (a user plug-in for this test)."""

        name = "test_known_gyro_bias"
        paper = "none"
        units = {"bias": "rad/s"}

        def __init__(self, bias: list[float] | None = None):
            self.bias = bias

        def calibrate(self, t, acc, gyr, mag):
            self.acc_, self.gyr_, self.mag_ = acc, gyr - np.asarray(self.bias), mag
            self.report_ = {"bias": list(self.bias)}
            return self

    cfg = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"}, "corrections": [{"type": "zupt"}]}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        clean = Pipeline.from_dict(cfg).run(rec)
        fixed = Pipeline.from_dict({**cfg, "calibration": [{"type": "test_known_gyro_bias",
                                                            "bias": bias.tolist()}]}).run(biased)
    np.testing.assert_allclose(fixed.pos, clean.pos, atol=1e-9)
