"""Bad plug-ins: whatever a plug-in does, the process does not crash, the caller's data does not change, and no
broken result passes as one.

Each case is a small plug-in that breaks one rule of the contract (footzoo.plugins.contract): it raises, exits,
forgets ``return self``, returns a wrong shape, NaN, a non-unit quaternion or a NaN "stance", or writes into its
input. Each must give a PluginError naming the plug-in, the method and the cause (chained), in a batch run, live
and on the command line (exit code 4, never "internal error"); in a study only its cells fail.
"""

from __future__ import annotations

import re
import textwrap
import warnings

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import footzoo
from footzoo import Pipeline, PluginError
from footzoo.apps.cli import EXIT_PLUGIN, main
from footzoo.core.errors import ConfigError, PluginImportError
from footzoo.detectors.angular_rate_fsm import AngularRateFSM
from footzoo.io.canonical import write
from footzoo.orientation.madgwick import Madgwick
from footzoo.plugins import registry
from footzoo.plugins.base import Analysis, Calibration, Detector, Orientation, VelocityCorrection
from footzoo.plugins.contract import QUAT_NORM_TOL, checked
from footzoo.plugins.extensions import IMPORT_TIMEOUT_VARIABLE, load_plugins
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=1))


def _still(gyr):
    return np.linalg.norm(gyr, axis=1) < 0.6


# --------------------------------------------------------------------------- the faulty plug-ins
FAULTY: list[type] = []


def faulty(cls: type) -> type:
    """A faulty plug-in of this module: registered while its tests run only (studies of every registered
    combination in other test modules must not meet it)."""
    FAULTY.append(cls)
    return cls


@pytest.fixture(autouse=True, scope="module")
def _registered():
    from footzoo.plugins import registry

    for cls in FAULTY:
        footzoo.register(cls)
    yield
    for cls in FAULTY:
        registry._REGISTRY[cls.kind].pop(cls.name, None)
    registry._REGISTRY["detector"].pop("cli_boom", None)


@faulty
class Raising(Detector):
    """Raises a ZeroDivisionError (a bug in a plug-in)."""

    name = "test_fault_raising"

    def detect(self, t, acc, gyr, ctx=None):
        return 1 / 0


@faulty
class Exiting(Detector):
    """Calls sys.exit() in its action method."""

    name = "test_fault_exiting"

    def detect(self, t, acc, gyr, ctx=None):
        raise SystemExit(0)


@faulty
class NoReturn(Detector):
    """Forgets ``return self``."""

    name = "test_fault_no_return"

    def detect(self, t, acc, gyr, ctx=None):
        self.stance_ = _still(gyr)
        self.statistic_ = np.linalg.norm(gyr, axis=1)


@faulty
class NanStance(Detector):
    """A float stance with NaN where it did not decide (NaN would read as True in a bool cast)."""

    name = "test_fault_nan_stance"

    def detect(self, t, acc, gyr, ctx=None):
        stance = _still(gyr).astype(float)
        stance[::7] = np.nan
        self.stance_, self.statistic_ = stance, np.linalg.norm(gyr, axis=1)
        return self


@faulty
class ShortStance(Detector):
    """One sample short."""

    name = "test_fault_short_stance"

    def detect(self, t, acc, gyr, ctx=None):
        self.stance_, self.statistic_ = _still(gyr)[:-1], np.linalg.norm(gyr, axis=1)
        return self


@faulty
class Mutating(Detector):
    """Writes into its input (gyr[:] = 0) instead of a copy."""

    name = "test_fault_mutating"

    def detect(self, t, acc, gyr, ctx=None):
        gyr -= gyr.mean(axis=0)
        self.stance_, self.statistic_ = _still(gyr), np.linalg.norm(gyr, axis=1)
        return self


@faulty
class LiveNanStance(AngularRateFSM):
    """Yun's FSM whose live chunks carry a NaN stance (a float column)."""

    name = "test_fault_live_nan_stance"

    def step(self, t, acc, gyr):
        out = dict(super().step(t, acc, gyr))
        if len(out.get("stance", ())):
            stance = out["stance"].astype(float)
            stance[0] = np.nan
            out["stance"] = stance
        return out


