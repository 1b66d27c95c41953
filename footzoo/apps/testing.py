"""Conformance checks for plug-ins, like scikit-learn's ``check_estimator``.

``check_plugin(cls)`` runs a plug-in class through the contract of :mod:`footzoo.plugins.base` on a
short simulated walk (with magnetometer, distance sensors and truth), raises ``AssertionError``
naming the first broken rule, and otherwise returns a :class:`CheckReport` of what it checked
(printed as one line; ``print(report.details())`` lists every check). Use it in your plug-in's
tests::

    from footzoo.apps.testing import check_plugin
    def test_my_detector_follows_the_contract():
        check_plugin(MyDetector)

or on a plug-in file from the command line: ``python -m footzoo.apps.testing my_detector.py``.

The checks:

* registered under its kind and name, derived from the kind's base class, with a docstring
  and a ``paper``;
* every constructor parameter has a default; declared parameters (``parameters``, see
  :mod:`footzoo.core.params`) have a meaning, a unit where they are numbers and the source of their
  default, and every value their declaration refuses (wrong types, NaN, infinities, values just out
  of range) is refused where footzoo builds the plug-in (:meth:`~footzoo.plugins.base.Plugin.validate_params`,
  as a config is built), by ``set_params`` and, given to the constructor in Python, by the action method
  with a ``ConfigError`` naming the parameter, while the
  edges of the accepted ranges are accepted; a plug-in without declarations
  needs a unit in ``units`` for every numeric parameter (and the report suggests declaring);
  parameters are stored as attributes under their own names (``get_params``), constructing
  from ``get_params()`` gives the same parameters (idempotent), ``set_params`` works and
  rejects unknown names with a ``ConfigError``;
* YAML round trip: ``spec()`` dumps with ``yaml.safe_dump`` and builds back to the same
  parameters; ``clone()`` gives an equal, unfitted, independent copy;
* the action method, called as footzoo calls it (:func:`footzoo.plugins.contract.checked`), leaves
  its inputs untouched and returns results of the documented shapes, finite;
* a calibration returns corrected copies shaped like its inputs and a ``report_`` dict, and
  passes a recording without a magnetometer through;
* a block that implements the incremental protocol (``begin``/``step``/``finish``, see
  :mod:`footzoo.plugins.incremental`) gives the same final outputs fed in chunks of random
  sizes (and one sample at a time) as in one batch, declares a :class:`~footzoo.plugins.incremental.Latency`,
  and its ``provisional()`` guesses are shaped like its outputs;
* a Kalman correction gives the same trajectory (1e-9) on the compiled and the reference
  engine (or runs on the reference one, with a warning, when its model does not compile), and
  live in :class:`~footzoo.runtime.stream.Stream` the same as in a batch run.
"""

from __future__ import annotations

import copy
import inspect
import sys
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import yaml

from ..core.context import RunContext
from ..core.errors import ConfigError, FootzooError, PluginError
from ..core.params import Real
from ..filters.strapdown import motion_acceleration
from ..io import Reader
from ..plugins.base import (
    CHECKS_PARAMS,
    AccelerationCorrection,
    Analysis,
    Calibration,
    Detector,
    KalmanCorrection,
    Orientation,
    Plugin,
    VelocityCorrection,
)
from ..plugins.contract import checked
from ..plugins.extensions import load_plugins
from ..plugins.incremental import Latency, concat
from ..plugins.registry import KINDS, available, build, same_plugin
from ..runtime.pipeline import Pipeline
from ..runtime.stream import Stream
from ..sim import NoiseModel, simulate

_WALK: Any = None


def _walk():
    """A short simulated walk with magnetometer, two distance sensors and truth (cached)."""
    global _WALK
    if _WALK is None:
        _WALK = simulate(n_strides=5, profile="physical", rate=100.0, noise=NoiseModel(seed=7),
                         distance_sensors=True, clearance=0.1)
    return _WALK


