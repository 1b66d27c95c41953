"""Plug-in kinds as base classes: what each kind takes, does, returns and declares.

Every plug-in (built-in or yours) derives from one of :class:`Orientation`, :class:`Detector`,
:class:`VelocityCorrection`, :class:`AccelerationCorrection`, :class:`KalmanCorrection`,
:class:`Analysis` or :class:`Calibration`, and is made available by name with :func:`footzoo.register`. The rules, as in
scikit-learn:

* ``__init__`` takes every parameter as a keyword with its paper's default, stores it under the
  same name, and does nothing else that depends on data;
* ``parameters`` declares each of them once (:mod:`footzoo.core.params`: type, unit, accepted
  range, one line of meaning, the source of the default). The declarations are checked where a
  plug-in is put to use, not in ``__init__`` (which runs as written): :meth:`Plugin.validate_params`
  validates and converts the arguments of a config before :func:`footzoo.plugins.registry.build`
  constructs the plug-in, :meth:`Plugin.set_params` does the same, a
  :class:`~footzoo.runtime.pipeline.Pipeline` calls :meth:`Plugin.check_params` on every block it is
  given, and so does each action method (and ``begin``) before it runs (:data:`CHECKS_PARAMS`), so
  ``SHOE(threshold=-1).detect(...)`` in a script is refused as the config would be. The
  declarations also drive ``footzoo list``, the documentation and the fuzz tests.
  ``paper`` gives the reference, the class docstring the equations. (A plug-in without
  declarations, with a ``units`` dict and its own checks in ``__init__``, works too;
  ``check_plugin`` then suggests declaring.)
* the one action method (``calibrate``, ``estimate``, ``detect``, ``apply``, ``apply_acceleration``,
  ``analyze``; a Kalman correction's ``model``) sets results as attributes ending in ``_`` and
  returns ``self`` (or the corrected array);
* capabilities are class attributes the pipeline reads instead of names: ``needs_magnetometer``,
  ``needs_truth``, ``needs_distance``, ``causal`` (the output at a sample depends only on samples
  up to it, so it can run live in :class:`footzoo.runtime.stream.Stream`).

The classes are plain :mod:`abc` classes: a method a kind requires is an ``abc.abstractmethod``
(``Calibration.calibrate``, ``KalmanCorrection.model``, ``Analysis.analyze`` and ``annotate``);
an optional one has a default implementation (a detector writes ``detect``, or ``step`` and gets
``detect`` from it). footzoo wraps a plug-in's methods only to check its parameters first
(:data:`CHECKS_PARAMS`, when its class is defined); its callers check the contract at each call
(:func:`footzoo.plugins.contract.checked`), and
``footzoo.apps.testing.check_plugin`` runs a plug-in through it.
"""

from __future__ import annotations

import abc
import copy
import functools
import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..core.context import RunContext
from ..core.errors import ConfigError, FootzooError, PluginError, did_you_mean
from ..core.params import (  # noqa: F401 - Real ... File: the declaration vocabulary, re-exported for plug-ins
    REQUIRED,
    Boolean,
    Choice,
    Declared,
    File,
    Integer,
    Param,
    Real,
    Vector,
    Vectors,
    declared,
)
from ..filters.measurement import MeasurementModel, StateBlock
from .contract import ACTIONS, Output, checked, inputs_checked_once  # noqa: F401 - the callers' side of the contract
from .incremental import WHOLE_RECORDING, Chunk, Latency, concat

#: The methods that put a plug-in to use: each checks the parameters (:meth:`Plugin.check_params`) before it runs,
#: so a plug-in constructed in Python with a value its declaration refuses is refused where it is used, as a
#: config's is when the plug-in is built (``__init__`` stores what it is given, scikit-learn's rule).
CHECKS_PARAMS = (*ACTIONS, "model", "begin")