@faulty
class LiveMutating(AngularRateFSM):
    """Yun's FSM that, live, removes the chunk's mean rate in place."""

    name = "test_fault_live_mutating"

    def step(self, t, acc, gyr):
        gyr -= gyr.mean(axis=0)
        return super().step(t, acc, gyr)


@faulty
class Scaled(Madgwick):
    """Madgwick's filter whose quaternions are multiplied by ``scale`` (not unit when scale ≠ 1)."""

    name = "test_fault_scaled_quat"

    def __init__(self, scale: float = 1.5):
        super().__init__(use_magnetometer=False)
        self.scale = scale

    def step(self, t, acc, gyr, mag, stance):
        out = super().step(t, acc, gyr, mag, stance)
        return {**out, "quat": out["quat"] * self.scale}


@faulty
class NanVelocity(VelocityCorrection):
    """Returns NaN velocities."""

    name = "test_fault_nan_velocity"

    def apply(self, t, acc_nav, stance, ctx=None):
        self.vel_ = np.full((len(t), 3), np.nan)
        self.pos_ = np.zeros((len(t), 3))
        return self


@faulty
class RaisingAnalysis(Analysis):
    """Raises KeyError in analyze."""

    name = "test_fault_analysis"

    def analyze(self, t, quat, pos, stance, meta):
        return meta["no such key"]

    def annotate(self, steps, t):
        return steps


@faulty
class WrongCalibration(Calibration):
    """Returns the accelerometer with a column missing."""

    name = "test_fault_calibration"

    def calibrate(self, t, acc, gyr, mag):
        self.acc_, self.gyr_, self.mag_, self.report_ = acc[:, :2], gyr, mag, {}
        return self


@faulty
class ReturnsAnother(AngularRateFSM):
    """Returns a built-in detector it made, not itself (its results would be read as the plug-in's)."""

    name = "test_fault_returns_another"

    def detect(self, t, acc, gyr, ctx=None):
        return AngularRateFSM().detect(t[:10], acc[:10], gyr[:10])


def _config(**parts):
    base = {"name": "faulty", "orientation": {"type": "madgwick", "use_magnetometer": False},
            "detector": {"type": "angular_rate_fsm"}, "corrections": [{"type": "zvu_dedrift"}]}
    return {**base, **parts}


BATCH = [
    ("raising", _config(detector={"type": "test_fault_raising"}), "detect", "ZeroDivisionError"),
    ("exiting", _config(detector={"type": "test_fault_exiting"}), "detect", "never exit the process"),
    ("no_return", _config(detector={"type": "test_fault_no_return"}), "detect", "return self"),
    # before: the error named the built-in angular_rate_fsm, whose shapes were wrong, not the plug-in
    ("returns_another", _config(detector={"type": "test_fault_returns_another"}), "detect",
     r"returned another AngularRateFSM object, not itself: set the results on self and end detect\(\) with 'return "
     "self'"),
    ("nan_stance", _config(detector={"type": "test_fault_nan_stance"}), "detect", "NaN is not stance"),
    ("short_stance", _config(detector={"type": "test_fault_short_stance"}), "detect", r"shape \(\d+,\)"),
    ("mutating", _config(detector={"type": "test_fault_mutating"}), "detect", "copy it first"),
    ("non_unit_quat", _config(orientation={"type": "test_fault_scaled_quat"}), "estimate", "non-unit quaternions"),
    ("nan_velocity", _config(corrections=[{"type": "test_fault_nan_velocity"}]), "apply", "non-finite"),
    ("analysis", _config(analysis=[{"type": "test_fault_analysis"}]), "analyze", "KeyError"),
    ("calibration", _config(calibration=[{"type": "test_fault_calibration"}]), "calibrate", r"shape \(\d+, 2\)"),
]