@dataclass
class CheckReport:
    """What :func:`check_plugin` checked on a plug-in that passed, and what it suggests.

    Attributes
    ----------
    plugin : str
        ``"<kind> '<name>'"``.
    checks : list of str
        Each check that passed, in order.
    notes : list of str
        Suggestions that are not failures (e.g. declare the parameters).
    """

    plugin: str
    checks: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def passed(self, what: str) -> None:
        """Record a check that passed."""
        self.checks.append(what)

    def __str__(self) -> str:
        notes = f"; {len(self.notes)} note(s): " + " ".join(self.notes) if self.notes else ""
        return f"check_plugin: {self.plugin} passed {len(self.checks)} checks ({'; '.join(self.checks)}){notes}"

    def details(self) -> str:
        """One line per check and note."""
        return "\n".join([f"check_plugin: {self.plugin}", *(f"  passed: {c}" for c in self.checks),
                          *(f"  note: {n}" for n in self.notes)])

    def __repr__(self) -> str:
        return str(self)


def check_plugin(cls: type[Plugin], verbose: bool | None = None) -> CheckReport:
    """Run every conformance check on a plug-in class (see the module docstring).

    Parameters
    ----------
    cls : type
        The plug-in class.
    verbose : bool, optional
        Print the report's one-line summary (default: in an interactive session or a notebook).

    Returns
    -------
    CheckReport
        What was checked; an ``AssertionError`` names the first broken rule instead.
    """
    report = CheckReport(f"{getattr(cls, 'kind', '?')} {getattr(cls, 'name', '?')!r}")
    _check_declaration(cls)
    _check_stored_as_given(cls)
    report.passed("registration and declaration")
    _check_declared_parameters(cls, report)
    instance = cls()
    _check_params(cls, instance)
    report.passed("get_params/set_params")
    _check_round_trip(cls, instance)
    report.passed("YAML round trip and clone")
    try:
        _check_behaviour(instance, report)
    except PluginError as err:  # the contract footzoo checks at every call (footzoo.plugins.contract) names the fault
        edit = " (the action method modified its input arrays)" if "read-only" in str(err) else ""
        raise AssertionError(f"{cls.__name__}: {err}{edit}") from err
    if verbose if verbose is not None else _interactive():
        print(report)
    return report


def _check_behaviour(instance: Plugin, report: CheckReport) -> None:
    """The kind's behaviour checks on a simulated walk."""
    if isinstance(instance, Calibration):
        _check_calibration(instance)
        report.passed("calibrate on a simulated walk, with and without magnetometer")
    elif isinstance(instance, Detector):
        _check_detector(instance)
        report.passed("detect on a simulated walk" + (", chunked = batch" if instance.causal else ""))
    elif isinstance(instance, Orientation):
        _check_orientation(instance)
        report.passed("estimate on a simulated walk (unit quaternions)")
    elif isinstance(instance, KalmanCorrection) and not isinstance(instance, (VelocityCorrection,
                                                                              AccelerationCorrection)):
        _check_kalman(instance)
        report.passed("compiled = reference engine" + (" = live stream" if instance.causal else ""))
    elif isinstance(instance, (VelocityCorrection, AccelerationCorrection)):
        _check_batch_correction(instance)
        report.passed("batch correction on a simulated walk")
        if isinstance(instance, KalmanCorrection):
            _check_kalman(instance)
            report.passed("compiled = reference engine" + (" = live stream" if instance.causal else ""))
    elif isinstance(instance, Analysis):
        _check_analysis(instance)
        report.passed("analyze and annotate on a simulated walk")


def _interactive() -> bool:
    """Whether Python runs interactively (a REPL, ``python -i``, IPython or a notebook)."""
    return hasattr(sys, "ps1") or bool(sys.flags.interactive) or "IPython" in sys.modules


