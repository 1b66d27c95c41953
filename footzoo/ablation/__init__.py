"""Ablation studies: swap one block, keep the rest, run on many recordings, read a table.

``run_study(study_or_yaml, jobs=1, scheduler=None, out=None) -> DataFrame`` (see :mod:`.runner`).
"""

from .report import summarise, to_latex, to_markdown
from .runner import run_cell, run_study, tidy
from .study import Cell, RecordingSpec, Study, set_dotted

__all__ = ["Cell", "RecordingSpec", "Study", "run_cell", "run_study", "set_dotted", "summarise", "tidy",
           "to_latex", "to_markdown"]
