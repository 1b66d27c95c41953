"""Every built-in plug-in follows the plug-in contract (footzoo.apps.testing.check_plugin); its report; registration."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import footzoo
from footzoo.apps.testing import check_plugin
from footzoo.core.errors import RecordingError
from footzoo.plugins.base import Detector, Real
from footzoo.plugins.contract import checked
from footzoo.plugins.registry import KINDS, available, build

ROOT = Path(__file__).resolve().parents[2]

BUILTINS = [(kind, name) for kind in KINDS for name in sorted(available(kind))]


@pytest.mark.parametrize("kind,name", BUILTINS, ids=[f"{k}-{n}" for k, n in BUILTINS])
def test_every_builtin_passes_check_plugin(kind, name):
    check_plugin(available(kind)[name])


def test_check_plugin_catches_a_detector_that_mutates_its_input():
    @footzoo.register
    class Mutating(Detector):
        """Marks still samples as stance, but scribbles on its input (a bug check_plugin must catch)."""

        name = "test_mutating"
        paper = "none (test)"
        units = {"threshold": "rad/s"}

        def __init__(self, threshold: float = 0.5):
            self.threshold = threshold

        def detect(self, t, acc, gyr):
            self.stance_ = np.linalg.norm(gyr, axis=1) < self.threshold
            self.statistic_ = np.linalg.norm(gyr, axis=1)
            gyr[:] = 0.0
            return self

    with pytest.raises(AssertionError, match="modified its input"):
        check_plugin(Mutating)


def test_check_plugin_catches_a_numeric_parameter_without_a_unit():
    @footzoo.register
    class NoUnit(Detector):
        """Gyro-magnitude threshold without a declared unit."""

        name = "test_no_unit"
        paper = "none (test)"

        def __init__(self, threshold: float = 0.5):
            self.threshold = threshold

        def detect(self, t, acc, gyr):
            self.statistic_ = np.linalg.norm(gyr, axis=1)
            self.stance_ = self.statistic_ < self.threshold
            return self

    with pytest.raises(AssertionError, match="numeric parameter 'threshold' has no unit: declare it"):
        check_plugin(NoUnit)


@pytest.mark.parametrize("stored, says", [
    ("doubled", r"self.gyro_max is 1.2 where gyro_max=0.6 was given"),
    ("renamed", r"it has no attribute self.gyro_max"),
])
def test_check_plugin_names_an_init_that_does_not_store_its_parameters_as_given(stored, says):
    """scikit-learn's rule is checked first, so its breach is named as such (not as a set_params or action failure)."""
    class Stores(Detector):
        """Gyro-magnitude threshold whose __init__ breaks the rule."""

        name = f"test_stores_{stored}"
        paper = "none (test)"
        parameters = {"gyro_max": Real("rad/s", "(0, 10]", "bound on |ω|", source="a test")}

        def __init__(self, gyro_max: float = 0.6):
            if stored == "doubled":
                self.gyro_max = 2.0 * gyro_max
            else:
                self.gmax = gyro_max

        def detect(self, t, acc, gyr):
            self.statistic_ = np.linalg.norm(gyr, axis=1)
            self.stance_ = self.statistic_ < 0.6
            return self

    footzoo.register(Stores)
    with pytest.raises(AssertionError, match=r"Stores.__init__ must store each parameter as given, under its own "
                                             rf"name \(self.gyro_max = gyro_max\).*{says}"):
        check_plugin(Stores)


def test_nan_input_to_any_action_method_footzoo_calls_is_a_clear_error():
    det = available("detector")["shoe"]()
    t = np.arange(100) / 100.0
    acc = np.tile([0.0, 0.0, -9.81], (100, 1))
    acc[40, 2] = np.nan
    with pytest.raises(RecordingError, match=r"detector 'shoe': input 'acc' has 1 non-finite sample.*index 40"):
        checked(det.detect, t, acc, np.zeros((100, 3)))