# --------------------------------------------------------------------------- declaration
def _check_declaration(cls: type[Plugin]) -> None:
    assert isinstance(cls, type) and issubclass(cls, Plugin), (
        f"check_plugin expects a footzoo plug-in class, got {cls!r} ({type(cls).__name__}): pass the class itself, "
        "the one decorated with @footzoo.register")
    assert cls.name, f"{cls.__name__}: class attribute 'name' is empty"
    registered = available(cls.kind).get(cls.name)
    assert registered is not None and same_plugin(registered, cls), (
        f"{cls.__name__}: not registered as {cls.kind} {cls.name!r} (decorate it with @footzoo.register; "
        f"found {registered!r})")
    assert (cls.__doc__ or "").strip(), f"{cls.__name__}: no docstring (cite the paper and its equations)"
    assert cls.paper, f"{cls.__name__}: class attribute 'paper' is empty (cite the source)"


def _check_stored_as_given(cls: type[Plugin]) -> None:
    """scikit-learn's rule, checked first (the later checks assume it): ``__init__`` stores each parameter as given,
    as the attribute of its own name."""
    instance = cls()
    for name, default in cls.defaults().items():
        rule = (f"{cls.__name__}.__init__ must store each parameter as given, under its own name (self.{name} = "
                f"{name}); derived values belong in the action method")
        assert hasattr(instance, name), f"{rule}: it has no attribute self.{name}"
        assert _equal(getattr(instance, name), default), (f"{rule}: self.{name} is {getattr(instance, name)!r} where "
                                                          f"{name}={default!r} was given")


def _check_declared_parameters(cls: type[Plugin], report: CheckReport) -> None:
    """Declarations complete; every value a declaration refuses is refused as a config builds the plug-in and by
    set_params."""
    declaration = cls.declaration()
    undeclared = cls.undeclared()
    if undeclared:
        report.notes.append(f"declare {undeclared} in {cls.__name__}.parameters (see footzoo.core.params): "
                            "validation, footzoo list, the docs and fuzzed bad values then come from it")
    if not declaration:
        return
    for name, d in declaration.items():
        p = d.param
        assert p.doc, f"{cls.__name__}: the declaration of {name!r} has no meaning (its doc text)"
        assert p.source or d.default is None, (f"{cls.__name__}: the declaration of {name!r} gives no source of its "
                                               "default (source='Paper 2020, Table 1' or footzoo's reason)")
        if isinstance(p, Real):
            assert p.unit, f"{cls.__name__}: numeric parameter {name!r} declares no unit ('1' if dimensionless)"
    base = cls()
    refused = accepted = 0
    for name, d in declaration.items():
        for bad in d.param.invalid_values():
            for how in ("validate_params", "set_params", "its action method"):
                try:
                    if how == "set_params":
                        base.clone().set_params(**{name: copy.deepcopy(bad)})
                    elif how == "its action method":
                        plugin = _constructed(cls, {name: copy.deepcopy(bad)})
                        if plugin is None:
                            continue  # its constructor's own work refused it: the action method never sees it
                        action = next(m for m in CHECKS_PARAMS if callable(getattr(cls, m, None)))
                        getattr(plugin, action)()  # the parameters are checked before an argument is read
                    else:
                        _build(cls, {name: copy.deepcopy(bad)})
                except ConfigError as err:
                    assert name in str(err), f"{cls.__name__}: {how} refused {name}={bad!r} without naming it: {err}"
                    refused += 1
                    continue
                except Exception as err:  # noqa: BLE001 - the check reports what it got
                    raise AssertionError(f"{cls.__name__}: {how} refused {name}={bad!r} with "
                                         f"{type(err).__name__} ({err}), not a ConfigError") from None
                raise AssertionError(f"{cls.__name__}: {how} accepted {name}={bad!r}, which its declaration refuses")
        for edge in d.param.edge_values(d.default):
            try:
                _build(cls, {name: copy.deepcopy(edge)})
                accepted += 1
            except ConfigError:
                pass  # a cross-parameter rule may refuse an edge together with the other defaults
            except Exception as err:  # noqa: BLE001 - the check reports what it got
                raise AssertionError(f"{cls.__name__}: {name}={edge!r} (within its declared range) raised "
                                     f"{type(err).__name__} ({err}), not a ConfigError") from None
    report.passed(f"declared parameters ({refused} bad values refused, {accepted} edge values accepted)")


