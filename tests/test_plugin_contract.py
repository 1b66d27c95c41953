"""Every built-in plug-in follows the plug-in contract (footzoo.apps.testing.check_plugin)."""

import numpy as np
import pytest

import footzoo
from footzoo.apps.testing import check_plugin
from footzoo.core.errors import RecordingError
from footzoo.plugins.base import Detector
from footzoo.plugins.registry import KINDS, available

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")

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

    with pytest.raises(AssertionError, match="no unit"):
        check_plugin(NoUnit)


def test_nan_input_to_any_action_method_is_a_clear_error():
    det = available("detector")["shoe"]()
    t = np.arange(100) / 100.0
    acc = np.tile([0.0, 0.0, -9.81], (100, 1))
    acc[40, 2] = np.nan
    with pytest.raises(RecordingError, match=r"detector 'shoe': input 'acc' has 1 non-finite sample.*index 40"):
        det.detect(t, acc, np.zeros((100, 3)))


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
    from pathlib import Path

    root = Path(footzoo.__file__).parent
    files = [*sorted((root / "filters").glob("*.py")), *sorted((root / "runtime").glob("*.py")),
             *sorted((root / "kernels").glob("*.py"))]
    names = {name for kind in KINDS for name in available(kind) if not name.startswith("test_")}
    for f in files:
        text = f.read_text()
        for name in names:
            assert f'"{name}"' not in text and f"'{name}'" not in text, f"{f.name} names the plug-in {name!r}"
