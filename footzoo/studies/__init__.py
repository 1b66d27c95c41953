"""Ablation studies: swap one block, keep the rest, run on many recordings, read a table.

``run_study(study_or_yaml, jobs=1, scheduler=None, out=None) -> DataFrame`` (see :mod:`.runner`);
``tune(tune_yaml) -> TuneResult``: a setting chosen by leave-one-group-out cross-validation (:mod:`.tune`).
"""

from .cache import CacheWarning
from .report import run_frames, summarise, to_latex, to_markdown
from .runner import read_trajectories, run_cell, run_chunk, run_study, tidy
from .study import METRICS, Cell, RecordingSpec, Study, set_dotted
from .tune import TuneResult, TuneSpec, cross_validate, leave_one_group_out, tune

__all__ = ["METRICS", "CacheWarning", "Cell", "RecordingSpec", "Study", "TuneResult", "TuneSpec", "cross_validate",
           "leave_one_group_out", "read_trajectories", "run_cell", "run_chunk", "run_frames", "run_study",
           "set_dotted", "summarise", "tidy", "to_latex", "to_markdown", "tune"]