def _checking_params(method: Callable[..., Any]) -> Callable[..., Any]:
    """``method``, checking its plug-in's parameters (:meth:`Plugin.check_params`) before it runs."""
    if getattr(method, "_footzoo_checks_params", False):
        return method

    @functools.wraps(method)
    def checking(self: Plugin, *args: Any, **kwargs: Any) -> Any:
        _run_check_params(self)
        return method(self, *args, **kwargs)

    checking._footzoo_checks_params = True  # type: ignore[attr-defined]
    return checking


def _run_check_params(plugin: Plugin) -> None:
    """``plugin.check_params()``; a plug-in's own override raising anything but a footzoo error (or not callable)
    is a :class:`PluginError` naming the plug-in, not a bare traceback."""
    try:
        plugin.check_params()
    except FootzooError:
        raise
    except Exception as err:  # noqa: BLE001 - a plug-in's own check_params: any error is the plug-in's fault
        who = f"{plugin.kind or 'plug-in'} {plugin.name or type(plugin).__name__!r}"
        raise PluginError(f"{who}: its check_params raised {type(err).__name__}: {err}; check_params must return "
                          "the plug-in or raise footzoo.ConfigError naming the refused parameter, its value and the "
                          "accepted range (or call super().check_params())", plugin=who,
                          method="check_params") from err


