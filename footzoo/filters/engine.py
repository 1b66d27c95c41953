"""The error-state Kalman engine: state layout, measurement models, a compiled or a reference implementation.

The engine takes what the plug-ins hand it — whether the attitude is a filter state, the
corrections' :class:`~footzoo.filters.measurement.StateBlock` lists and
:class:`~footzoo.filters.measurement.MeasurementModel` objects — and the INS core's noise
(:class:`NavigationNoise`). It knows no plug-in by name. It assembles them once
(:class:`~footzoo.filters.implementation.Setup`) and hands them to one implementation of
:class:`~footzoo.filters.implementation.Implementation`: ``engine="fast"`` the compiled loop
(:class:`~footzoo.filters.compiled.CompiledEngine`), ``"reference"`` the filterpy loop
(:class:`~footzoo.filters.reference.ReferenceEngine`), ``"auto"`` the compiled one when every model
compiles (else the reference, with a one-line warning saying which model and why). How a smoother
runs is :mod:`footzoo.filters.smoothing`'s business.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.checks import Settings
from ..core.errors import ConfigError, FootzooWarning, user_stacklevel
from ..core.params import Real
from .compiled import CompiledEngine
from .eskf import Layout
from .implementation import Implementation, Setup
from .measurement import CORE_BLOCKS, MeasurementModel, NotCompilable, StateBlock
from .process_noise import noise_of
from .reference import ReferenceEngine
from .smoothing import Smoothing, smoothing

ENGINES = ("auto", "fast", "reference")


@dataclass
class NavigationNoise(Settings):
    """Process noise and initial uncertainty of the INS core of the error-state filter.

    Set in a pipeline's YAML under ``navigation:``, whatever the orientation source. Nguyen &
    La 2016 (Sec. VI) set ``Q = diag(1e-4·I, 0, 0, 1e-4·I, 0)`` per sample; at the 100 Hz
    their sample counts assume that is 0.01 per second for attitude (rad²) and velocity
    ((m/s)²) — the defaults. Duong & Suh 2015 (Table 1) give per-sample sensor variances;
    their config converts them.

    Parameters
    ----------
    attitude_noise : float
        Attitude error variance growth (rad²/s); used when the attitude is a filter state.
    velocity_noise : float
        Velocity error variance growth ((m/s)²/s).
    position_noise : float
        Position error variance growth (m²/s); paper: 0.
    initial_attitude_std : float
        Standard deviation of the initial attitude error (rad).
    initial_velocity_std : float
        Standard deviation of the initial velocity error (m/s); the start is still: 0.
    initial_position_std : float
        Standard deviation of the initial position error (m); the origin is the start: 0.
    impact_noise : float
        Velocity error variance growth per squared motion acceleration (s, i.e. ((m/s)²/s) per
        (m/s²)²): each velocity axis grows by ``(velocity_noise + impact_noise·|a|²)·dt``, with
        ``a`` the NED motion acceleration of the sample. Accelerometer scale-factor, misalignment
        and clipping errors grow with the acceleration, most at the heel strike (footzoo's; a
        white-noise stand-in for them; 0, the default: uniform in time, as in the papers).
    integration_noise : float
        κ (1): each velocity axis of sample k grows by ``(κ·|f_k − f_{k−1}|·dt)²``, ``f`` the
        specific force as sampled: a change of the specific force at an unknown instant within
        the interval, which a heel strike shorter than the interval makes on an accelerometer
        that is not band-limited below the Nyquist rate; 1/√12 ≈ 0.29 when that instant is
        uniform in the interval (:mod:`footzoo.filters.process_noise`). 0, the default: the
        samples resolve the motion, as the papers assume.

    A ``<term>_noise`` parameter of the velocity that follows the signals is a field ``<term>`` of
    :class:`footzoo.filters.process_noise.Noise` (:func:`~footzoo.filters.process_noise.noise_of`).
    """

    attitude_noise: float = 0.01
    velocity_noise: float = 0.01
    position_noise: float = 0.0
    initial_attitude_std: float = 0.01
    initial_velocity_std: float = 0.0
    initial_position_std: float = 0.0
    impact_noise: float = 0.0
    integration_noise: float = 0.0

    section = "navigation"
    example = "{velocity_noise: 0.01}"
    parameters = {
        "attitude_noise": Real("rad^2/s", "[0, 1]", "attitude error variance growth",
                               source="Nguyen & La 2016, Sec. VI: 1e-4 per sample at 100 Hz"),
        "velocity_noise": Real("(m/s)^2/s", "[0, 100]", "velocity error variance growth",
                               source="Nguyen & La 2016, Sec. VI: 1e-4 per sample at 100 Hz"),
        "position_noise": Real("m^2/s", "[0, 100]", "position error variance growth", source="Nguyen & La 2016: 0"),
        "initial_attitude_std": Real("rad", "[0, pi]", "σ of the initial attitude error",
                                     source="footzoo's: 0.57° after the still-start alignment"),
        "initial_velocity_std": Real("m/s", "[0, 10]", "σ of the initial velocity error",
                                     source="the start is still: 0"),
        "initial_position_std": Real("m", "[0, 100]", "σ of the initial position error",
                                     source="the origin is the start: 0"),
        "impact_noise": Real("s", "[0, 0.01]", "velocity variance growth per squared motion acceleration",
                             source="footzoo's: 0 (uniform in time, as in the papers)",
                             why="0.01 s: at a heel strike's 100 m/s² that is 100 (m/s)²/s"),
        "integration_noise": Real("1", "[0, 1]", "velocity σ per sample per |Δf|·dt (an impact the samples do not "
                                  "resolve)", source="footzoo's: 0 (the samples resolve the motion, as in the papers); "
                                  "1/√12 ≈ 0.29: the change at a uniform instant within the interval",
                                  why="1: the whole change |Δf|·dt of one interval as one σ"),
    }


def assemble(carries_attitude: bool, blocks: list[StateBlock], noise: NavigationNoise):
    """Error-state layout, initial variances and variance growth per second.

    Order (Nguyen & La eq. 31): ``att`` (when the filter carries the attitude), ``gyro_bias``,
    ``pos``, ``vel``, ``acc_bias`` (each bias only when a correction switches it on), then the
    corrections' own blocks in the order they are listed.
    """
    core: dict[str, StateBlock] = {}
    extra: list[StateBlock] = []
    for b in blocks:
        if b.name in ("gyro_bias", "acc_bias"):
            if b.size != 3:
                raise ConfigError(f"state block {b.name!r} has 3 states, a correction declared {b.size}")
            core.setdefault(b.name, b)
        elif b.name in CORE_BLOCKS:
            raise ConfigError(f"state block {b.name!r} belongs to the INS core; name a correction's block otherwise")
        else:
            extra.append(b)
    order: list[StateBlock] = []
    if carries_attitude:
        order.append(StateBlock("att", 3, noise.initial_attitude_std**2, noise.attitude_noise))
    if "gyro_bias" in core:
        order.append(core["gyro_bias"])
    order.append(StateBlock("pos", 3, noise.initial_position_std**2, noise.position_noise))
    order.append(StateBlock("vel", 3, noise.initial_velocity_std**2, noise.velocity_noise))
    if "acc_bias" in core:
        order.append(core["acc_bias"])
    order += extra
    layout = Layout([(b.name, b.size) for b in order])
    p0 = np.concatenate([np.full(b.size, float(b.initial_variance)) for b in order])
    q = np.concatenate([np.full(b.size, float(b.noise)) for b in order])
    return layout, p0, q


def block_offsets(layout: Layout, own: list[str]) -> np.ndarray:
    """``idx`` of one model: the core blocks' offsets (−1 if absent), then its own blocks'."""
    names = list(CORE_BLOCKS) + list(own)
    return np.array([layout[b].start if layout.has(b) else -1 for b in names], dtype=np.int64)


def compiled_models(models: list[MeasurementModel], names: list[str], engine: str) -> list[MeasurementModel] | None:
    """The models with their functions compiled, or None where one does not compile (``engine="auto"``: with a
    warning naming it; ``"fast"``: a :class:`~footzoo.core.errors.ConfigError`)."""
    compiled = []
    for name, m in zip(names, models, strict=True):
        try:
            compiled.append(m.compiled())
        except NotCompilable as err:
            if engine == "fast":
                raise ConfigError(f"engine='fast': {name} cannot be compiled ({err}); use engine='reference' "
                                  "or make its measurement functions numba-compilable") from None
            warnings.warn(f"{name}: measurement model not compilable ({err}); running the reference engine",
                          FootzooWarning, stacklevel=user_stacklevel())
            return None
    return compiled


class KalmanEngine:
    """One error-state filter run (or stream) over a recording, by the implementation chosen.

    Parameters
    ----------
    carries_attitude : bool
        The attitude error is a state (INS orientation); otherwise ``quat_ext`` is used.
    blocks : list of StateBlock
        All blocks the corrections declare, in order.
    models : list of MeasurementModel
        The corrections' measurement models, in stacking order.
    noise : NavigationNoise
        INS core noise.
    gravity : float
        g (m/s²).
    engine : {"auto", "fast", "reference"}
        Which implementation (module docstring).
    names : list of str, optional
        The models' names in messages (``correction '<its name>'``).

    Attributes
    ----------
    layout : Layout
        The error state's blocks.
    engine : str
        The implementation chosen: ``"fast"`` or ``"reference"``.
    implementation : Implementation
        It.
    """

    def __init__(self, carries_attitude: bool, blocks: list[StateBlock], models: list[MeasurementModel],
                 noise: NavigationNoise, gravity: float, engine: str = "auto", names: list[str] | None = None):
        if engine not in ENGINES:
            raise ConfigError(f"engine must be one of {list(ENGINES)}, got {engine!r}")
        layout, p0, q = assemble(carries_attitude, blocks, noise)
        names = names or [f"correction {i}" for i in range(len(models))]
        compiled = None if engine == "reference" else compiled_models(models, names, engine)
        setup = Setup(layout, p0, noise_of(q, noise), float(gravity), carries_attitude,
                      compiled if compiled is not None else models,
                      [block_offsets(layout, m.block_names) for m in models], names)
        self.implementation: Implementation = CompiledEngine(setup) if compiled is not None else ReferenceEngine(setup)
        self.layout = layout

    @property
    def engine(self) -> str:
        return self.implementation.name

    @property
    def setup(self) -> Setup:
        return self.implementation.setup

    def run(self, t, acc, gyr, stance, q0, quat_ext=None, covariance: bool = True,
            smoother: bool | str = False) -> dict[str, Any]:
        """Filter a whole recording; returns the trajectories and each model's diagnostics.

        With ``smoother`` (``"rts"`` or True, ``"stepwise"``: :mod:`footzoo.filters.smoothing`) the
        trajectories are the smoothed ones and the forward pass's are kept as ``quat_forward``,
        ``vel_forward``, ``pos_forward``.
        """
        return self.implementation.run(t, acc, gyr, stance, q0, quat_ext, covariance, smoothing(smoother))

    def start(self, nav0: np.ndarray) -> Any:
        """The filter's state before sample 0 (resumable with :meth:`advance`)."""
        return self.implementation.start(nav0)

    def advance(self, state: Any, t, acc, gyr, stance, quat_ext, data: list[np.ndarray | None], k0: int,
                covariance: bool = True, record: bool = False) -> dict[str, np.ndarray]:
        """Run samples 1… of a chunk from ``state`` (updated); row 0 of the outputs is the incoming state.

        ``record``: also a smoother's record of every row (the columns of
        :func:`footzoo.filters.recorders.columns`).
        """
        return self.implementation.advance(state, t, acc, gyr, stance, quat_ext, data, k0, covariance, record)

    def fork(self, state: Any) -> Any:
        """An independent copy of a state from :meth:`start` (a live stream's guess runs ahead on it)."""
        return self.implementation.fork(state)

    def diagnostics(self, state: Any) -> dict[str, Any]:
        """The models' results (e.g. a calibration) from their memory."""
        return self.implementation.diagnostics(state)

    def smooth(self, rows: dict[str, np.ndarray], ends: np.ndarray, smoother: bool | str | Smoothing) -> None:
        """Smooth ``rows`` (per-sample ``t``, ``quat``, ``vel``, ``pos``, ``gyro_bias``, ``acc_bias`` and a record's
        columns, sample k in row k) in place, segment by segment up to each of ``ends`` (increasing), as
        ``smoother`` does (:mod:`footzoo.filters.smoothing`)."""
        self.implementation.smooth(rows, ends, smoothing(smoother))


