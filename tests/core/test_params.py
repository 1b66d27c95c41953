"""Declared parameters (footzoo.core.params): each kind of declaration, its messages, and how plug-ins use it."""

from __future__ import annotations

import math

import numpy as np
import pytest

import footzoo
from footzoo import ConfigError
from footzoo.core.params import (
    Boolean,
    Choice,
    File,
    Integer,
    Interval,
    Real,
    Vector,
    Vectors,
)
from footzoo.plugins.base import Detector
from footzoo.plugins.registry import available, build


def refused(param, value, default=None, name="p") -> str:
    with pytest.raises(ConfigError) as err:
        param.validate(name, value, default)
    return str(err.value)


# --------------------------------------------------------------------------- intervals
@pytest.mark.parametrize("text, inside, outside", [
    ("(0, 10]", [1e-300, 5.0, 10.0], [0.0, -1.0, 10.000001]),
    ("[0, 1/3]", [0.0, 1 / 3], [-1e-12, 0.34]),
    ("(0, pi]", [math.pi], [3.1416, 0.0]),
    ("[0, inf)", [0.0, 1e308], [-1e-300, math.inf]),
    ("[-pi/2, pi/2)", [-math.pi / 2, 1.5], [math.pi / 2, -1.571]),
])
def test_intervals_parse_their_ends_and_openness(text, inside, outside):
    iv = Interval.parse(text)
    assert all(v in iv for v in inside) and not any(v in iv for v in outside)
    assert all(v in iv for v in iv.inside()) and not any(v in iv for v in iv.outside())


def test_interval_messages_read_as_written():
    assert str(Interval.parse("(0, pi]")) == "(0, π]"
    assert Interval.parse("(0, inf)").requirement("s") == "be > 0 s"
    assert Interval.parse("[9.7, 9.9]").requirement("m/s^2") == "lie in [9.7, 9.9] m/s^2"
    for bad in ("0..10", "(0, x]", "(0, 1, 2]"):
        with pytest.raises(TypeError, match="written like"):
            Interval.parse(bad)
    with pytest.raises(TypeError, match="must not exceed"):
        Interval.parse("[2, 1]")


# --------------------------------------------------------------------------- each kind
def test_real_converts_and_refuses_with_the_unit_range_and_fix():
    r = Real("rad/s", "(0, 10]", "Ω_th")
    assert r.validate("threshold", 1, 0.6) == 1.0 and isinstance(r.validate("threshold", 1, 0.6), float)
    assert r.validate("threshold", np.float32(0.5), 0.6) == pytest.approx(0.5)
    assert refused(r, -1, 0.6, "threshold") == ("threshold = -1 rad/s is out of range: it must lie in (0, 10] rad/s; "
                                                "e.g. the default 0.6 rad/s")
    assert "must be a finite number, got nan" in refused(r, float("nan"), 0.6)
    assert "must be a finite number, got 10000000000" in refused(r, 10**400, 0.6)  # an int too large for a float
    assert "(401 characters)" in refused(r, 10**400, 0.6)
    assert "got str '3e4' (write the number without quotes)" in refused(r, "3e4", 0.6)
    assert "must be a number, got bool True" in refused(r, True, 0.6)
    assert "got None (null)" in refused(r, None, 0.6)
    assert "must be a number, got list [1]" in refused(r, [1], 0.6)


@pytest.mark.parametrize("unit, interval, value, default, hint", [
    # a deg/s value given as rad/s (issue 24: 35 rad/s passed silently); 35 °/s = 0.611 rad/s
    ("rad/s", "(0, 10]", 35, 0.6, "35 rad/s is 2005 °/s: threshold is in rad/s (the default 0.6 rad/s is 34.4 °/s); "
                                  "for 35 °/s write 0.611"),
    ("rad", "(0, pi]", 30, 0.5, "30 rad is 1719 °: threshold is in rad (the default 0.5 rad is 28.6 °); "
                                "for 30 ° write 0.524"),
    # g for m/s²: 1 g = 9.81 m/s²
    ("m/s^2", "[9.7, 9.9]", 1.0, 9.81, "1 m/s^2 is 0.102 g: threshold is in m/s^2 (the default 9.81 m/s^2 is 1 g); "
                                       "for 1 g write 9.81"),
    # ms for s
    ("s", "[0, 1]", 100, 0.1, "100 s is 100000 ms: threshold is in s (the default 0.1 s is 100 ms); "
                              "for 100 ms write 0.1"),
])
def test_a_value_in_a_unit_often_given_by_mistake_gets_the_conversion(unit, interval, value, default, hint):
    assert hint in refused(Real(unit, interval), value, default, "threshold")