class Plugin(abc.ABC):  # noqa: B024 - the kinds below declare the methods a plug-in must write
    """Base of every plug-in: parameters in ``__init__``, estimates in attributes ending in ``_``."""

    kind: ClassVar[str] = ""
    name: ClassVar[str] = ""
    paper: ClassVar[str] = ""
    #: The declaration of each parameter (:mod:`footzoo.core.params`), new or changed in this class.
    parameters: ClassVar[dict[str, Param]] = {}
    #: The unit of each parameter (derived from ``parameters`` when the class declares them).
    units: ClassVar[dict[str, str]] = {}
    needs_magnetometer: ClassVar[bool] = False
    needs_truth: ClassVar[bool] = False
    needs_distance: ClassVar[bool] = False
    causal: ClassVar[bool] = False
    #: The per-sample outputs of the kind (attributes ``<name>_`` of the action method, columns of ``step``),
    #: checked on return by the caller (:func:`footzoo.plugins.contract.checked`).
    outputs: ClassVar[dict[str, Output]] = {}

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Check the class's parameter declarations when it is defined (see :func:`_declare`); its methods of
        :data:`CHECKS_PARAMS` check the parameters before they run."""
        super().__init_subclass__(**kwargs)
        _declare(cls)
        for name in CHECKS_PARAMS:
            method = cls.__dict__.get(name)
            if inspect.isfunction(method):
                setattr(cls, name, _checking_params(method))

    @classmethod
    def param_names(cls) -> list[str]:
        """The constructor's parameter names, in order."""
        sig = inspect.signature(cls.__init__)
        return [p for p, v in sig.parameters.items() if p != "self" and v.kind not in (v.VAR_POSITIONAL, v.VAR_KEYWORD)]

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """The constructor's defaults (the paper's values; ``inspect.Parameter.empty`` for a required one)."""
        sig = inspect.signature(cls.__init__)
        return {p: sig.parameters[p].default for p in cls.param_names()}

    @classmethod
    def declaration(cls) -> dict[str, Declared]:
        """``{name: Declared}`` of the declared parameters, in the constructor's order (:mod:`footzoo.core.params`)."""
        cached = cls.__dict__.get("_footzoo_declaration")
        return dict(cached) if cached is not None else _declaration(cls)

    @classmethod
    def undeclared(cls) -> list[str]:
        """The constructor's parameters without a declaration."""
        decl = cls.declaration()
        return [p for p in cls.param_names() if p not in decl]

    @classmethod
    def validate_params(cls, params: Mapping[str, Any]) -> dict[str, Any]:
        """The constructor's arguments for ``params``: every declared parameter validated, in its declared type.

        Each declared parameter comes back — the value given in ``params``, else its default —
        equal to what it was, converted (an int given for a float as that float, a tuple for a
        vector as a list); undeclared arguments pass as they are. :func:`footzoo.plugins.registry.build`
        and :meth:`set_params` construct a plug-in from the arguments this returns.

        Raises
        ------
        ConfigError
            A value its declaration refuses, naming the parameter, the unit, the accepted range and the fix.
        """
        out = dict(params)
        for name, d in cls.declaration().items():
            if name in params or d.default is not REQUIRED:
                out[name] = d.validate(params[name] if name in params else d.default)
        return out

    def check_params(self) -> Plugin:
        """Refuse a declared parameter whose current value its declaration refuses; returns ``self``.

        A plug-in constructed in Python (``SHOE(threshold=35)``) stores what it was given; a
        :class:`~footzoo.runtime.pipeline.Pipeline` calls this on each block it is given, and each
        method of :data:`CHECKS_PARAMS` before it runs.

        Raises
        ------
        ConfigError
            As :meth:`validate_params`, prefixed with the plug-in's kind and name.
        """
        try:
            self.validate_params(self.get_params())
        except ConfigError as err:
            raise ConfigError(f"{self.kind} {self.name!r}: {err}") from None
        return self

    def get_params(self, deep: bool = True) -> dict[str, Any]:
        """Current parameter values (scikit-learn style; ``deep`` is accepted for compatibility)."""
        return {p: getattr(self, p) for p in self.param_names()}

    def set_params(self, **params: Any) -> Plugin:
        """Change parameters, validated against their declarations (:meth:`validate_params`); returns ``self``.

        Raises
        ------
        ConfigError
            An unknown parameter (with a did-you-mean) or a value the constructor refuses.
        """
        names = self.param_names()
        for key in params:
            if key not in names:
                raise ConfigError(f"{self.kind} {self.name!r}: unknown parameter {key!r}"
                                  f"{did_you_mean(key, names)}; valid parameters: {names}")
        try:
            fresh = type(self)(**self.validate_params({**self.get_params(), **params}))
        except (TypeError, ValueError) as err:  # ConfigError is a ValueError; a plug-in's own checks may raise either
            raise ConfigError(f"{self.kind} {self.name!r}: {err}") from None
        self.__dict__.clear()
        self.__dict__.update(fresh.__dict__)
        return self

    def clone(self) -> Plugin:
        """An unfitted copy with the same parameters."""
        return type(self)(**copy.deepcopy(self.get_params()))

    def spec(self) -> dict[str, Any]:
        """``{"type": name, **params}``: the YAML form."""
        return {"type": self.name, **_plain(self.get_params())}

    @classmethod
    def capabilities(cls) -> dict[str, Any]:
        """The declared capabilities, for listings and checks."""
        return {k: getattr(cls, k) for k in ("needs_magnetometer", "needs_truth", "needs_distance", "causal")}

    # ------------------------------------------------------------------ the incremental protocol
    @classmethod
    def incremental(cls) -> bool:
        """Whether the class implements the incremental protocol (runs live, see :mod:`footzoo.plugins.incremental`).

        Default: no; each kind that has the protocol says whether the class implements its ``step``.
        """
        return False

    def latency(self, ctx: RunContext) -> Latency:
        """How long after a sample this block's output for it is final (:class:`~footzoo.plugins.incremental.Latency`).

        Default: none for a ``causal`` block, the whole recording for one without ``step``.
        """
        if self.causal or not self.incremental():
            return Latency() if self.causal else Latency(until=(WHOLE_RECORDING,))
        raise NotImplementedError(f"{type(self).__name__} implements step but not latency(ctx)")

    @_checking_params
    def begin(self, ctx: RunContext) -> Plugin:
        """Start a run (batch or live): fresh state for the recording of ``ctx``; returns ``self``."""
        self.ctx_ = _context(ctx)
        return self

    def finish(self) -> Chunk:
        """End of the data: the outputs of every sample not final yet (default: none pending)."""
        return {}

    def provisional(self) -> Chunk:
        """The current guess for the samples pushed but not final yet (default: none pending)."""
        return {}

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"