@pytest.mark.parametrize("config, method, cause", [c[1:] for c in BATCH], ids=[c[0] for c in BATCH])
def test_a_faulty_plugin_is_a_plugin_error_naming_it_and_the_recording_is_unchanged(config, method, cause, walk):
    before = {k: getattr(walk, k).copy() for k in ("t", "acc", "gyr")}
    with pytest.raises(PluginError, match=cause) as info:
        Pipeline.from_dict(config).run(walk)
    err = info.value
    assert err.method == method and "internal error" not in str(err)
    faulty = [p for p in (config["detector"], config["orientation"], *config["corrections"],
                          *config.get("analysis", []), *config.get("calibration", [])) if "fault" in p["type"]]
    assert faulty[0]["type"] in err.plugin and faulty[0]["type"] in str(err)
    for k, v in before.items():
        np.testing.assert_array_equal(getattr(walk, k), v)


def test_the_original_error_is_chained(walk):
    with pytest.raises(PluginError) as info:
        Pipeline.from_dict(_config(detector={"type": "test_fault_raising"})).run(walk)
    assert isinstance(info.value.__cause__, ZeroDivisionError)


def test_tiny_quaternion_drift_is_accepted_and_the_numbers_are_those_of_the_filter(walk):
    drift = 1 + QUAT_NORM_TOL / 10
    ok = Pipeline.from_dict(_config(orientation={"type": "test_fault_scaled_quat", "scale": drift})).run(walk)
    ref = Pipeline.from_dict(_config(orientation={"type": "test_fault_scaled_quat", "scale": 1.0})).run(walk)
    assert np.isfinite(ok.pos).all() and np.abs(ok.quat - ref.quat * drift).max() < 1e-12


def test_live_a_nan_stance_chunk_is_a_plugin_error(walk):
    stream = Stream(Pipeline.from_dict(_config(detector={"type": "test_fault_live_nan_stance"})), rate=walk.rate)
    with pytest.raises(PluginError, match="NaN is not stance") as info:
        stream.run(walk)
    assert info.value.method == "step"


def test_live_a_mutating_plugin_cannot_change_the_pushed_samples(walk):
    stream = Stream(Pipeline.from_dict(_config(detector={"type": "test_fault_live_mutating"})), rate=walk.rate)
    gyr = walk.gyr.copy()
    with pytest.raises(PluginError, match="copy it first"):
        stream.run(walk)
    np.testing.assert_array_equal(walk.gyr, gyr)


IMPORT_FAILURES = {
    "exits": ("import sys\nsys.exit(0)\n", r"sys.exit\(0\).*never exit the process"),
    # an allocation too large at import is the plug-in's, not "use a smaller recording"
    "out_of_memory": ("raise MemoryError()\n",
                      r"MemoryError: it ran out of memory while being imported.*plug-in's methods"),
    # an exception whose message itself raises is still named, not an internal error
    "unprintable": ("class Odd(Exception):\n    def __str__(self):\n        raise RuntimeError('no')\nraise Odd()\n",
                    r"at line 4: Odd: \(its message could not be printed: RuntimeError\)"),
}


@pytest.mark.parametrize("how", IMPORT_FAILURES)
def test_a_plugin_file_that_fails_on_import_is_a_plugin_error_naming_it(how, tmp_path):
    source, cause = IMPORT_FAILURES[how]
    bad = tmp_path / f"{how}.py"
    bad.write_text(source)
    with pytest.raises(PluginImportError, match=cause) as info:
        load_plugins([str(bad)])
    assert isinstance(info.value, ConfigError) and info.value.method == "import"
    assert f"{how}.py" in str(info.value)