def test_no_unit_hint_where_the_conversion_does_not_help():
    msg = refused(Real("rad/s", "(0, 10]"), 1e6, 0.6, "threshold")
    assert "°/s" not in msg and "must lie in (0, 10] rad/s" in msg
    assert "°" not in refused(Real("rad/s", "(0, 10]"), -3, 0.6)


def test_why_is_shown_with_a_refusal():
    msg = refused(Real("rad/s", "(0, 10]", why="only a swing is faster"), 20, 0.6, "threshold")
    assert "(0, 10] rad/s (only a swing is faster)" in msg


def test_integer_takes_whole_numbers_only():
    i = Integer("1", "[1, 10]")
    assert i.validate("n", 5.0, 3) == 5 and isinstance(i.validate("n", 5.0, 3), int)
    assert "must be a whole number, got 2.5" in refused(i, 2.5, 3)
    assert "out of range" in refused(i, 11, 3)
    assert "got bool True" in refused(i, True, 3)
    assert i.edge_values(3) == [3, 1, 10]


@pytest.mark.parametrize("value", ["no", "false", "off", 0, 1, 0.0, None, "true"])
def test_boolean_is_strict(value):
    assert "must be true or false" in refused(Boolean(), value, True, "use_magnetometer")


def test_boolean_accepts_numpy_bools():
    assert Boolean().validate("b", np.bool_(False)) is False


def test_choice_suggests_the_closest_name():
    c = Choice(("auto", "right", "left"))
    assert c.validate("foot", "left") == "left"
    assert "got 'rihgt' (did you mean 'right'?)" in refused(c, "rihgt", "auto", "foot")
    assert "must be one of ['auto', 'right', 'left'], got 3" in refused(c, 3, "auto", "foot")
    with pytest.raises(TypeError):
        Choice("abc")


def test_vector_checks_size_elements_range_and_direction():
    v = Vector(2, "1", range="[0, 1]")
    assert v.validate("window", (0.2, 0.8)) == [0.2, 0.8]
    assert v.validate("window", np.array([0, 1])) == [0.0, 1.0]
    assert "window must be a list of 2 numbers like [0, 1]" in refused(v, [0.2], None, "window")
    assert "window[1] = 1.5 is out of range: it must lie in [0, 1]" in refused(v, [0.2, 1.5], None, "window")
    assert "window[0] must be a finite number" in refused(v, [math.nan, 0.5], None, "window")
    assert "must not be all zeros" in refused(Vector(3, "1", nonzero=True), [0, 0, 0], None, "foot_vector")
    assert "got str" not in refused(v, "0.2, 0.8", None, "window") and "got '0.2, 0.8'" in refused(v, "0.2, 0.8")