def test_a_plugin_class_is_plain_its_methods_run_as_written():
    """footzoo wraps only to check the parameters: the constructor is the author's and stores what it is given, an
    action method is the author's after that check; a method the kind requires is an abc.abstractmethod; a direct
    call runs without the caller's checks of the arrays."""
    from footzoo.plugins.base import Calibration, KalmanCorrection

    def __init__(self, threshold: float = 0.5):
        self.threshold = threshold

    def detect(self, t, acc, gyr):
        self.statistic_ = np.linalg.norm(gyr, axis=1)
        self.stance_ = self.statistic_ < self.threshold
        gyr[0] = 0.0  # writes into its input: only the caller's check refuses it
        return self

    Plain = type("Plain", (Detector,), {"__init__": __init__, "detect": detect, "name": "test_plain",
                                        "parameters": {"threshold": Real("rad/s", "(0, 10]", "t", source="test")}})
    assert Plain.__init__ is __init__ and Plain.detect.__wrapped__ is detect and not Plain.incremental()
    gyr = np.ones((5, 3))
    assert Plain(threshold=5).detect(np.arange(5) / 100.0, np.ones((5, 3)), gyr).threshold == 5
    assert gyr[0].tolist() == [0.0, 0.0, 0.0]  # as written: no read-only view
    assert Plain(threshold=50).threshold == 50  # stored as given ...
    with pytest.raises(footzoo.ConfigError, match=r"detector 'test_plain': threshold = 50 .*10"):
        Plain(threshold=50).detect(np.arange(5) / 100.0, np.ones((5, 3)), gyr)  # ... and refused where it is used
    with pytest.raises(footzoo.PluginError, match="writes into an input array"):
        checked(Plain().detect, np.arange(5) / 100.0, np.ones((5, 3)), np.ones((5, 3)))
    for kind, method in ((Calibration, "calibrate"), (KalmanCorrection, "model")):
        with pytest.raises(TypeError, match=f"abstract method.*{method}"):
            type("Incomplete", (kind,), {"name": "test_incomplete"})()
    assert not [name for name in dir(Detector) if "footzoo" in name and name.startswith("__")]


def test_within_a_run_an_array_proven_finite_is_not_scanned_again_but_any_other_is():
    """A pipeline run scans its recording's arrays for NaN once (inputs_checked_once); a new or changed
    array handed to a block is still checked, and outside a run every call checks."""
    from footzoo.plugins.base import inputs_checked_once

    det = available("detector")["shoe"]()
    t = np.arange(100) / 100.0
    acc = np.tile([0.0, 0.0, -9.81], (100, 1))
    gyr = np.zeros((100, 3))
    with inputs_checked_once():
        checked(det.detect, t, acc, gyr)
        bad = acc.copy()
        bad[40, 2] = np.nan
        with pytest.raises(RecordingError, match=r"input 'acc' has 1 non-finite sample.*index 40"):
            checked(det.detect, t, bad, gyr)  # another object: checked
        acc[7, 0] = np.inf  # the same object, changed behind the run's back: not scanned again
        checked(det.detect, t, acc, gyr)
    with pytest.raises(RecordingError, match=r"input 'acc' has 1 non-finite sample.*index 7"):
        checked(det.detect, t, acc, gyr)  # outside: every call checks


def test_an_output_that_passed_its_check_is_proven_finite_for_the_next_block_within_a_run_only():
    """A block's output checked finite on return (check_array) is not scanned again as the next block's
    input within the run; a copy of it is, and nothing is proven outside a run."""
    from footzoo.plugins.base import inputs_checked_once
    from footzoo.plugins.contract import Output, check_array, proven_finite

    det = available("detector")["shoe"]()
    out = np.ones((10, 3))
    with inputs_checked_once():
        assert not proven_finite(out)
        check_array(det, "detect", "x_", out, Output(width=3), 10)
        assert proven_finite(out) and not proven_finite(out.copy())
        statistic = np.ones(10)
        check_array(det, "detect", "statistic_", statistic, Output(finite=False), 10)
        assert not proven_finite(statistic)  # an output that may hold NaN is not scanned, so proves nothing
    check_array(det, "detect", "x_", out, Output(width=3), 10)
    assert not proven_finite(out)