def check_parameters(blocks: list[Any]) -> None:
    """:meth:`Plugin.check_params` of each plug-in among ``blocks`` (a pipeline's, when it is assembled)."""
    for block in blocks:
        if isinstance(block, Plugin):
            _run_check_params(block)


def _context(ctx: Any) -> RunContext:
    """``ctx``, checked to be a :class:`RunContext`."""
    if isinstance(ctx, RunContext):
        return ctx
    hint = f": begin(RunContext(rate={ctx!r}))" if isinstance(ctx, (int, float)) and not isinstance(ctx, bool) else ""
    raise ConfigError(f"begin() takes a footzoo.core.context.RunContext, got {type(ctx).__name__} {ctx!r}{hint}")


def run_context(ctx: RunContext | None, t: np.ndarray) -> RunContext:
    """``ctx``, or the context of the time stamps alone for a plug-in called outside a pipeline."""
    return _context(ctx) if ctx is not None else RunContext.from_time(t)


def call(method: Callable[..., Any], *args: Any, ctx: RunContext) -> Any:
    """``method(*args, ctx=ctx)``, or ``method(*args)`` for an action method that takes no ``ctx``, under the
    plug-in contract (:func:`footzoo.plugins.contract.checked`).

    ``ctx`` is optional in an action method's signature: one without it computes its durations
    from the time stamps itself (and runs in batch).
    """
    if _takes_context(method):
        return checked(method, *args, ctx=ctx)
    return checked(method, *args)


@functools.lru_cache(maxsize=1024)
def _takes_context_of(function: Callable[..., Any]) -> bool:
    params = inspect.signature(function).parameters
    return "ctx" in params or any(p.kind is p.VAR_KEYWORD for p in params.values())


def _takes_context(method: Callable[..., Any]) -> bool:
    return _takes_context_of(getattr(method, "__func__", method))


def run_whole(block: Plugin, ctx: RunContext, *arrays: Any) -> Chunk:
    """A block's outputs over whole arrays through its incremental protocol: begin, one step, finish."""
    block.begin(ctx)
    return concat([block.step(*arrays), block.finish()], copy=False)


def _declaration(cls: type[Plugin]) -> dict[str, Declared]:
    defaults = {k: (REQUIRED if v is inspect.Parameter.empty else v) for k, v in cls.defaults().items()}
    return declared(cls, defaults)


def _declare(cls: type[Plugin]) -> None:
    """Bind a new plug-in class's declarations to its constructor's names and defaults (:mod:`footzoo.core.params`).

    Keeps them as ``cls._footzoo_declaration`` (see :meth:`Plugin.declaration`) and derives
    ``units`` from them unless the class sets it. Mistakes in the declarations (a name that is
    no parameter, a default the declaration refuses) raise a ``TypeError`` here, when the class
    is defined. The constructor is left as written.
    """
    decl = _declaration(cls)
    cls._footzoo_declaration = decl  # type: ignore[attr-defined]
    if decl and "units" not in cls.__dict__:
        inherited = {k: v for k, v in cls.units.items() if k in cls.param_names()}
        cls.units = {**inherited, **{n: d.param.unit for n, d in decl.items() if d.param.unit}}