def _constructed(cls: type[Plugin], params: dict[str, Any]) -> Plugin | None:
    """The plug-in constructed in Python with ``params`` as given (scikit-learn's rule: stored, not checked), or None
    when its constructor refuses them itself (a rule between parameters, or work it does on them)."""
    try:
        return cls(**params)
    except Exception:  # noqa: BLE001 - whatever the constructor's own work raises: the value goes no further
        return None


def _build(cls: type[Plugin], params: dict[str, Any]) -> Plugin:
    """The plug-in as footzoo builds it from a config (:func:`footzoo.plugins.registry.build`): validated, then made."""
    return cls(**cls.validate_params(params))


def _check_params(cls: type[Plugin], p: Plugin) -> None:
    defaults = cls.defaults()
    for name, default in defaults.items():
        assert default is not inspect.Parameter.empty, f"{cls.__name__}: parameter {name!r} has no default"
        numeric = isinstance(default, (int, float)) and not isinstance(default, bool)
        assert not numeric or name in cls.units, (f"{cls.__name__}: numeric parameter {name!r} has no unit: declare "
                                                  f"it in parameters (or give its unit in 'units')")
    stray = sorted(set(cls.units) - set(defaults))
    assert not stray, f"{cls.__name__}: 'units' names no parameter {stray}"
    params = p.get_params()
    again = cls(**copy.deepcopy(params)).get_params()
    assert _equal(params, again), f"{cls.__name__}: constructing from get_params() changes them: {params} -> {again}"
    q = p.clone()
    if params:
        name = next(iter(params))
        assert q.set_params(**{name: copy.deepcopy(params[name])}) is q, f"{cls.__name__}: set_params must return self"
        assert _equal(q.get_params(), params), f"{cls.__name__}: set_params to the same value changed parameters"
    try:
        q.set_params(no_such_parameter_xyz=1)
    except ConfigError:
        pass
    except Exception as err:  # noqa: BLE001 - the check reports what it got
        raise AssertionError(f"{cls.__name__}: set_params refused an unknown parameter with {type(err).__name__}, "
                             "not a ConfigError (Plugin.set_params raises one)") from None
    else:
        raise AssertionError(f"{cls.__name__}: set_params accepted an unknown parameter")


def _check_round_trip(cls: type[Plugin], p: Plugin) -> None:
    spec = p.spec()
    text = yaml.safe_dump(spec)
    back = build(cls.kind, yaml.safe_load(text), where="check_plugin")
    assert type(back) is cls, f"{cls.__name__}: YAML round trip built {type(back).__name__}"
    assert _equal(back.get_params(), p.get_params()), f"{cls.__name__}: YAML round trip changed the parameters"
    c = p.clone()
    assert c is not p and _equal(c.get_params(), p.get_params()), f"{cls.__name__}: clone() differs"
    fitted = [k for k in vars(c) if k.endswith("_") and not k.startswith("_")]
    assert not fitted, f"{cls.__name__}: a fresh instance already has results {fitted} (set them in the action method)"


def _equal(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple, np.ndarray)) or isinstance(b, (list, tuple, np.ndarray)):
        try:
            return bool(np.array_equal(np.asarray(a, dtype=object), np.asarray(b, dtype=object)))
        except Exception:
            return False
    return a == b or (isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b))


# --------------------------------------------------------------------------- behaviour
def _signals(rec) -> tuple[np.ndarray, ...]:
    return rec.t.copy(), rec.acc.copy(), rec.gyr.copy(), rec.mag.copy()