def test_register_rejects_a_class_of_the_wrong_base_and_a_taken_name():
    class NotAPlugin:
        name = "x"

    with pytest.raises(TypeError, match="plug-in class"):
        footzoo.register(NotAPlugin)

    class Stray(footzoo.plugins.base.Plugin):
        kind = "detector"
        name = "test_stray"

    with pytest.raises(TypeError, match="derives from footzoo.plugins.base.Detector"):
        footzoo.register(Stray)

    class Shoe2(Detector):
        """Another SHOE."""

        name = "shoe"

    with pytest.raises(ValueError, match="already registered"):
        footzoo.register(Shoe2)


def test_the_engine_pipeline_and_stream_name_no_plugin():
    """The engine, the runtime and the kernels know no plug-in by name: adding one touches none of their files."""
    root = Path(footzoo.__file__).parent
    files = [*sorted((root / "filters").glob("*.py")), *sorted((root / "runtime").glob("*.py")),
             *sorted((root / "kernels").glob("*.py"))]
    names = {name for kind in KINDS for name in available(kind) if not name.startswith("test_")}
    for f in files:
        text = f.read_text()
        for name in names:
            assert f'"{name}"' not in text and f"'{name}'" not in text, f"{f.name} names the plug-in {name!r}"


# --------------------------------------------------------------------------- one plug-in loaded twice
PLUGIN_FILE = '''
import numpy as np

import footzoo
from footzoo.plugins.base import Detector, Real

VERSION = {version}


@footzoo.register
class Twice(Detector):
    """Stance while |ω| is small (a plug-in imported by a script and listed under plugins:)."""

    name = "{name}"
    paper = "none (test)"
    parameters = {{"gyro_max": Real("rad/s", "(0, 10]", "bound on |ω|", source="test")}}

    def __init__(self, gyro_max: float = 0.8):
        self.gyro_max = gyro_max

    def detect(self, t, acc, gyr):
        self.statistic_ = np.linalg.norm(gyr, axis=1)
        self.stance_ = self.statistic_ < self.gyro_max
        return self
'''


def _config(path, name):
    return {"plugins": [str(path)], "orientation": {"type": "madgwick"}, "detector": {"type": name},
            "corrections": [{"type": "zvu_dedrift"}]}


@pytest.mark.parametrize("script_first", [True, False], ids=["import-then-config", "config-then-import"])
def test_a_plugin_imported_by_a_script_and_listed_under_plugins_is_one_plugin(tmp_path, monkeypatch, script_first):
    """Issue 24: the same file loaded under two module names failed as 'already registered'."""
    import importlib

    from footzoo import Pipeline

    module = f"twice_{'a' if script_first else 'b'}"
    name = f"test_contract_{module}"
    path = tmp_path / f"{module}.py"
    path.write_text(PLUGIN_FILE.format(version=1, name=name))
    monkeypatch.syspath_prepend(str(tmp_path))
    if script_first:
        mine = importlib.import_module(module)
        pipe = Pipeline.from_dict(_config(path, name))
    else:
        pipe = Pipeline.from_dict(_config(path, name))
        mine = importlib.import_module(module)
        pipe = Pipeline.from_dict(_config(path, name))
    assert isinstance(pipe.detector, mine.Twice)  # the registry keeps the script's class
    assert available("detector")[name] is mine.Twice
    assert check_plugin(mine.Twice, verbose=False).checks


