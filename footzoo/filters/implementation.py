"""The interface of the Kalman engine's implementations, and what they share.

:class:`Setup` is the assembled filter (state layout, initial covariance, process noise, gravity,
the corrections' models); :class:`Implementation` is what runs it: :meth:`~Implementation.start`,
:meth:`~Implementation.advance` over a chunk, :meth:`~Implementation.diagnostics`, and a whole
recording with a smoother (:meth:`~Implementation.run`). Two implement it: the compiled loop
(:class:`footzoo.filters.compiled.CompiledEngine`) and filterpy's (the reference,
:class:`footzoo.filters.reference.ReferenceEngine`); a test keeps them equal to 1e-9.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..core.errors import PluginError
from ..kernels.functions import trusted
from .eskf import Layout
from .measurement import BAD_ROW, CORE_BLOCKS, ROW_PROBLEMS, ROWS_PER_PROBLEM, MeasurementModel
from .process_noise import Noise
from .recorders import SAMPLE_KEYS, from_columns
from .smoothing import Smoothing
from .structures import Offsets, Trajectory

#: The per-sample outputs a run returns, (N, 3) but ``quat`` (N, 4).
TRAJECTORY = ("quat", "vel", "pos", "gyro_bias", "acc_bias")


@dataclass
class Setup:
    """The assembled error-state filter both implementations run.

    ``layout``; ``p0`` (n,) initial variances; ``noise`` the process noise; ``gravity`` m/s²;
    ``carries_attitude`` (else the attitude comes from ``quat_ext``); ``models`` the corrections'
    measurement models (compiled for the compiled engine); ``idx`` each model's ``ctx.idx``;
    ``names`` the models' names in messages.
    """

    layout: Layout
    p0: np.ndarray
    noise: Noise
    gravity: float
    carries_attitude: bool
    models: list[MeasurementModel]
    idx: list[np.ndarray]
    names: list[str]

    @property
    def offsets(self) -> Offsets:
        """The INS core's blocks' offsets (−1 where absent)."""
        return Offsets(*(self.layout[b].start if self.layout.has(b) else -1 for b in CORE_BLOCKS))

    @property
    def m_max(self) -> int:
        """Most measurement rows of one sample (at least 1)."""
        return max(1, sum(int(m.max_rows) for m in self.models))


class Implementation(ABC):
    """How a :class:`Setup` is run (module docstring)."""

    #: ``"fast"`` or ``"reference"``: the engine's name in results.
    name: ClassVar[str]

    def __init__(self, setup: Setup):
        self.setup = setup

    @abstractmethod
    def start(self, nav0: np.ndarray) -> Any:
        """The filter's state before sample 0 (the nominal state ``nav0`` (16,), ``P = diag(p0)``, the models'
        memory), resumable with :meth:`advance`."""

    @abstractmethod
    def advance(self, state: Any, t, acc, gyr, stance, quat_ext, data: list[np.ndarray | None], k0: int,
                covariance: bool, record: bool) -> dict[str, np.ndarray]:
        """Run samples 1… of a chunk from ``state`` (updated); row 0 of the outputs is the incoming state.

        Returns ``quat`` (N, 4), ``vel``, ``pos``, ``acc_nav``, ``gyro_bias``, ``acc_bias`` (N, 3) and, with
        ``covariance``, ``P_diag`` (N, n), ``nis`` (N,) and ``nis_rows`` (N,) int; with ``record``, the record's columns
        (:func:`footzoo.filters.recorders.columns`).
        """

    @abstractmethod
    def fork(self, state: Any) -> Any:
        """An independent copy of a state."""

    @abstractmethod
    def memories(self, state: Any) -> list[np.ndarray]:
        """Each model's memory in ``state``."""

    @abstractmethod
    def run(self, t, acc, gyr, stance, q0, quat_ext, covariance: bool, smoothing: Any) -> dict[str, Any]:
        """A whole recording with ``smoothing`` (:mod:`footzoo.filters.smoothing`); the outputs of
        :meth:`advance` (smoothed, the forward ones as ``*_forward``) and ``diagnostics``."""

    def diagnostics(self, state: Any) -> dict[str, Any]:
        """The models' results (e.g. a calibration) from their memory."""
        diag: dict[str, Any] = {}
        for m, mem in zip(self.setup.models, self.memories(state), strict=True):
            if m.diagnostics is not None:
                diag.update(m.diagnostics(mem))
        return diag

    def smooth(self, rows: dict[str, np.ndarray], ends: np.ndarray, smoothing: Smoothing) -> None:
        """Smooth ``rows`` (a chunk's ``t`` and outputs with its record's columns, sample k in row k) in place,
        segment by segment up to each of ``ends``, as ``smoothing`` does (:meth:`Smoothing.smooth`)."""
        rec = from_columns({k: rows[k] for k in SAMPLE_KEYS}, rows)
        traj = Trajectory(*(rows[k] for k in TRAJECTORY))
        smoothing.smooth(rec, np.asarray(ends, np.int64), self.setup.offsets, not self.setup.carries_attitude, traj,
                         rows["t"])

    def initial_nav(self, q0: np.ndarray, quat_ext: np.ndarray | None) -> np.ndarray:
        """The nominal state at sample 0: the attitude ``quat_ext[0]`` or ``q0``, at rest at the origin."""
        nav0 = np.zeros(16)
        nav0[:4] = quat_ext[0] if quat_ext is not None else q0
        return nav0