@pytest.mark.parametrize("spec", ["file", "module"])
def test_a_plugin_whose_import_never_returns_is_a_plugin_error_not_a_hang(spec, tmp_path, monkeypatch, capsys):
    """A plug-in that waits forever at import (a device, the network) would hang every command that loads it."""
    monkeypatch.setenv(IMPORT_TIMEOUT_VARIABLE, "0.1")
    stem = f"sleeps_forever_{spec}"
    (tmp_path / f"{stem}.py").write_text("import threading\nthreading.Event().wait()\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    name = str(tmp_path / f"{stem}.py") if spec == "file" else stem
    with pytest.raises(PluginImportError, match=rf"importing plug-in {spec} '.*{stem}(\.py)?' did not finish in "
                                                rf"0\.1 s.*must not do work at import.*{IMPORT_TIMEOUT_VARIABLE}"):
        load_plugins([name])
    assert main(["list", "--plugins", name]) == EXIT_PLUGIN
    assert "did not finish in 0.1 s" in capsys.readouterr().err


@pytest.mark.parametrize("value", ["0", "-1", "soon", "nan"])
def test_a_plugin_import_time_limit_that_is_no_time_is_refused(value, monkeypatch):
    monkeypatch.setenv(IMPORT_TIMEOUT_VARIABLE, value)
    with pytest.raises(ConfigError, match=rf"{IMPORT_TIMEOUT_VARIABLE}='{value}': give the seconds"):
        load_plugins(["no_such_module_is_imported"])


def test_listing_a_plugin_file_that_registers_nothing_says_so(tmp_path, capsys):
    # e.g. the @footzoo.register decorator forgotten: the listing would silently lack the plug-in
    empty = tmp_path / "forgot_register.py"
    empty.write_text("from footzoo.plugins.base import Detector\n\nclass Forgot(Detector):\n    name = 'forgot'\n")
    with warnings.catch_warnings():
        warnings.simplefilter("always")  # the command prints its warnings (checked below)
        assert main(["list", "--kind", "detector", "--plugins", str(empty)]) == 0
    out, err = capsys.readouterr()
    assert re.search(r"footzoo: warning: --plugins\[0\]: .*forgot_register\.py registers no plug-in.*"
                     r"@footzoo\.register", err), err
    assert "forgot" not in out

def test_cli_a_faulty_plugin_exits_4_without_traceback_and_names_it(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "boom.py").write_text(textwrap.dedent('''
        import footzoo
        from footzoo.plugins.base import Detector

        @footzoo.register
        class Boom(Detector):
            """Divides by zero."""
            name = "cli_boom"
            def detect(self, t, acc, gyr, ctx=None):
                return 1 / 0
    '''))
    cfg = _config(detector={"type": "cli_boom"}, plugins=["boom.py"])
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(cfg))
    sim = tmp_path / "walk.csv"
    write(simulate(n_strides=3, rate=100.0), sim)
    assert main(["run", str(tmp_path / "c.yaml"), "--data", str(sim)]) == EXIT_PLUGIN
    err = capsys.readouterr().err
    assert "detector 'cli_boom'" in err and "detect()" in err and "ZeroDivisionError" in err
    assert "internal error" not in err and "Traceback" not in err
    (tmp_path / "exits.py").write_text("import sys\nsys.exit(0)\n")
    (tmp_path / "e.yaml").write_text(yaml.safe_dump(_config(plugins=["exits.py"])))
    assert main(["run", str(tmp_path / "e.yaml"), "--data", str(sim)]) == EXIT_PLUGIN
    assert "never exit the process" in capsys.readouterr().err


def test_a_faulty_plugin_in_a_study_fails_its_cells_only():
    from footzoo.studies import Study, run_study

    study = Study.from_dict({
        "name": "faulty",
        "base": _config(),
        "factors": {"detector.type": ["angular_rate_fsm", "test_fault_raising"]},
        "recordings": [{"simulate": {"path": "straight", "n_strides": 4, "rate": 50}, "seeds": [0]}],
        "metrics": ["path_length_m"],
    })
    table = run_study(study)
    by = table["detector.type"]
    good, bad = table[by == "angular_rate_fsm"], table[by == "test_fault_raising"]
    assert len(good) and good["error"].isna().all() and np.isfinite(good["value"].astype(float)).all()
    assert len(bad) and bad["error"].str.contains("PluginError: detector 'test_fault_raising'").all()
    assert bad["error"].str.contains("ZeroDivisionError").all()