def _unchanged(before: tuple[np.ndarray, ...], after: tuple[np.ndarray, ...], who: str) -> None:
    for a, b in zip(before, after, strict=True):
        assert np.array_equal(a, b), f"{who}: the action method modified its input arrays"


def _stance(rec) -> np.ndarray:
    return rec.truth.stance.copy()


def _check_detector(d: Detector) -> None:
    rec = _walk()
    t, acc, gyr, mag = _signals(rec)
    who = f"detector {d.name!r}"
    args = (t, acc, gyr, rec.truth) if d.needs_truth else (t, acc, gyr)
    out = checked(d.clone().detect, *args)
    assert out is not None, f"{who}: detect() must return self"
    _unchanged((rec.t, rec.acc, rec.gyr), (t, acc, gyr), who)
    stance = np.asarray(out.stance_)
    assert stance.shape == t.shape and stance.dtype == bool, f"{who}: stance_ must be (N,) bool, got {stance.dtype}"
    assert np.asarray(out.statistic_).shape == t.shape, f"{who}: statistic_ must be (N,)"
    assert stance.any() and not stance.all(), f"{who}: found no stance or no swing in a simulated walk"
    if d.incremental() and not d.needs_truth:
        _check_live(who, d, (RunContext.of(rec),), {"t": t, "acc": acc, "gyr": gyr}, {"stance": stance})


def _check_live(who: str, block: Plugin, begin: tuple, inputs: dict[str, np.ndarray],
                expected: dict[str, np.ndarray], step: str = "step") -> None:
    """The incremental protocol against the batch outputs: chunks of random sizes, then one sample at a time."""
    lat = checked(block.latency, begin[0])
    assert isinstance(lat, Latency), f"{who}: latency(ctx) must return a footzoo.plugins.incremental.Latency"
    n = len(next(iter(inputs.values())))
    rng = np.random.default_rng(0)
    for sizes in (rng.integers(1, 40, size=64), np.ones(1, dtype=int)):
        live = block.clone()
        checked(live.begin, *begin)
        parts, k, i = [], 0, 0
        stop = n if sizes.size > 1 else min(n, 300)  # one sample at a time: the first 3 s
        while k < stop:
            m = min(int(sizes[i % sizes.size]), stop - k)
            parts.append(checked(getattr(live, step), *(v[k:k + m] for v in inputs.values())))
            k, i = k + m, i + 1
            if i % 9 == 0:  # a guess for (at most) the samples pushed but not final
                pending = k - len(concat(parts).get(next(iter(expected)), ()))
                for key, value in checked(live.provisional).items():
                    assert len(value) <= pending, (f"{who}: provisional() gives {len(value)} {key!r} for "
                                                   f"{pending} pending samples")
        parts.append(checked(live.finish))
        out = concat(parts)
        for key, want in expected.items():
            got = np.asarray(out.get(key, np.zeros(0)))
            assert got.shape == np.asarray(want[:stop]).shape, (
                f"{who}: fed in chunks, {step}() and finish() gave {key!r} for {got.shape[0]} of {stop} samples")
            same = np.array_equal(got, want[:stop]) if got.dtype == bool else np.allclose(got, want[:stop], rtol=0,
                                                                                          atol=1e-9)
            if not same and sizes.size == 1 and stop < n:
                continue  # the first seconds alone: the batch saw what followed them (a look-ahead)
            assert same, f"{who}: fed in chunks, its final {key!r} differs from the batch (check latency and restart)"