def test_a_plugin_file_edited_after_the_import_replaces_it_and_another_class_is_refused(tmp_path, monkeypatch):
    import importlib

    from footzoo import Pipeline

    name = "test_contract_twice_edited"
    path = tmp_path / "twice_edited.py"
    path.write_text(PLUGIN_FILE.format(version=1, name=name))
    monkeypatch.syspath_prepend(str(tmp_path))
    importlib.import_module("twice_edited")
    path.write_text(PLUGIN_FILE.format(version=2, name=name))
    Pipeline.from_dict(_config(path, name))
    registered = available("detector")[name]
    assert sys.modules[registered.__module__].VERSION == 2  # the newest code runs, as in a study's workers
    other = tmp_path / "other.py"
    other.write_text(PLUGIN_FILE.format(version=1, name=name))
    with pytest.raises(footzoo.ConfigError, match=f"a detector plug-in named '{name}' is already registered"):
        Pipeline.from_dict(_config(other, name))


# --------------------------------------------------------------------------- the report
def test_check_plugin_returns_a_report_and_prints_one_line(capsys):
    report = check_plugin(available("detector")["angular_rate_fsm"], verbose=True)
    line = capsys.readouterr().out
    assert line.count("\n") == 1 and line.startswith("check_plugin: detector 'angular_rate_fsm' passed ")
    assert str(report) == line.strip() and len(report.checks) >= 5 and not report.notes
    assert "bad values refused" in report.details()
    check_plugin(available("detector")["shoe"], verbose=False)
    assert capsys.readouterr().out == ""


def test_check_plugin_from_the_command_line(tmp_path, capsys):
    """``python -m footzoo.apps.testing FILE.py``: one line per plug-in, exit 1 when one fails."""
    from footzoo.apps.testing import main

    good = tmp_path / "good.py"
    good.write_text(PLUGIN_FILE.format(version=1, name="test_contract_cli"))
    assert main([str(good)]) == 0
    assert capsys.readouterr().out.startswith("check_plugin: detector 'test_contract_cli' passed")
    bad = tmp_path / "bad.py"
    bad.write_text(PLUGIN_FILE.format(version=1, name="test_contract_cli_bad").replace(
        "gyr, axis=1)\n        self.stance_", "gyr, axis=1)\n        gyr[:] = 0\n        self.stance_"))
    assert main([str(bad)]) == 1
    err = capsys.readouterr().err
    assert "check_plugin: detector 'test_contract_cli_bad' FAILED: " in err and "modified its input" in err
    assert main([str(tmp_path / "none.py")]) == 2 and "does not exist" in capsys.readouterr().err


def test_check_plugin_on_a_reader_file_says_how_readers_are_registered_and_tried(tmp_path, capsys):
    from footzoo.apps.testing import main

    reader = tmp_path / "my_format_reader.py"
    reader.write_text("from footzoo.io import Reader\n\n\nclass MyFormatReader(Reader):\n"
                      "    def guess_can_open(self, path):\n        return False\n\n"
                      "    def open(self, path):\n        raise NotImplementedError\n")
    assert main([str(reader)]) == 2
    err = capsys.readouterr().err
    assert "defines the reader MyFormatReader" in err and "footzoo.readers" in err and "footzoo.load(" in err
    assert "@footzoo.register" not in err  # the fix for a pipeline plug-in, wrong for a reader
    empty = tmp_path / "empty_module.py"
    empty.write_text("X = 1\n")
    assert main([str(empty)]) == 2 and "decorate the classes with @footzoo.register" in capsys.readouterr().err


@pytest.mark.slow  # a new Python process
def test_the_testing_module_runs_as_a_script():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "footzoo.apps.testing", "--help"], capture_output=True, text=True,
                          env=env)
    assert proc.returncode == 0 and proc.stdout.startswith("usage: python -m footzoo.apps.testing")


def test_check_plugin_checks_the_declarations():
    @footzoo.register
    class Unitless(Detector):
        """A declared threshold without a unit or a source."""

        name = "test_contract_unitless"
        paper = "none (test)"
        parameters = {"threshold": Real("", "(0, 10]", "bound on |ω|")}

        def __init__(self, threshold: float = 0.5):
            self.threshold = threshold

        def detect(self, t, acc, gyr):
            self.statistic_ = np.linalg.norm(gyr, axis=1)
            self.stance_ = self.statistic_ < self.threshold
            return self

    with pytest.raises(AssertionError, match="gives no source of its default"):
        check_plugin(Unitless)
    Unitless.parameters["threshold"].source = "test"
    with pytest.raises(AssertionError, match="declares no unit"):
        check_plugin(Unitless)