# --------------------------------------------------------------------------- properties
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(values=st.lists(st.sampled_from([0.0, 1.0, np.nan, 0.5, 2.0, -1.0]), min_size=30, max_size=30))
def test_property_a_stance_array_is_accepted_only_when_every_sample_is_decided(values):
    from footzoo.plugins.contract import Output, check_array

    arr = np.asarray(values)
    det = Raising()
    if np.isin(arr, (0.0, 1.0)).all():
        check_array(det, "detect", "stance_", arr, Output("bool"), len(arr))
    else:
        with pytest.raises(PluginError, match="neither 0 nor 1"):
            check_array(det, "detect", "stance_", arr, Output("bool"), len(arr))


@settings(max_examples=40, deadline=None)
@given(scale=st.floats(0.5, 1.5), k=st.integers(0, 19))
def test_property_quaternions_beyond_the_tolerance_are_refused(scale, k):
    from footzoo.plugins.contract import Output, check_array

    q = np.tile([1.0, 0.0, 0.0, 0.0], (20, 1))
    q[k] *= scale
    det = Raising()
    if abs(scale - 1.0) <= QUAT_NORM_TOL / 2:
        check_array(det, "estimate", "quat_", q, Output("quat", 4), 20)
    elif abs(scale - 1.0) > 2 * QUAT_NORM_TOL:
        with pytest.raises(PluginError, match=f"at sample {k}"):
            check_array(det, "estimate", "quat_", q, Output("quat", 4), 20)


@settings(max_examples=25, deadline=None)
@given(exc=st.sampled_from([ValueError, TypeError, IndexError, KeyError, RuntimeError, AttributeError,
                            ZeroDivisionError, AssertionError, RecursionError, SystemExit]))
def test_property_any_exception_of_a_plugin_is_a_plugin_error(exc):
    class Any_(Orientation):
        name = "test_fault_any"

        def estimate(self, t, acc, gyr, mag, stance, q0, ctx=None):
            raise exc("boom")

    t = np.arange(10) / 100.0
    with pytest.raises(PluginError, match=f"test_fault_any.*estimate.*{exc.__name__}") as info:
        checked(Any_().estimate, t, np.zeros((10, 3)), np.zeros((10, 3)), None, np.ones(10, bool),
                np.array([1.0, 0, 0, 0]))
    assert isinstance(info.value.__cause__, exc)


def test_a_reader_that_exits_is_a_plugin_error(tmp_path, monkeypatch, walk):
    from footzoo.io import registry
    from footzoo.io.base import Reader

    class ExitingReader(Reader):
        """Calls sys.exit() instead of raising."""

        name = "test_exiting"

        def open(self, path, **options):
            raise SystemExit(1)

    readers = registry.available()
    monkeypatch.setitem(readers._readers, "test_exiting", ExitingReader())
    monkeypatch.setitem(readers.origins, "test_exiting", "a test package")
    data = write(walk, tmp_path / "w.csv")
    with pytest.raises(PluginError, match=r"the test_exiting reader \(a test package\).*never exit the process"):
        footzoo.load(data, format="test_exiting")


def test_a_plugin_that_raises_in_its_constructor_or_takes_a_builtin_name_is_a_plugin_error(tmp_path, capsys,
                                                                                            monkeypatch):
    """The command line exits 4 naming the plug-in (before: exit 1, "internal error", a bug in footzoo)."""
    monkeypatch.chdir(tmp_path)
    source = '''
        import footzoo
        from footzoo.plugins.base import Detector

        @footzoo.register
        class Bad(Detector):
            """A detector whose constructor fails, or whose name is a built-in's."""
            name = "{name}"
            def __init__(self, threshold: float = 1.0):
                {init}
                self.threshold = threshold
            def detect(self, t, acc, gyr, ctx=None):
                return self
    '''
    sim = write(simulate(n_strides=2, rate=100.0), tmp_path / "walk.csv")
    for file, name, init, expected in [
        ("init.py", "raises_in_init", "raise RuntimeError('no licence')",
         ("detector 'raises_in_init' (footzoo_plugin_", "in init.py) failed in __init__(): RuntimeError: no licence; "
                                                        "fix the plug-in")),
        ("clash.py", "shoe", "pass", ("importing plug-in file", "clash.py' failed at line",
                                      "a detector plug-in named 'shoe' is already registered by "
                                      "footzoo.detectors.shoe.SHOE; choose another name")),
    ]:
        (tmp_path / file).write_text(textwrap.dedent(source).format(name=name, init=init))
        (tmp_path / "c.yaml").write_text(yaml.safe_dump(_config(detector={"type": name}, plugins=[file])))
        try:
            assert main(["run", "c.yaml", "--data", str(sim)]) == EXIT_PLUGIN
        finally:
            registry._REGISTRY["detector"].pop("raises_in_init", None)
        err = capsys.readouterr().err
        assert all(e in err for e in expected) and "internal error" not in err and "Traceback" not in err
    assert registry._REGISTRY["detector"]["shoe"].__module__ == "footzoo.detectors.shoe"