def _check_calibration(c: Calibration) -> None:
    rec = _walk()
    t, acc, gyr, mag = _signals(rec)
    who = f"calibration {c.name!r}"
    for m in (mag, None):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = checked(c.clone().calibrate, t, acc, gyr, m)
        _unchanged((rec.t, rec.acc, rec.gyr, rec.mag), (t, acc, gyr, mag), who)
        for name, before in (("acc", acc), ("gyr", gyr), ("mag", m)):
            after = getattr(out, f"{name}_", "missing")
            if before is None:
                assert after is None, f"{who}: without a magnetometer, mag_ must be None"
                continue
            assert isinstance(after, np.ndarray) and after.shape == before.shape and np.isfinite(after).all(), (
                f"{who}: {name}_ must be a finite array shaped like the input {before.shape}")
        assert isinstance(out.report_, dict), f"{who}: report_ must be a dict"
        try:
            yaml.safe_dump(out.report_)
        except yaml.YAMLError as err:
            raise AssertionError(f"{who}: report_ must hold plain values (numbers, text, lists): {err}") from None


def _check_orientation(o: Orientation) -> None:
    rec = _walk()
    t, acc, gyr, mag = _signals(rec)
    who = f"orientation {o.name!r}"
    q0 = rec.truth.quat[0].copy()
    out = checked(o.clone().estimate, t, acc, gyr, mag, _stance(rec), q0)
    _unchanged((rec.t, rec.acc, rec.gyr, rec.mag), (t, acc, gyr, mag), who)
    quat = np.asarray(out.quat_)
    assert quat.shape == (len(t), 4) and np.isfinite(quat).all(), f"{who}: quat_ must be finite (N, 4)"
    assert np.allclose(np.linalg.norm(quat, axis=1), 1.0, atol=1e-6), f"{who}: quat_ must be unit quaternions"
    if o.incremental():
        _check_live(who, o, (RunContext.of(rec), q0), {"t": t, "acc": acc, "gyr": gyr, "mag": mag,
                                                       "stance": _stance(rec)}, {"quat": quat})


def _check_batch_correction(c: Plugin) -> None:
    rec = _walk()
    who = f"correction {c.name!r}"
    t = rec.t.copy()
    acc_nav = motion_acceleration(rec.truth.quat, rec.acc, 9.81)
    before = acc_nav.copy()
    stance = _stance(rec)
    if isinstance(c, VelocityCorrection):
        out = checked(c.clone().apply, t, acc_nav, stance)
        _unchanged((before,), (acc_nav,), who)
        assert out.vel_.shape == acc_nav.shape and out.pos_.shape == acc_nav.shape, f"{who}: vel_/pos_ must be (N, 3)"
        assert np.isfinite(out.pos_).all(), f"{who}: non-finite positions"
        if c.incremental():
            _check_live(who, c, (RunContext.of(rec),), {"t": t, "acc_nav": acc_nav, "stance": stance},
                        {"vel": out.vel_, "pos": out.pos_})
    if isinstance(c, AccelerationCorrection):
        new = checked(c.clone().apply_acceleration, rec.truth.quat.copy(), acc_nav, stance)
        _unchanged((before,), (acc_nav,), who)
        assert np.shape(new) == acc_nav.shape and np.isfinite(new).all(), f"{who}: must return a finite (N, 3) array"
        if c.incremental():
            _check_live(who, c, (RunContext.of(rec),), {"quat": rec.truth.quat, "acc_nav": acc_nav,
                                                        "stance": stance}, {"acc_nav": new}, step="step_acceleration")


