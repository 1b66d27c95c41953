"""Ablation studies: swap one block, keep the rest, run on many recordings, read a table.

``run_study(study_or_yaml, jobs=1, scheduler=None, out=None) -> DataFrame`` (see :mod:`.runner`).
"""

from .report import run_frames, summarise, to_latex, to_markdown
from .runner import CacheWarning, read_trajectories, run_cell, run_chunk, run_study, tidy
from .study import METRICS, Cell, RecordingSpec, Study, set_dotted

__all__ = ["METRICS", "CacheWarning", "Cell", "RecordingSpec", "Study", "read_trajectories", "run_cell",
           "run_chunk", "run_frames", "run_study", "set_dotted", "summarise", "tidy", "to_latex", "to_markdown"]