class RowCountError(TypeError):
    """A model's ``measure`` returned something that is not a row count (None, a fraction, an array)."""


def model_fault(setup: Setup, j: int, rows: int, k: int, caught: list[BaseException], where: str) -> PluginError:
    """The :class:`~footzoo.core.errors.PluginError` of model ``j`` (−1: not known) that broke its contract at
    sample ``k`` in ``where`` (the engine's loop): a row count ``rows`` outside ``[m, m + max_rows]`` (or, from
    :data:`~footzoo.filters.measurement.BAD_ROW` on, a row no update can use), or an
    exception ``caught`` in one of its functions."""
    names, models = setup.names, setup.models
    suspects = [name for name, m in zip(names, models, strict=True)
                if not all(trusted(fn) for fn in (m.measure, m.feedback, m.after))] or names
    who = names[j] if j >= 0 else suspects[0] if len(suspects) == 1 else "one of " + ", ".join(suspects)
    if caught and isinstance(caught[0], RowCountError):
        return PluginError(f"{who}: its measure function {caught[0]} at sample {k}", plugin=who, method="measure")
    if caught:  # a bounds-checked write failed (the call then returns 0, which may also look like a row count)
        err = caught[0]
        text = f"{type(err).__name__}: {err}" if str(err) else type(err).__name__
        hint = ", or run engine='reference' to see the failing line" if "compiled" in where else ""
        return PluginError(f"{who}: a measurement function failed inside {where} ({text}) at sample {k} or before; "
                           "a write outside the rows its model declares (max_rows) or outside its par/mem/data "
                           f"arrays is refused: fix the function{hint}", plugin=who, method="measure")
    if rows >= BAD_ROW:
        problem, row = divmod(rows - BAD_ROW, ROWS_PER_PROBLEM)
        return PluginError(f"{who}: its measure function wrote a row no Kalman update can use at sample {k}: row {row} "
                           f"of its own has {ROW_PROBLEMS[problem]}; write a positive, finite variance R and finite z "
                           "and H (skip the row, return m unchanged, when there is nothing to measure)",
                           plugin=who, method="measure")
    fix = "return m plus the rows written (at most max_rows), or raise max_rows in its MeasurementModel"
    if rows >= 0:
        problem = f"returned {rows} rows at sample {k}, but its model declares max_rows={models[j].max_rows}"
    else:
        problem = f"returned a row count {-rows} below the first free row it was given (sample {k})"
    return PluginError(f"{who}: its measure function {problem}; {fix}", plugin=who, method="measure")