def test_two_classes_of_one_module_under_one_name_are_refused_and_a_redefinition_replaces():
    """A notebook or script: two classes under one name was silently the second; one class defined again replaces."""
    namespace: dict = {}
    source = ("import footzoo\nfrom footzoo.detectors.angular_rate_fsm import AngularRateFSM\n"
              "@footzoo.register\nclass {cls}(AngularRateFSM):\n    '''A copy.'''\n    name = 'test_twice'\n")
    try:
        exec(source.format(cls="First"), namespace)
        exec(source.format(cls="First"), namespace)  # the cell run again: the new class replaces the old
        assert registry.get("detector", "test_twice") is namespace["First"]
        with pytest.raises(ValueError, match="Second: a detector plug-in named 'test_twice' is already registered by "
                                             "First of the same module; give each class its own name"):
            exec(source.format(cls="Second"), namespace)
    finally:
        registry._REGISTRY["detector"].pop("test_twice", None)


def test_a_notebook_plugin_that_raises_in_its_constructor_is_a_plugin_error(walk):
    """A class with no source file (a notebook's, an exec'd one) was taken for a built-in: its error escaped raw."""
    namespace: dict = {}
    exec("import footzoo\nfrom footzoo.detectors.angular_rate_fsm import AngularRateFSM\n@footzoo.register\n"
         "class NoLicence(AngularRateFSM):\n    '''Fails to start.'''\n    name = 'test_no_licence'\n"
         "    def __init__(self, threshold=0.6, min_duration=0.1):\n        raise RuntimeError('no licence')\n",
         namespace)
    try:
        with pytest.raises(PluginError, match=r"detector 'test_no_licence' .* failed in __init__\(\): RuntimeError: "
                                              "no licence; fix the plug-in"):
            Pipeline.from_dict(_config(detector={"type": "test_no_licence"}))
    finally:
        registry._REGISTRY["detector"].pop("test_no_licence", None)


@pytest.mark.parametrize("value, loads", [("30s", False), ("-inf", False), ("1e300", True), ("1e400", True)])
def test_the_import_time_limit_is_checked_as_the_environment_s_and_a_huge_one_is_no_limit(value, loads, tmp_path,
                                                                                          monkeypatch, capsys):
    """A malformed limit is a config error (exit 2) naming the variable, not a plug-in's failed import (exit 4); a
    limit beyond what a thread's wait accepts (1e300 s) is no limit, not an OverflowError."""
    monkeypatch.setenv(IMPORT_TIMEOUT_VARIABLE, value)
    plugin = tmp_path / f"quick_{len(value)}_{loads}.py"
    plugin.write_text("QUICK = 1\n")
    if loads:
        assert load_plugins([str(plugin)])[0]["path"] == str(plugin)
        return
    with pytest.raises(ConfigError, match=rf"{IMPORT_TIMEOUT_VARIABLE}='{value}': give the seconds") as err:
        load_plugins([str(plugin)])
    assert not isinstance(err.value, PluginImportError)
    assert main(["list", "--plugins", str(plugin)]) == 2
    assert IMPORT_TIMEOUT_VARIABLE in capsys.readouterr().err
