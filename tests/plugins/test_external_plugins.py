"""Plug-ins defined outside the package are first-class: every engine, the stream, the same numbers."""

import importlib.util
import sys
import textwrap
import warnings

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.core.errors import FootzooWarning
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=10, profile="physical", rate=100.0, noise=NoiseModel(seed=5), clearance=0.1)


def _import(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def external(tmp_path_factory):
    path = tmp_path_factory.mktemp("plugins") / "my_corrections.py"
    path.write_text(textwrap.dedent('''
        import statistics

        import numpy as np
        import footzoo
        from footzoo.corrections import ZUPT
        from footzoo.filters.measurement import VEL, MeasurementModel
        from footzoo.plugins.base import KalmanCorrection


        @footzoo.register
        class MyZUPT(ZUPT):
            """Duong & Suh's zero-velocity update under another name (test)."""

            name = "test_my_zupt"


        def slow_measure(ctx, rows):
            k, t, nav, w, f, stance, idx, par, mem, data = ctx
            z, H, R, m = rows
            if stance and statistics.fmean([1.0, 1.0]) == 1.0:  # the statistics module: numba cannot compile it
                for i, value in enumerate(nav[7:10]):
                    H[m, idx[VEL] + i] = 1.0
                    z[m] = value
                    R[m] = par[0] ** 2
                    m += 1
            return m


        @footzoo.register
        class PythonZUPT(KalmanCorrection):
            """Zero-velocity update written in plain Python (runs on the reference engine)."""

            name = "test_python_zupt"
            paper = "Duong & Suh 2015, eq. 23"
            observes = ("velocity",)
            units = {"velocity_std": "m/s"}

            def __init__(self, velocity_std: float = 0.01):
                self.velocity_std = velocity_std

            def model(self, samples):
                return MeasurementModel(measure=slow_measure, max_rows=3, par=np.array([self.velocity_std]))
    '''))
    return _import(path, "test_external_my_corrections")


def _pipeline(correction, detector="dgp"):
    return Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": detector, "min_swing": 0.2},
                               "corrections": [{"type": correction}]})


def test_an_external_kalman_correction_runs_everywhere_like_the_builtin_it_copies(walk, external):
    builtin = _pipeline("zupt").run(walk, engine="reference")
    mine = _pipeline("test_my_zupt")
    runs = {engine: mine.run(walk, engine=engine) for engine in ("fast", "reference", "auto")}
    runs["stream"] = Stream(mine).run(walk)
    scale = np.abs(builtin.pos).max()
    for how, res in runs.items():
        pos = res["pos"] if isinstance(res, dict) else res.pos
        assert np.abs(pos - builtin.pos).max() <= 1e-9 * scale, how
    assert runs["auto"].config["engine"] == "fast"
    assert runs["auto"].config["corrections"] == [{"type": "test_my_zupt", "velocity_std": 0.01, "roll_lever": 0.0,
                                                   "hold_after": 2.0, "hold_std": 0.001, "hold_rate": 0.2}]


@pytest.mark.slow
def test_a_correction_that_does_not_compile_falls_back_loudly_and_never_drops(walk, external):
    p = _pipeline("test_python_zupt")
    reference = _pipeline("zupt").run(walk, engine="reference")
    with pytest.warns(FootzooWarning, match=r"correction 'test_python_zupt': measurement model not compilable.*"
                                            r"running the reference engine"):
        auto = p.run(walk, engine="auto")
    assert auto.config["engine"] == "reference"
    np.testing.assert_allclose(auto.pos, reference.pos, rtol=0, atol=1e-9 * np.abs(reference.pos).max())
    with pytest.raises(ConfigError, match=r"engine='fast': correction 'test_python_zupt' cannot be compiled"):
        p.run(walk, engine="fast")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FootzooWarning)
        live = Stream(p).run(walk)
    np.testing.assert_allclose(live["pos"], reference.pos, rtol=0, atol=1e-9 * np.abs(reference.pos).max())


def test_check_plugin_accepts_the_external_corrections(external):
    from footzoo.apps.testing import check_plugin

    check_plugin(external.MyZUPT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FootzooWarning)
        check_plugin(external.PythonZUPT)