def test_vectors_check_each_row():
    vs = Vectors(3, "m", nonzero=True, min_count=1)
    assert vs.validate("directions", ((0, 0, 1), (0, 1, 0))) == [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
    assert "at least 1" in refused(vs, [], None, "directions")
    assert "directions[1] is [1, 2]" in refused(vs, [[0, 0, 1], [1, 2]], None, "directions")
    assert "directions[0][2] must be a finite number" in refused(vs, [[0, 0, math.inf]], None, "directions")
    assert "must not contain [0, 0, 0]" in refused(vs, [[0, 0, 0]], None, "directions")


def test_file_and_optional():
    f = File(suffixes=(".yaml", ".yml"), optional=True)
    assert f.validate("calibration", None) is None
    from pathlib import Path

    assert f.validate("calibration", Path("fv.yaml")) == "fv.yaml"
    assert "ending in .yaml or .yml, got 'fv.txt'" in refused(f, "fv.txt", None, "calibration")
    assert "got int 3" in refused(f, 3, None, "calibration")
    assert "got str ''" in refused(f, "", None, "calibration")


@pytest.mark.parametrize("param, default", [
    (Real("s", "(0, 1]"), 0.5), (Integer("1", "[0, 10]"), 3), (Boolean(), True), (Choice(("a", "b")), "a"),
    (Vector(3, "m", range="[-1, 1]", nonzero=True), [1, 0, 0]), (Vectors(2, "m"), [[0, 1]]),
    (File(suffixes=(".yaml",)), "x.yaml"), (Real("m", "[0, 1]", optional=True), None),
])
def test_invalid_values_are_refused_and_edge_values_accepted(param, default):
    """The fuzz tests rely on these lists: each invalid value is refused, each edge value accepted."""
    for bad in param.invalid_values():
        refused(param, bad, default)
    for edge in param.edge_values(default):
        param.validate("p", edge, default)


# --------------------------------------------------------------------------- plug-ins
def _detector(parameters, init, name):
    namespace = {"parameters": parameters, "name": name, "__init__": init,
                 "__doc__": "A test detector.", "paper": "none (test)"}
    return type("T" + name, (Detector,), namespace)


def test_the_declarations_are_checked_where_the_plugin_is_used_and_the_constructor_runs_as_written():
    seen = {}

    def __init__(self, threshold: float = 0.6, window: list | tuple = (0.2, 0.8)):
        seen.update(threshold=threshold, window=window)
        self.threshold, self.window = threshold, window

    cls = _detector({"threshold": Real("rad/s", "(0, 10]", "t", source="test"),
                     "window": Vector(2, "1", "w", source="test")}, __init__, "test_params_convert")
    p = cls(**cls.validate_params({"threshold": 1}))  # as a config builds it (registry.build): validated, then made
    assert seen == {"threshold": 1.0, "window": [0.2, 0.8]} and type(p.threshold) is float
    assert p.get_params() == {"threshold": 1.0, "window": [0.2, 0.8]}
    with pytest.raises(ConfigError, match=r"threshold = 35 rad/s is out of range"):
        cls.validate_params({"threshold": 35})
    direct = cls(threshold=35)  # in Python, __init__ stores what it is given ...
    assert seen == {"threshold": 35, "window": (0.2, 0.8)} and direct.threshold == 35
    with pytest.raises(ConfigError, match=r"detector 'test_params_convert': threshold = 35 rad/s is out of range"):
        direct.check_params()  # ... and a pipeline refuses it when it is given the plug-in
    with pytest.raises(ConfigError, match=r"threshold = 35 rad/s is out of range"):
        footzoo.Pipeline(orientation=available("orientation")["madgwick"](), detector=direct)
    assert cls.units == {"threshold": "rad/s", "window": "1"}


def test_declaration_mistakes_fail_when_the_class_is_defined():
    def __init__(self, threshold: float = 0.6):
        self.threshold = threshold

    with pytest.raises(TypeError, match=r"declares 'treshold', which is not a parameter of its __init__ "
                                        r"\(did you mean 'threshold'\?\)"):
        _detector({"treshold": Real("rad/s", "(0, 10]")}, __init__, "test_params_stray")
    with pytest.raises(TypeError, match=r"the default of 'threshold' is refused by its own declaration"):
        _detector({"threshold": Real("rad/s", "(1, 10]")}, __init__, "test_params_bad_default")
    with pytest.raises(TypeError, match=r"must be a footzoo.core.params.Param"):
        _detector({"threshold": (0, 10)}, __init__, "test_params_not_a_param")


def test_a_subclass_declares_only_what_it_changes():
    base = available("detector")["shoe"]

    class Tighter(base):
        """SHOE with a narrower threshold range."""

        name = "test_params_tighter"
        parameters = {"threshold": base.parameters["threshold"].replace(range="(0, 1e5]", source="test")}

    assert Tighter.declaration()["window"].param is base.declaration()["window"].param
    assert str(Tighter.declaration()["threshold"].param.interval) == "(0, 1e5]"
    with pytest.raises(ConfigError, match=r"threshold = 200000.0 is out of range: it must lie in \(0, 1e5\]"):
        Tighter(threshold=2e5).check_params()
    assert base(threshold=2e5).threshold == 2e5  # the base's own declaration is unchanged


def test_a_plugin_without_declarations_works_as_before():
    @footzoo.register
    class OldStyle(Detector):
        """A detector written before declarations: a units dict and its own check."""

        name = "test_params_old_style"
        paper = "none (test)"
        units = {"threshold": "rad/s"}

        def __init__(self, threshold: float = 0.5):
            from footzoo.plugins.registry import check_range

            self.threshold = check_range("threshold", threshold, 0.0, 10.0, "rad/s", lo_open=True)

        def detect(self, t, acc, gyr):
            self.statistic_ = np.linalg.norm(gyr, axis=1)
            self.stance_ = self.statistic_ < self.threshold
            return self

    assert OldStyle.declaration() == {} and OldStyle.undeclared() == ["threshold"]
    assert build("detector", {"type": "test_params_old_style", "threshold": 1}).threshold == 1.0
    with pytest.raises(ConfigError, match=r"detector \(test_params_old_style\): threshold = 20 rad/s is out of range"):
        build("detector", {"type": "test_params_old_style", "threshold": 20}, "detector")
    report = footzoo.check_plugin(OldStyle, verbose=False)
    assert any("declare ['threshold']" in n for n in report.notes)


# --------------------------------------------------------------------------- set_params
def test_set_params_validates_like_the_constructor_and_raises_config_errors():
    det = available("detector")["angular_rate_fsm"]()
    assert det.set_params(threshold=1) is det and det.threshold == 1.0
    with pytest.raises(ConfigError, match=r"detector 'angular_rate_fsm': unknown parameter 'treshold' "
                                          r"\(did you mean 'threshold'\?\); valid parameters"):
        det.set_params(treshold=1.0)
    with pytest.raises(ConfigError, match=r"detector 'angular_rate_fsm': threshold = 35 rad/s is out of range"):
        det.set_params(threshold=35)
    assert det.threshold == 1.0  # a refused change leaves the parameters as they were
    ekf = available("correction")["ekf_zupt"]()
    with pytest.raises(ConfigError, match="zero_rate measures the gyro bias"):  # a cross-parameter rule
        ekf.set_params(gyro_bias=False)
    assert ekf.clone().get_params() == ekf.get_params()


def test_spec_round_trips_declared_values():
    fpa = build("analysis", {"type": "huang_fpa", "window": (0.1, 0.9), "foot": "left"})
    assert fpa.spec()["window"] == [0.1, 0.9]
    assert build("analysis", fpa.spec()).get_params() == fpa.get_params()


def test_every_builtin_physical_quantity_has_a_plausible_upper_bound():
    """The range review holds for every built-in (and a new one): a rate, angle, acceleration or duration is bounded,
    so that a value in another unit (°/s, °, g, ms) is refused with the conversion instead of passing silently."""
    from footzoo.core.params import UNIT_SLIPS
    from footzoo.plugins.registry import KINDS
    from footzoo.runtime.validate import settings_declarations

    declared = {f"{n}.{p}": d for k in KINDS for n, cls in available(k).items() if not n.startswith("test_")
                for p, d in cls.declaration().items()}
    declared.update(settings_declarations())
    physical = {k: d for k, d in declared.items() if isinstance(d.param, Real) and d.param.unit in UNIT_SLIPS}
    assert len(physical) > 40
    unbounded = [k for k, d in physical.items() if not math.isfinite(d.param.interval.hi)]
    assert not unbounded
