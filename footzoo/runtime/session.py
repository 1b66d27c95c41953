"""Both feet of one walk: each foot through the same pipeline, per-foot and bilateral tables.

A layer above :class:`~footzoo.runtime.pipeline.Pipeline`: :meth:`Session.run` calls
``Pipeline.run`` once per foot and combines the stride tables. Bilateral
parameters follow the usual gait-lab definitions (e.g. gaitmap's
``TemporalParameterCalculation`` and the symmetry index of Robinson et al. 1987,
``SI = 100 · |L − R| / (0.5 · (L + R))``): the **step time** of a foot is the
time from the other foot's initial contact to this foot's next initial contact.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.archive import read_session, save_session
from ..core.data import Recording
from ..core.errors import FootzooWarning, FormatError, NotARecordingError, user_stacklevel
from ..evaluation.result import Result
from ..io import detect_format, load
from ..io.gaitmap import feet
from .pipeline import Pipeline, require_pipeline

FEET = ("left", "right")
#: Shortest overlap of the two feet's time spans, as a fraction of the shorter span, for one clock.
MIN_CLOCK_OVERLAP = 0.5
#: Parameters of the bilateral table: median per foot of these stride-table columns.
BILATERAL_COLUMNS = ["stride_time_s", "step_time_s", "stance_time_s", "swing_time_s", "cadence_steps_min",
                     "stride_length_m", "speed_m_s", "max_clearance_m"]


class Session:
    """Recordings of both feet of one walk, on one clock.

    Parameters
    ----------
    recordings : dict or list
        ``{"left": Recording, "right": Recording}`` (one foot alone is allowed;
        the bilateral table then stays empty), or a list of recordings whose
        ``meta["foot"]`` names each foot once (as the xsens reader's ``_lf`` / ``_rf`` files do).
    name : str
        Session name.
    """

    def __init__(self, recordings: dict[str, Recording] | list[Recording], name: str = "session"):
        if isinstance(recordings, (list, tuple)):
            recordings = _by_foot(recordings)
        bad = [k for k in recordings if k not in FEET]
        if bad or not recordings:
            raise FormatError(f"a session holds recordings keyed 'left' and/or 'right', got the keys "
                              f"{[str(k) for k in recordings]}: give Session({{'left': rec_l, 'right': rec_r}})")
        for foot, rec in recordings.items():
            if not isinstance(rec, Recording):
                raise NotARecordingError(f"session[{foot!r}] must be a footzoo Recording, got {type(rec).__name__}; "
                                         "build it with footzoo.load(path)")
        self.recordings = dict(recordings)
        self.name = name
        _check_one_clock(self.recordings)

    def __repr__(self) -> str:
        return f"Session({self.name!r}, feet={list(self.recordings)})"

    @classmethod
    def load(cls, path: str | Path, format: str | None = None, **options: Any) -> Session:
        """Read every foot a file holds (gaitmap: ``left_sensor`` and ``right_sensor``).

        Raises
        ------
        FormatError
            When the file holds one foot only (use :func:`footzoo.io.load`).
        """

        p = Path(path)
        fmt = format or detect_format(p, options)
        if fmt != "gaitmap":
            raise FormatError(f"{p}: a {fmt} file holds one foot; load it with footzoo.load (command line: "
                              "--foot left or --foot right), or build Session({'left': ..., 'right': ...})")
        found = feet(p)
        if not found:
            raise FormatError(f"{p}: no left_sensor or right_sensor columns")
        recs = {f: load(p, format=fmt, foot=f, **options) for f in found}
        return cls(recs, name=p.stem)

    def run(self, pipeline: Pipeline, engine: str = "auto") -> SessionResult:
        """Run ``pipeline`` on each foot (``Pipeline.run``) and combine the stride tables."""
        require_pipeline(pipeline, "Session.run")
        results = {foot: pipeline.run(rec, engine=engine) for foot, rec in self.recordings.items()}
        return SessionResult(results=results, name=self.name)


def _by_foot(recordings: list | tuple) -> dict[str, Recording]:
    """A list of recordings keyed by the foot each names in ``meta["foot"]``; an error names any that names none or
    a foot already taken."""
    out: dict[str, Recording] = {}
    for i, rec in enumerate(recordings):
        if not isinstance(rec, Recording):
            raise NotARecordingError(f"session[{i}] must be a footzoo Recording, got {type(rec).__name__}; "
                                     "build it with footzoo.load(path)")
        foot = rec.meta.get("foot")
        if foot not in FEET or foot in out:
            why = ("names no foot (meta['foot'] is " + repr(foot) + ")" if foot not in FEET
                   else f"is a second {foot} foot (with {out[foot].name!r})")
            raise FormatError(f"session[{i}] ({rec.name!r}) {why}: a list of recordings is keyed by the foot each "
                              "names; give Session({'left': rec_l, 'right': rec_r}) to say which is which")
        out[foot] = rec
    return out


def _check_one_clock(recordings: dict[str, Recording]) -> None:
    """Warn when both feet are given but their time spans overlap for less than half of the shorter one: a step time
    pairs one foot's contact with the other's, which needs one clock (two loggers' clocks started apart)."""
    if len(recordings) < 2:
        return
    spans = {f: (float(r.t[0]), float(r.t[-1])) for f, r in recordings.items()}
    (lf, (l0, l1)), (rf, (r0, r1)) = spans.items()
    overlap = max(0.0, min(l1, r1) - max(l0, r0))
    if overlap >= MIN_CLOCK_OVERLAP * min(l1 - l0, r1 - r0):
        return
    warnings.warn(FootzooWarning(
        f"session: the {lf} foot's recording spans t = {l0:.6g}–{l1:.6g} s and the {rf} foot's {r0:.6g}–{r1:.6g} s, "
        f"overlapping {overlap:.3g} s: the two are not on one clock, so the step times (each foot's contact after the "
        "other's) and their symmetry come out NaN or wrong; the per-foot results are unaffected. Put both on one "
        "clock (e.g. Recording(t=rec.t - offset, ...)) for the bilateral table"), stacklevel=user_stacklevel())


def step_times(steps: dict[str, pd.DataFrame]) -> dict[str, np.ndarray]:
    """Step time (s) of each stride of each foot: its ``end_s`` minus the other foot's latest IC before it.

    NaN where the other foot has no earlier contact in the stride (the first
    step, or when the other foot's IC is older than this foot's previous one).
    """
    out: dict[str, np.ndarray] = {}
    for foot, table in steps.items():
        ic = table["end_s"].to_numpy(dtype=float)
        other = [f for f in steps if f != foot]
        if not other:
            out[foot] = np.full(len(ic), np.nan)
            continue
        o = np.sort(steps[other[0]]["end_s"].to_numpy(dtype=float))
        k = np.searchsorted(o, ic) - 1
        prev = np.where(k >= 0, o[np.maximum(k, 0)], np.nan)
        own_prev = table["start_s"].to_numpy(dtype=float)
        st = ic - prev
        st[~(prev > own_prev)] = np.nan  # the other foot must land within this stride
        out[foot] = st
    return out


@dataclass
class SessionResult:
    """Results of both feet.

    Attributes
    ----------
    results : dict
        ``{"left": Result, "right": Result}``.
    name : str
        Session name.
    """

    results: dict[str, Result]
    name: str = "session"

    def save(self, path: str | Path, backend: str = "auto", inputs: Any = (),
             files: dict[str, dict[str, bytes]] | None = None) -> Path:
        """Save as a folder: one :meth:`Result.save` folder per foot, and the stride and bilateral tables.

        Atomic as one unit and never over an input (see :mod:`footzoo.core.archive`); ``files``: per
        foot, more files (figures) saved into its folder with it.
        """

        return save_session(self, path, backend=backend, inputs=inputs, files=files)

    @classmethod
    def load(cls, path: str | Path, verify: bool = True) -> SessionResult:
        """A session saved by :meth:`save` (the stride and bilateral tables are recomputed); ``verify`` as
        :meth:`Result.load`'s."""

        name, fields = read_session(path, verify)
        return cls(results={foot: Result(**f) for foot, f in fields.items()}, name=name)

    @cached_property
    def steps(self) -> pd.DataFrame:
        """Stride tables of both feet, one after the other, with ``foot`` and ``step_time_s`` (s)."""
        per = {f: r.steps for f, r in self.results.items()}
        st = step_times(per)
        frames = [t.assign(step_time_s=st[f]).assign(foot=f) for f, t in per.items()]
        cols = ["foot", *frames[0].columns.drop("foot")]
        return pd.concat(frames, ignore_index=True)[cols]

    @property
    def per_foot(self) -> pd.DataFrame:
        """One row per foot: :attr:`footzoo.evaluation.result.Result.metrics` (errors against each foot's reference)."""
        return pd.DataFrame({f: r.metrics for f, r in self.results.items()}).T.rename_axis("foot")

    @property
    def bilateral(self) -> pd.DataFrame:
        """Median of each parameter per foot and the symmetry index ``100 · |L − R| / (0.5 · (L + R))`` (%)."""
        steps = self.steps
        rows = {}
        for col in BILATERAL_COLUMNS:
            if col not in steps.columns:
                continue
            med = {}
            for f in FEET:
                v = steps.loc[steps["foot"] == f, col].to_numpy(dtype=float)
                v = v[np.isfinite(v)]
                med[f] = float(np.median(v)) if v.size else np.nan
            si = 100.0 * abs(med["left"] - med["right"]) / (0.5 * (med["left"] + med["right"]))
            rows[col] = {"left": med["left"], "right": med["right"], "symmetry_index_pct": si}
        return pd.DataFrame(rows).T.rename_axis("parameter")