def _plain(value: Any) -> Any:
    """Parameters as YAML-safe plain values."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


class Calibration(Plugin):
    """In-situ sensor calibration: fitted on the recording itself, applied before every other stage.

    ``calibrate(t, acc, gyr, mag)`` takes time (s), specific force (m/s², FRD), angular rate
    (rad/s, FRD) and the magnetometer (any unit, or None) and sets ``acc_``, ``gyr_`` and ``mag_``
    (corrected copies in the same units; ``mag_`` None without a magnetometer; the inputs are not
    changed) and ``report_`` (a dict of plain numbers, text and lists: what was fitted or why
    nothing was, shown in ``Result.diagnostics["calibration"]``). A calibration that cannot be
    fitted reliably on a recording leaves the signals as they are and says so (warning and
    ``report_``); it never guesses.

    Live, a calibration cannot see the whole recording. It takes its fit from a calibration run
    or file (:meth:`fixed`, from an earlier ``report_``; or parameters that give the fit, e.g.
    ``hard_iron: {offset: [...]}``, for which :meth:`is_fitted` is true), or fits online on the
    first seconds of the stream (:meth:`calibrate` on them; :class:`footzoo.Stream`'s ``warmup``).
    Then ``step(t, acc, gyr, mag)`` applies the fit to each new chunk
    (``{"acc", "gyr", "mag"}``). "Final = batch" means: equal to the batch run given the same fit.
    """

    kind: ClassVar[str] = "calibration"
    outputs: ClassVar[dict[str, Output]] = {"acc": Output(width=3), "gyr": Output(width=3),
                                            "mag": Output(width=3, required=False)}
    #: The signals the fit is made from: without any of them there is nothing to fit (nor to wait for, live).
    fits_on: ClassVar[tuple[str, ...]] = ("acc", "gyr", "mag")

    @abc.abstractmethod
    def calibrate(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, mag: np.ndarray | None) -> Calibration:
        """Set ``acc_``, ``gyr_``, ``mag_`` and ``report_``; returns ``self``."""

    def is_fitted(self) -> bool:
        """Whether the parameters already give the fit (nothing to fit on the data): it can run live as it is."""
        return False

    def fixed(self, report: dict[str, Any]) -> Calibration:
        """A copy whose fit is the one ``report`` (an earlier ``report_``) describes, for live use."""
        raise NotImplementedError(f"calibration {self.name!r} cannot take a fit from a report: give its fit as "
                                  "parameters, or let the stream fit it online (warmup)")

    def step(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, mag: np.ndarray | None) -> Chunk:
        """Apply the fit to the next samples: ``{"acc", "gyr", "mag"}`` (``mag`` absent without one)."""
        self.calibrate(t, acc, gyr, mag)
        out = {"acc": self.acc_, "gyr": self.gyr_}
        if mag is not None:
            out["mag"] = self.mag_
        return out

    @classmethod
    def incremental(cls) -> bool:
        """A calibration runs live once fitted (see the class docstring)."""
        return True


class Orientation(Plugin):
    """Attitude of the sensor (body → NED quaternion per sample).

    ``estimate(t, acc, gyr, mag, stance, q0)`` sets ``quat_`` ((N, 4), scalar first) from time
    (s), specific force (m/s², FRD), angular rate (rad/s), magnetometer (any unit, or None), the
    detector's stance mask and the initial attitude ``q0`` from the still start.
    ``carried_by_filter``: the attitude is a state of the error-state Kalman filter (the INS);
    the filter then propagates and corrects it and ``estimate`` is only used without a filter.
    ``use_magnetometer``: read the magnetometer (parameter or class attribute).
    """

    kind: ClassVar[str] = "orientation"
    outputs: ClassVar[dict[str, Output]] = {"quat": Output("quat", width=4)}
    carried_by_filter: ClassVar[bool] = False
    needs_stance: ClassVar[bool] = False
    use_magnetometer: bool = False

    def estimate(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, mag: np.ndarray | None,
                 stance: np.ndarray, q0: np.ndarray, ctx: RunContext | None = None) -> Orientation:
        """Set ``quat_``; returns ``self``. Default: the incremental protocol over the whole arrays."""
        self.begin(run_context(ctx, t), q0)
        out = concat([self.step(t, acc, gyr, mag, stance), self.finish()], copy=False)
        for key, value in out.items():
            setattr(self, f"{key}_", value)
        return self

    def begin(self, ctx: RunContext, q0: np.ndarray | None = None) -> Orientation:  # type: ignore[override]
        """Start a run from the attitude ``q0`` (body → NED) at the first sample; returns ``self``."""
        super().begin(ctx)
        self.q0_ = None if q0 is None else np.asarray(q0, dtype=float).reshape(4)
        return self

    def step(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, mag: np.ndarray | None,
             stance: np.ndarray) -> Chunk:
        """Push the next samples (with their final stance); ``{"quat": (m, 4)}`` of those now final."""
        raise NotImplementedError(f"orientation {self.name!r} does not implement the incremental protocol (step)")

    @classmethod
    def incremental(cls) -> bool:
        """Whether the class implements :meth:`step` (runs live)."""
        return cls.step is not Orientation.step


class Detector(Plugin):
    """Stance (zero-velocity) detection.

    ``detect(t, acc, gyr, ctx=None)`` (with ``needs_truth``: ``detect(t, acc, gyr, truth)``) sets
    ``stance_`` ((N,) bool) and ``statistic_`` ((N,) float, the test statistic, NaN if none) from
    time (s), specific force (m/s², FRD) and angular rate (rad/s, FRD); ``ctx`` is the run's
    :class:`~footzoo.core.context.RunContext` (its rate converts the detector's durations).

    Live (:mod:`footzoo.plugins.incremental`): ``begin(ctx)``, then ``step(t, acc, gyr)`` for each
    new chunk returns ``{"stance": (m,) bool, ...}`` for the ``m`` samples whose stance became
    final, ``provisional()`` the stance it would give the others now, ``finish()`` the rest at
    the end, and ``latency(ctx)`` how long after a sample its stance is final. A detector that
    implements only ``step`` gets ``detect`` for free (begin, one step, finish).
    """

    kind: ClassVar[str] = "detector"
    outputs: ClassVar[dict[str, Output]] = {"stance": Output("bool"), "statistic": Output(finite=False, required=False)}

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, ctx: RunContext | None = None) -> Detector:
        """Set ``stance_`` and ``statistic_`` (and the step outputs' other arrays); returns ``self``."""
        out = run_whole(self, run_context(ctx, t), t, acc, gyr)
        for key, value in out.items():
            setattr(self, f"{key}_", value)
        if "statistic" not in out:
            self.statistic_ = np.full(len(t), np.nan)
        return self

    def step(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
        """Push the next samples; ``{"stance": ...}`` of the samples whose stance became final."""
        raise NotImplementedError(f"detector {self.name!r} does not implement the incremental protocol (step)")

    @classmethod
    def incremental(cls) -> bool:
        """Whether the class implements :meth:`step` (runs live)."""
        return cls.step is not Detector.step


class Correction(Plugin):
    """Base of the corrections; use one of the three subclasses."""

    kind: ClassVar[str] = "correction"


class VelocityCorrection(Correction):
    """Batch velocity/position from the NED motion acceleration (e.g. zero-velocity dedrift).

    ``apply(t, acc_nav, stance)`` sets ``vel_`` and ``pos_`` ((N, 3), m/s and m). At most one per
    pipeline, and not together with Kalman corrections (both would set the velocity).
    """

    outputs: ClassVar[dict[str, Output]] = {"vel": Output(width=3), "pos": Output(width=3)}

    def apply(self, t: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray,
              ctx: RunContext | None = None) -> VelocityCorrection:
        """Set ``vel_`` and ``pos_``; returns ``self``. Default: the incremental protocol over the whole arrays."""
        out = run_whole(self, run_context(ctx, t), t, acc_nav, stance)
        for key, value in out.items():
            setattr(self, f"{key}_", value)
        return self

    def step(self, t: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> Chunk:
        """Push the next samples; ``{"vel": (m, 3), "pos": (m, 3)}`` of those now final."""
        raise NotImplementedError(f"correction {self.name!r} does not implement the incremental protocol (step)")

    @classmethod
    def incremental(cls) -> bool:
        """Whether the class implements :meth:`step` (runs live)."""
        return cls.step is not VelocityCorrection.step


class AccelerationCorrection(Correction):
    """Batch change of the NED motion acceleration before integration (e.g. heading reduction).

    ``apply_acceleration(quat, acc_nav, stance)`` returns the corrected (N, 3) acceleration (m/s²).
    A class that is also a :class:`KalmanCorrection` acts inside the filter when the pipeline has
    one, and in this batch form otherwise.
    """

    def apply_acceleration(self, quat: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray,
                           ctx: RunContext | None = None) -> np.ndarray:
        """The corrected motion acceleration (m/s², NED). Default: the incremental protocol over the whole arrays."""
        self.begin(ctx if ctx is not None else RunContext(rate=1.0))
        return concat([self.step_acceleration(quat, acc_nav, stance), self.finish()], copy=False)["acc_nav"]

    def step_acceleration(self, quat: np.ndarray, acc_nav: np.ndarray, stance: np.ndarray) -> Chunk:
        """Push the next samples; ``{"acc_nav": (m, 3)}`` of those now final (``apply_acceleration`` live)."""
        raise NotImplementedError(f"correction {self.name!r} does not implement the incremental protocol "
                                  "(step_acceleration)")

    @classmethod
    def incremental(cls) -> bool:
        """Whether the class implements :meth:`step_acceleration` (runs live)."""
        return cls.step_acceleration is not AccelerationCorrection.step_acceleration


@dataclass
class Samples:
    """Signals a Kalman correction builds its model and per-sample inputs from.

    ``t`` (N,) s; ``acc``, ``gyr`` (N, 3) m/s², rad/s; ``mag`` (N, 3) or None; ``dist`` (N, k)
    m or None; ``init_window`` (N,) bool: the still start used for the initial alignment. In a
    batch run these are the whole recording; live, :meth:`KalmanCorrection.model` sees the still
    start and :meth:`KalmanCorrection.sample_data` each new chunk.
    """

    t: np.ndarray
    acc: np.ndarray
    gyr: np.ndarray
    mag: np.ndarray | None
    dist: np.ndarray | None
    init_window: np.ndarray


class KalmanCorrection(Correction):
    """A measurement of the error-state Kalman filter, owning its model.

    Implement :meth:`model` (and :meth:`state_blocks` / :meth:`sample_data` when needed). The
    model's functions follow :mod:`footzoo.filters.measurement`; compile them with its
    decorators and the correction runs in the compiled engine and live, else on the reference
    engine (with a warning). ``observes`` names the measured quantities: two corrections that
    observe the same quantity cannot be combined.
    """

    observes: ClassVar[tuple[str, ...]] = ()
    causal: ClassVar[bool] = True

    def state_blocks(self) -> list[StateBlock]:
        """Error-state blocks this correction adds or switches on (``gyro_bias``, ``acc_bias``)."""
        return []

    def requires_attitude_state(self) -> bool:
        """Whether the model needs the attitude error as a state (``orientation: ins``)."""
        return False

    def sample_data(self, samples: Samples) -> np.ndarray:
        """Per-sample inputs of the model, (N, d); default: none."""
        return np.zeros((len(samples.t), 0))

    @abc.abstractmethod
    def model(self, samples: Samples) -> MeasurementModel:
        """The measurement model for a run that starts with ``samples`` (see :class:`Samples`)."""


class Analysis(Plugin):
    """Analysis of a finished trajectory (e.g. foot progression angle per stride).

    ``analyze(t, quat, pos, stance, meta)`` sets its results; ``annotate(steps, t)`` returns the
    steps table with its columns added.
    """

    kind: ClassVar[str] = "analysis"

    @abc.abstractmethod
    def analyze(self, t: np.ndarray, quat: np.ndarray, pos: np.ndarray, stance: np.ndarray,
                meta: dict[str, Any]) -> Analysis:
        """Analyse a trajectory; returns ``self``."""

    def check(self, meta: dict[str, Any]) -> None:
        """Refuse a recording the analysis cannot use (from its metadata) before a run spends any time on it.

        Raise a footzoo error that names what is missing and the fix; default: accept every recording.
        """

    @abc.abstractmethod
    def annotate(self, steps: Any, t: np.ndarray) -> Any:
        """The steps table with this analysis' columns."""


#: Base class of each kind.
BASES: dict[str, tuple[type[Plugin], ...]] = {
    "calibration": (Calibration,),
    "orientation": (Orientation,),
    "detector": (Detector,),
    "correction": (VelocityCorrection, AccelerationCorrection, KalmanCorrection),
    "analysis": (Analysis,),
}