def _check_kalman(c: KalmanCorrection) -> None:
    rec = _walk()
    who = f"correction {c.name!r}"
    base = {"orientation": {"type": "ins"}, "detector": {"type": "dgp", "min_swing": 0.2}}
    host = [] if any(q in c.observes for q in ("velocity",)) else [{"type": "zupt"}]
    if "heading" in c.observes:
        host = [{"type": "ekf_zupt"}]
    spec = c.spec()
    try:
        pipe = Pipeline.from_dict({**base, "corrections": host + [spec]})
    except FootzooError as err:
        raise AssertionError(f"{who}: cannot be used with orientation ins, detector dgp and {host}: {err}") from None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        auto = pipe.run(rec, engine="auto")
    ref = pipe.run(rec, engine="reference")
    assert np.isfinite(ref.pos).all(), f"{who}: non-finite trajectory on the reference engine"
    _close(auto, ref, who, "engine='auto'")
    if auto.config["engine"] == "fast":
        _close(pipe.run(rec, engine="fast"), ref, who, "engine='fast'")
    else:
        assert any(c.name in str(w.message) for w in caught), f"{who}: fell back to the reference engine silently"
    if c.causal:
        live = Stream(pipe, rate=rec.rate, guess=False).run(rec, chunk=np.array([1, 5, 17, 3]))
        assert np.array_equal(live["stance"], auto.stance), f"{who}: live stance differs from the batch"
        scale = max(float(np.abs(auto.pos).max()), 1.0)
        err = float(np.abs(live["pos"] - auto.pos).max())
        assert err <= 1e-9 * scale, f"{who}: live trajectory differs from the batch by {err:.3g} m"


def _close(a, b, who: str, what: str) -> None:
    scale = max(float(np.abs(b.pos).max()), 1.0)
    err = max(float(np.abs(a.pos - b.pos).max()), float(np.abs(a.quat - b.quat).max()) * scale)
    assert err <= 1e-9 * scale, f"{who}: {what} differs from the reference engine by {err:.3g}"


def _check_analysis(a: Analysis) -> None:
    rec = _walk()
    who = f"analysis {a.name!r}"
    res = Pipeline.from_dict({"orientation": {"type": "madgwick"}, "detector": {"type": "shoe"},
                              "corrections": [{"type": "zvu_dedrift"}]}).run(rec)
    t, quat, pos, stance = rec.t.copy(), res.quat.copy(), res.pos.copy(), res.stance.copy()
    out = checked(a.clone().analyze, t, quat, pos, stance, dict(rec.meta, foot="right"))
    _unchanged((rec.t, res.quat, res.pos), (t, quat, pos), who)
    steps = checked(out.annotate, res.steps.copy(), t)
    assert len(steps) == len(res.steps), f"{who}: annotate() must keep one row per step"


def main(argv: list[str] | None = None) -> int:
    """``python -m footzoo.apps.testing PLUGIN.py|module [...]``: check every plug-in the files register."""

    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: python -m footzoo.apps.testing PLUGIN.py|module [...]: run check_plugin on every plug-in "
              "they register")
        return 0 if argv else 2
    try:
        modules = {info["module"] for info in load_plugins(argv)}
    except FootzooError as err:
        print(f"footzoo: error: {err}", file=sys.stderr)
        return 2
    found = [c for k in KINDS for c in available(k).values() if c.__module__ in modules]
    if not found:
        readers = _readers_in(modules)
        if readers:
            print(f"{', '.join(argv)} defines the reader {', '.join(readers)} and no pipeline plug-in: check_plugin "
                  "checks calibrations, orientations, detectors, corrections and analyses. A reader is registered by "
                  "an entry point of the group footzoo.readers (see 'Bring your own format' in the docs); try it on a "
                  "file with footzoo.load(FILE, format=NAME) and `footzoo formats`", file=sys.stderr)
        else:
            print(f"no plug-in is registered by {', '.join(argv)} (decorate the classes with @footzoo.register)",
                  file=sys.stderr)
        return 2
    failed = 0
    for cls in found:
        try:
            check_plugin(cls, verbose=True)
        except AssertionError as err:
            failed += 1
            print(f"check_plugin: {cls.kind} {cls.name!r} FAILED: {err}", file=sys.stderr)
    return 1 if failed else 0


def _readers_in(modules: set[str]) -> list[str]:
    """The reader classes (:class:`footzoo.io.Reader` subclasses) the modules define."""
    return sorted(obj.__name__ for name in modules for obj in vars(sys.modules[name]).values()
                  if isinstance(obj, type) and issubclass(obj, Reader) and obj is not Reader
                  and obj.__module__ == name)


if __name__ == "__main__":
    sys.exit(main())
