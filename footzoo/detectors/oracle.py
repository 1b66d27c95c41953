"""Truth-fed stance detector for ablations."""

from __future__ import annotations

import numpy as np

from ..core.errors import RecordingError
from ..plugins.base import Detector
from ..plugins.registry import register


@register
class Oracle(Detector):
    """Stance from the recording's ground truth (simulator or dataset labels).

    Not from a paper: the upper bound for ablations — how well a pipeline does
    when the gait phase is known exactly. Needs ``recording.truth.stance``
    (the simulator's, or PyShoe's ``zv_vicon_opt``).

    Attributes
    ----------
    stance_, stance_online_ : (N,) bool ndarray
        The true stance flag.
    statistic_ : (N,) ndarray
        0 in stance, 1 in swing.
    """

    name = "oracle"
    paper = "none (ground truth, for ablations)"
    needs_truth = True

    def __init__(self) -> None:
        pass

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, truth=None) -> Oracle:
        """Copy the true stance flag."""
        if truth is None or truth.stance is None:
            raise RecordingError(
                "detector 'oracle' needs a recording with a true stance flag (simulated, or PyShoe's zv_vicon_opt); "
                "this recording has none: choose another detector"
            )
        self.stance_ = np.asarray(truth.stance, dtype=bool).copy()
        self.stance_online_ = self.stance_.copy()
        self.statistic_ = (~self.stance_).astype(float)
        return self
