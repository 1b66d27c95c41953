"""What a pipeline produced for one recording: :class:`Result`, with its metrics against the recording's reference.

The estimates are plain data (per-sample and per-stride tables, the resolved config, versions,
diagnostics); :attr:`Result.metrics` scores them with :mod:`footzoo.evaluation.validity` and
:mod:`footzoo.evaluation.metrics`, and :meth:`Result.save` / :meth:`Result.load` keep them in a
folder (:mod:`footzoo.core.archive`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.archive import read_result, save_result
from ..core.data import Truth
from .validity import result_metrics_checked, warn_refused


@dataclass
class Result:
    """What a pipeline produced for one recording.

    Attributes
    ----------
    samples : DataFrame
        Per sample: ``t`` (s), ``qw..qz`` (body -> NED), ``roll, pitch, yaw``
        (rad, Z-Y-X), ``pos_n, pos_e, pos_d`` (m), ``vel_n, vel_e, vel_d`` (m/s),
        ``acc_n, acc_e, acc_d`` (motion acceleration, gravity removed, m/s²),
        ``stance`` (bool).
    steps : DataFrame
        Per stride, units in the column names (see
        :func:`footzoo.analysis.strides.segment_steps`): ``start_s``, ``to_s``,
        ``end_s`` (initial contact, toe-off, next initial contact), stride, stance
        and swing time (s), ``cadence_steps_min``, ``stride_length_m``,
        ``speed_m_s``, ``heading_rad``, mid-stance positions (m),
        ``max_clearance_m``; ``fpa_rad`` with an FPA analysis.
    config : dict
        The resolved configuration (every parameter, defaults filled in).
    versions : dict
        Versions of footzoo and its numerical dependencies.
    recording : dict
        The recording's metadata.
    diagnostics : dict
        Plug-in statistics (e.g. detector test statistic), arrays by name.
    reference : Truth or None
        The recording's reference (simulator truth, VICON, motion-capture events,
        footprints, hand-counted strides), used by :attr:`metrics`.
    """

    samples: pd.DataFrame
    steps: pd.DataFrame
    config: dict[str, Any]
    versions: dict[str, str]
    recording: dict[str, Any] = field(default_factory=dict)
    diagnostics: dict[str, Any] = field(default_factory=dict)
    reference: Truth | None = None

    def __repr__(self) -> str:
        name = self.recording.get("name", "recording")
        return (f"Result({self.config.get('name', 'pipeline')!r} on {name!r}, {len(self.samples)} samples, "
                f"{len(self.steps)} strides, reference={'yes' if self.reference is not None else 'no'})")

    @property
    def metrics(self) -> dict[str, float]:
        """Summary and errors against the recording's reference, one number per key (units in the keys).

        Always: ``duration_s``, ``path_length_m`` (horizontal), ``strides``,
        median ``stride_time_s``, ``cadence_steps_min``, ``stride_length_m``,
        ``stance_time_s``, ``swing_time_s``. With a closed-loop reference: loop
        closure. With reference positions: ``armse_3d_m`` (after a least-squares
        yaw alignment) and ``pyshoe_error_m``. With a hand count:
        ``stride_count_ref``, ``stride_count_error``. With reference strides: the
        matched count and the median absolute IC/TO errors (s), stride-length
        RMS and mean error (m) over every matched stride and over the straight
        ones (``..._straight_m``), stride-time and FPA errors
        (:func:`footzoo.evaluation.metrics.stride_errors`). With footprints: per-footprint
        error after a 2-D rigid alignment. With per-stride trajectories: the
        median per-stride 3-D path RMS after a yaw alignment. See :func:`footzoo.evaluation.metrics.result_metrics`.

        A metric the reference cannot score (fragmented stance labels, missing events, too few
        strides: :mod:`footzoo.evaluation.validity`, the rules studies apply) is NaN, with a
        :class:`~footzoo.evaluation.validity.MetricWarning`; :attr:`metric_notes` gives the reasons.
        """
        values, notes = self._checked_metrics()
        warn_refused(f"{self.recording.get('name', 'recording')}", notes)
        return values

    @property
    def metric_notes(self) -> dict[str, str]:
        """Why each NaN of :attr:`metrics` is NaN: metric -> reason (empty when every metric could be scored)."""
        return self._checked_metrics()[1]

    def checked_metrics(self) -> tuple[dict[str, float], dict[str, str]]:
        """:attr:`metrics` and :attr:`metric_notes` in one computation, without the warning: for callers that
        keep or show the reasons themselves (:meth:`save` writes them into ``metrics.json``)."""
        return self._checked_metrics()

    def _checked_metrics(self) -> tuple[dict[str, float], dict[str, str]]:
        t = self.samples["t"].to_numpy()
        return result_metrics_checked(t, self.pos, self.steps, self.reference)

    def save(self, path: str | os.PathLike, backend: str = "auto", inputs: Any = (),
             files: dict[str, bytes] | None = None) -> Path:
        """Save as a folder: tables, metrics, config, versions, metadata, diagnostics and the reference.

        Lossless and self-describing (a ``manifest.json`` says what each file holds, written last:
        a folder without it, or with ``.footzoo-incomplete``, is refused by :meth:`load` as
        incomplete); Parquet tables when pyarrow is installed, CSV + JSON otherwise; written
        atomically, never over an input (see :mod:`footzoo.core.archive`).

        Parameters
        ----------
        path : str or Path
            The folder (created when missing).
        backend : {"auto", "parquet", "csv"}
            Table format.
        inputs : iterable of paths
            Further files that must not be replaced (the recording's own are known).
        files : dict of str to bytes, optional
            More files saved with the result and listed in its manifest (figures: file name ->
            content); a later save without them removes them.

        Returns
        -------
        Path
            The folder.
        """
        return save_result(self, path, backend=backend, inputs=inputs, files=files)

    @classmethod
    def load(cls, path: str | os.PathLike, verify: bool = True) -> Result:
        """A result saved by :meth:`save` (tables with their dtypes, every value as it was saved).

        ``verify``: compare each file with the SHA-256 its manifest records and warn
        (``FootzooWarning``) of one changed after the save; it is loaded as it is now. ``False``
        skips the check. A truncated or unreadable file is a ``FormatError`` either way.
        """
        return cls(**read_result(path, verify))

    @property
    def pos(self) -> np.ndarray:
        """Position (N, 3) in NED (m)."""
        return self.samples[["pos_n", "pos_e", "pos_d"]].to_numpy()

    @property
    def vel(self) -> np.ndarray:
        """Velocity (N, 3) in NED (m/s)."""
        return self.samples[["vel_n", "vel_e", "vel_d"]].to_numpy()

    @property
    def quat(self) -> np.ndarray:
        """Attitude (N, 4), body -> NED, scalar first."""
        return self.samples[["qw", "qx", "qy", "qz"]].to_numpy()

    @property
    def stance(self) -> np.ndarray:
        """Stance flag (N,), bool."""
        return self.samples["stance"].to_numpy(dtype=bool)