@pytest.mark.parametrize("given", ["shoe", 3, np.zeros(3)])
def test_check_plugin_of_a_non_class_says_to_pass_the_class(given):
    with pytest.raises(AssertionError, match=r"check_plugin expects a footzoo plug-in class, got .*the class itself"):
        check_plugin(given)


@pytest.mark.parametrize("kind, name, params, message", [
    ("detector", "shoe", {"threshold": -1}, r"detector 'shoe': threshold = -1 is out of range"),
    ("analysis", "huang_fpa", {"alpha": -1}, r"analysis 'huang_fpa': alpha = -1 .*\(0, 1\]"),
    ("analysis", "huang_fpa", {"foot_vector": [0.0, 0.0]}, r"analysis 'huang_fpa': foot_vector"),
    ("orientation", "madgwick", {"gyro_error": float("nan")}, r"orientation 'madgwick': gyro_error"),
])
def test_a_plugin_built_in_python_with_a_refused_value_is_refused_where_it_is_used(kind, name, params, message):
    """The constructor stores what it is given (scikit-learn's rule); the action method, called by hand or by a
    stream (begin), checks it as a config's value is checked, with the same message."""
    plugin = available(kind)[name](**params)
    assert all(getattr(plugin, k) is v for k, v in params.items())
    t = np.arange(200) / 100.0  # a foot at rest, 2 s: the value is refused before the samples are read
    acc, gyr = np.tile([0.0, 0.0, -9.81], (200, 1)), np.zeros((200, 3))
    quat, pos, stance = np.tile([1.0, 0.0, 0.0, 0.0], (200, 1)), np.zeros((200, 3)), np.ones(200, dtype=bool)
    with pytest.raises(footzoo.ConfigError, match=message):
        if kind == "detector":
            plugin.detect(t, acc, gyr)
        elif kind == "orientation":
            plugin.estimate(t, acc, gyr, None)
        else:
            plugin.analyze(t, quat, pos, stance, {})
    with pytest.raises(footzoo.ConfigError, match=message):
        plugin.begin(footzoo.core.context.RunContext.from_time(t))
    with pytest.raises(footzoo.ConfigError, match=message.partition(": ")[2]):  # the check of a config's value
        build(kind, {"type": name, **params})


def _raises_runtime_error(self):
    raise RuntimeError("cannot check")


def _raises_key_error(self):
    return {}["x"]


@pytest.mark.parametrize("check, cause", [
    (_raises_runtime_error, r"RuntimeError: cannot check"),
    (_raises_key_error, r"KeyError: 'x'"),
    (property(lambda self: None), r"TypeError: 'NoneType' object is not callable"),
])
def test_a_plugins_own_check_params_raising_any_error_is_a_plugin_error_naming_it(check, cause):
    """A plug-in overriding check_params with a bug: its action methods and a pipeline given it name the plug-in,
    the method and the fix (was the bare error, without the plug-in's name)."""
    from footzoo.plugins.base import check_parameters

    class OwnCheck(Detector):
        """Stance where |w| < 0.6 rad/s (test; paper none, eq. 0)."""

        name = "own_check"
        paper = "none (test)"
        check_params = check

        def detect(self, t, acc, gyr, ctx=None):
            self.statistic_ = np.linalg.norm(gyr, axis=1)
            self.stance_ = self.statistic_ < 0.6
            return self

    message = rf"detector 'own_check': its check_params raised {cause}; check_params must return the plug-in"
    t = np.arange(50) / 100.0
    with pytest.raises(footzoo.PluginError, match=message):
        OwnCheck().detect(t, np.tile([0.0, 0.0, -9.81], (50, 1)), np.zeros((50, 3)))
    with pytest.raises(footzoo.PluginError, match=message):
        check_parameters([OwnCheck()])
