"""Choose a setting by cross-validation over groups of recordings (subjects, days, motion classes).

``tune(study_or_yaml) -> TuneResult``: the candidate settings (a grid of the study's factors, or
settings drawn at random from a ``space``) run on every recording through the study runner (cached,
local workers or a Dask cluster); then, for every group of recordings in turn (leave-one-group-out,
as scikit-learn's ``LeaveOneGroupOut``), the setting with the best score on the other groups is
chosen and scored on the held-out group. Those held-out scores are the honest figure; the setting
chosen on every group is the result, written as a config YAML.

A tune file is a study file with a ``tune:`` block::

    tune:
      objective: pyshoe_error_m    # a metric of the study (footzoo.evaluation.metrics.METRICS)
      direction: minimize          # or maximize
      aggregate: mean              # mean, median or gmean over recordings
      weight: group                # every group weighs the same (or: recording)
      search: grid                 # grid over the factors, random over `space`, or optuna (TPE) over `space`
      trials: 20                   # settings drawn by a random search (per fold, by optuna)
      seed: 0
      space: {detector.threshold: {low: 1e4, high: 1e6, log: true}, detector.window: [3, 5, 7]}
      group_by: '^(\\d{4}-\\d{2}-\\d{2})'   # group = the regex's first group in the recording's label
      config: best.yaml            # where the chosen setting goes (default: OUT/best.yaml)

A recording's group is its ``group:`` in the study's ``recordings`` or the ``group_by`` match.

**The edge of the grid.** When the chosen value of a numeric factor (three levels or more) is the
smallest or the largest of its grid, or, in a random or optuna search, lies in the outer 5 % of a
``{low, high}`` range (on the log scale for a ``log`` range), the best may lie beyond it: ``tune``
says so in a :class:`~footzoo.core.errors.FootzooWarning`, in :attr:`TuneResult.edges_` and in the
written config's header, with the edge and a next value to try (:func:`grid_edges`).

``search: optuna`` (``pip install 'footzoo[tune]'``) searches ``space`` sample-efficiently with
optuna's TPE sampler (Bergstra et al. 2011; seeded, so repeatable): a search of ``trials``
settings on the training groups of every fold (nested, so the held-out group never steers the
search that scores it), and one on all groups for the chosen setting. Every trial runs through the
same study runner (one cache: a setting two searches propose runs once), so it is parallel over
the recordings as the other searches are.
"""

from __future__ import annotations

import copy
import json
import math
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

from ..config.library import resolve
from ..core.atomic import FileGroup, folder_lock, json_safe, write_text
from ..core.errors import ConfigError, FootzooWarning, did_you_mean, user_stacklevel
from ..core.warninglog import LOG, WarningLog, log_text
from ..core.yamlsafe import load_file
from ..evaluation.metrics import METRICS
from .runner import run_study
from .study import Study, set_dotted

TUNE_KEYS = {
    "objective": "the metric to optimise (a study metric)",
    "direction": "minimize or maximize",
    "aggregate": "mean, median or gmean of the objective over recordings",
    "weight": "group (every group weighs the same) or recording",
    "search": "grid (the study's factors), random (settings drawn from `space`) or optuna (TPE over `space`)",
    "trials": "settings drawn by a random search, or tried by each optuna search",
    "seed": "seed of a random search",
    "space": "dotted path -> list of values, or {low, high, log, integer} (random and optuna search)",
    "group_by": "regular expression on the recording's label; its first group is the recording's group",
    "config": "file the chosen setting is written to (default: OUT/best.yaml)",
}
AGGREGATES: dict[str, Callable[[np.ndarray], float]] = {
    "mean": lambda v: float(np.mean(v)),
    "median": lambda v: float(np.median(v)),
    "gmean": lambda v: float(np.exp(np.mean(np.log(v)))) if np.all(v > 0) else float("nan"),
}

SEARCHES = ("grid", "random", "optuna")

#: A score function: the objective's values of one setting on a set of recordings (indexed by
#: recording) and their groups -> one number (lower is better after the direction is applied).
Score = Callable[[pd.Series, pd.Series], float]


@dataclass
class TuneSpec:
    """The ``tune:`` block of a tune file (see the module's docstring)."""

    objective: str
    direction: str = "minimize"
    aggregate: str = "mean"
    weight: str = "group"
    search: str = "grid"
    trials: int = 20
    seed: int = 0
    space: dict[str, Any] = field(default_factory=dict)
    group_by: str | None = None
    config: str | None = None

    @classmethod
    def from_dict(cls, d: Any) -> TuneSpec:
        """Check and build from a mapping."""

        if not isinstance(d, dict) or "objective" not in d:
            raise ConfigError("a tune file needs a 'tune:' block with at least 'objective: METRIC'")
        for key in d:
            if key not in TUNE_KEYS:
                raise ConfigError(f"unknown tune key {key!r}{did_you_mean(str(key), list(TUNE_KEYS))}; "
                                  f"valid keys: {list(TUNE_KEYS)}")
        objective = str(d["objective"])
        if objective not in METRICS:
            raise ConfigError(f"tune.objective {d['objective']!r} is not a metric"
                              f"{did_you_mean(objective, list(METRICS))}; valid: {list(METRICS)}")
        spec = cls(objective, **{k: v for k, v in d.items() if k != "objective"})
        for name, value, allowed in (("direction", spec.direction, ("minimize", "maximize")),
                                     ("aggregate", spec.aggregate, tuple(AGGREGATES)),
                                     ("weight", spec.weight, ("group", "recording")),
                                     ("search", spec.search, SEARCHES)):
            if value not in allowed:
                raise ConfigError(f"tune.{name} must be one of {list(allowed)}, got {value!r}")
        for name in ("trials", "seed"):
            v = getattr(spec, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < (1 if name == "trials" else 0):
                raise ConfigError(f"tune.{name} must be a whole number >= {1 if name == 'trials' else 0}, got {v!r}")
        if spec.search != "grid" and not spec.space:
            raise ConfigError(f"tune.search: {spec.search} needs tune.space (dotted path -> values or {{low, high}})")
        if not isinstance(spec.space, dict):
            raise ConfigError(f"tune.space must map dotted paths to values or ranges, got {spec.space!r}")
        for path, dist in spec.space.items():
            _check_distribution(path, dist)
        if spec.search == "grid" and spec.space:
            raise ConfigError("tune.space is searched by search: random or optuna; with search: grid (the default) the "
                              "candidates are the study's factors and the space would be ignored: set search: random "
                              "(or optuna), or remove space")
        if spec.group_by is not None:
            try:
                if re.compile(str(spec.group_by)).groups < 1:
                    raise ConfigError(f"tune.group_by {spec.group_by!r} needs a (group) that picks the group name")
            except re.error as err:
                raise ConfigError(f"tune.group_by {spec.group_by!r} is not a regular expression: {err}") from None
        return spec

    def score_function(self) -> Score:
        """The score of this spec: the aggregate over recordings (per group first when ``weight: group``)."""
        agg = AGGREGATES[self.aggregate]
        sign = 1.0 if self.direction == "minimize" else -1.0

        def score(values: pd.Series, groups: pd.Series) -> float:
            v = values.to_numpy(dtype=float)
            if v.size == 0 or not np.all(np.isfinite(v)):
                return math.inf  # a failed or refused run: never the best
            if self.aggregate == "gmean" and np.any(v <= 0):
                raise ConfigError(f"tune.aggregate gmean needs positive values of the objective, but "
                                  f"{self.objective!r} is {float(v[v <= 0][0]):.4g} on a recording (a signed error, or "
                                  "zero): use aggregate: mean or median, or an objective that is never negative (an "
                                  "absolute or RMS error)")
            if self.weight == "recording":
                return sign * agg(v)
            per_group = [agg(values[groups == g].to_numpy(dtype=float)) for g in pd.unique(groups)]
            return sign * float(np.mean(per_group))

        return score


def _check_distribution(path: str, dist: Any) -> None:
    if isinstance(dist, list):
        if not dist:
            raise ConfigError(f"tune.space.{path} has no values")
        return
    if not isinstance(dist, dict) or not {"low", "high"} <= set(dist) or set(dist) - {"low", "high", "log", "integer"}:
        raise ConfigError(f"tune.space.{path} must be a list of values or {{low, high, log: bool, integer: bool}}, "
                          f"got {dist!r}")
    low, high = dist["low"], dist["high"]
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in (low, high)) or not low < high:
        raise ConfigError(f"tune.space.{path}: low and high must be numbers with low < high, got {low!r}, {high!r}")
    if dist.get("log") and low <= 0:
        raise ConfigError(f"tune.space.{path}: a log range needs low > 0, got {low!r}")


def sample_space(space: dict[str, Any], trials: int, seed: int) -> list[dict[str, Any]]:
    """``trials`` distinct settings drawn from ``space`` (a list: uniform choice; a range: uniform, or log-uniform)."""
    rng = np.random.default_rng(seed)
    out: list[dict[str, Any]] = []
    seen: set[str] = set()
    for _ in range(trials * 20):
        if len(out) == trials:
            break
        setting = {}
        for path, dist in space.items():
            if isinstance(dist, list):
                setting[path] = dist[int(rng.integers(len(dist)))]
                continue
            lo, hi = float(dist["low"]), float(dist["high"])
            x = float(np.exp(rng.uniform(np.log(lo), np.log(hi)))) if dist.get("log") else float(rng.uniform(lo, hi))
            setting[path] = int(round(x)) if dist.get("integer") else float(f"{x:.4g}")
        key = json.dumps(setting, sort_keys=True, default=str)
        if key not in seen:
            seen.add(key)
            out.append(setting)
    return out


def leave_one_group_out(groups: pd.Series) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """``(group, train, test)`` boolean masks, one fold per group in order of first appearance."""
    g = groups.to_numpy()
    return [(str(name), g != name, g == name) for name in pd.unique(g)]


def cross_validate(values: pd.DataFrame, groups: pd.Series, score: Score) -> tuple[pd.DataFrame, pd.Series, str]:
    """Leave-one-group-out choice of a setting.

    Parameters
    ----------
    values : DataFrame
        The objective, one row per recording, one column per setting (in the order that breaks ties).
    groups : Series
        The group of each recording (same index).
    score : callable
        ``score(values_of_one_setting, groups) -> float``, lower is better.

    Returns
    -------
    folds : DataFrame
        Per held-out group: ``group``, ``recordings``, ``chosen``, ``train_score``, ``test_score``.
    held_out : Series
        Per recording: the objective of the setting chosen without its group.
    chosen : str
        The setting with the best score on every recording.
    """
    groups = groups.reindex(values.index)
    folds, held_out = [], pd.Series(np.nan, index=values.index)
    for name, train, test in leave_one_group_out(groups):
        if not train.any():
            raise ConfigError(f"cross-validation needs at least two groups; every recording is in group {name!r}")
        scores = {s: score(values.loc[train, s], groups[train]) for s in values.columns}
        chosen = min(scores, key=scores.get)
        held_out[test] = values.loc[test, chosen]
        folds.append({"group": name, "recordings": int(test.sum()), "chosen": chosen,
                      "train_score": scores[chosen], "test_score": score(values.loc[test, chosen], groups[test])})
    scores = {s: score(values[s], groups) for s in values.columns}
    return pd.DataFrame(folds), held_out, min(scores, key=scores.get)


@dataclass
class TuneResult:
    """What :func:`tune` found.

    Attributes
    ----------
    best_ : str
        Name of the setting chosen on every group.
    best_config_ : dict
        Its full config.
    folds_ : DataFrame
        One row per held-out group: ``group``, ``recordings``, ``chosen``, ``train_score``, ``test_score``.
    held_out_ : Series
        Per recording, the objective of the setting chosen without its group (the cross-validated figure).
    scores_ : Series
        Every setting's score on all recordings (lower is better), best first.
    values_ : DataFrame
        The objective per recording (rows) and setting (columns).
    groups_ : Series
        Each recording's group.
    settings_ : dict
        Setting name -> its factor levels.
    edges_ : list of str
        The chosen setting's values at an edge of what was searched, each with the edge and a value
        to try next (:func:`grid_edges`); empty when none is.
    """

    best_: str
    best_config_: dict[str, Any]
    folds_: pd.DataFrame
    held_out_: pd.Series
    scores_: pd.Series
    values_: pd.DataFrame
    groups_: pd.Series
    settings_: dict[str, dict[str, Any]]
    objective: str = ""
    edges_: list[str] = field(default_factory=list)

    def save_config(self, path: str | Path, name: str | None = None) -> Path:
        """Write the chosen setting as a pipeline config YAML (atomically), the procedure in its header."""
        return write_text(path, self.config_text(name), what="tuned config")

    def config_text(self, name: str | None = None) -> str:
        """The YAML text :meth:`save_config` writes."""
        cfg = copy.deepcopy(self.best_config_)
        cfg["name"] = name or str(cfg.get("name", "tuned"))
        header = [f"# chosen by footzoo tune: {self.best_} ({self.objective}); leave-one-group-out over "
                  f"{self.groups_.nunique()} groups",
                  *(f"#   held out {r.group}: chose {r.chosen}, train score {r.train_score:.4g}, "
                    f"test score {r.test_score:.4g}" for r in self.folds_.itertuples()),
                  *(f"# at the edge: {e}" for e in self.edges_)]
        body = yaml.safe_dump(json_safe(cfg), sort_keys=False, default_flow_style=None, width=120)
        return "\n".join(header) + "\n" + body


def candidate_study(study: Study, spec: TuneSpec) -> tuple[Study, dict[str, dict[str, Any]]]:
    """The study whose bases are the candidate settings (grid of the factors, or drawn from the space)."""
    if spec.search == "random":
        settings = [{"base": name, **s} for name, _ in study.bases for s in sample_space(spec.space, spec.trials,
                                                                                          spec.seed)]
    else:
        settings = [levels for _, levels in study.configs()]
    return settings_study(study, spec, settings)


def settings_study(study: Study, spec: TuneSpec, settings: list[dict[str, Any]]) -> tuple[Study, dict[str, dict]]:
    """The study whose bases are these settings (``{"base": name, path: value, ...}`` each), and their names."""
    bases, named = [], {}
    base_configs = dict(study.bases)
    for levels in settings:
        cfg = copy.deepcopy(base_configs[levels["base"]])
        names = sorted((k for k in levels if k != "base"), key=lambda n: not n.endswith(".type"))
        for n in names:
            set_dotted(cfg, n, levels[n])
        label = setting_label(levels, multiple_bases=len(study.bases) > 1)
        bases.append((label, cfg))  # the config as the study runs it: the same cache entries
        named[label] = levels
    out = Study(study.name, bases, {}, study.recordings, [spec.objective], 0, study.plugins, study.jobs,
                study.max_cells)
    return out, named


#: Share of a ``{low, high}`` range (of its log for a log range) that counts as its edge.
EDGE_SHARE = 0.05


def grid_edges(chosen: dict[str, Any], searched: dict[str, Any]) -> list[str]:
    """The chosen values that sit at an edge of what was searched, each with the edge and a value to try next.

    Parameters
    ----------
    chosen : dict
        The chosen setting's levels (dotted path -> value).
    searched : dict
        The grid (dotted path -> list of levels) or the space (-> list, or ``{low, high, log}``).

    Returns
    -------
    list of str
        E.g. ``"detector.threshold = 1e+06 is the largest value of the grid [1e+04, 1e+05, 1e+06]: the
        best may lie beyond it; extend the grid above (next: 1e+07)"``. A list of fewer than three
        numbers, or of other values (plug-in types), has no edge worth naming.
    """
    out = []
    for path, where in searched.items():
        value = chosen.get(path)
        if not _number(value):
            continue
        if isinstance(where, list):
            levels = sorted({float(v) for v in where if _number(v)})
            if len(levels) < 3 or len(levels) != len(where):
                continue
            side = "smallest" if value == levels[0] else "largest" if value == levels[-1] else ""
            if side:
                nxt = _beyond(levels, side == "largest")
                grid = ", ".join(f"{v:g}" for v in levels)
                out.append(f"{path} = {value:g} is the {side} value of the grid [{grid}]: the best may lie beyond "
                           f"it; extend the grid {'above' if side == 'largest' else 'below'} (next: {nxt:g})")
        elif isinstance(where, dict) and {"low", "high"} <= set(where):
            lo, hi = float(where["low"]), float(where["high"])
            f = (lambda x: np.log(x)) if where.get("log") else (lambda x: x)
            share = (f(float(value)) - f(lo)) / (f(hi) - f(lo))
            side = "low" if share <= EDGE_SHARE else "high" if share >= 1 - EDGE_SHARE else ""
            if side:
                nxt = _past_range(lo, hi, bool(where.get("log")), side == "high")
                out.append(f"{path} = {value:g} is at the {side} end of the range [{lo:g}, {hi:g}] searched: the best "
                           f"may lie beyond it; extend the range (e.g. {side}: {nxt:g})")
    return out


def _number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _beyond(levels: list[float], above: bool) -> float:
    """The next value past an end of sorted ``levels``: the same ratio when they are spaced evenly on a log scale
    (all > 0), else the same step; never across zero from positive levels (then half the smallest)."""
    lv = np.asarray(levels, dtype=float)
    a, b = (lv[-2], lv[-1]) if above else (lv[1], lv[0])
    steps = np.diff(lv)
    if (lv > 0).all():
        logs = np.diff(np.log(lv))
        if np.std(logs) / np.mean(logs) < np.std(steps) / np.mean(steps):
            return float(b * (b / a))  # log-spaced: one more ratio
    nxt = float(b + (b - a))
    return nxt if not ((lv > 0).all() and nxt <= 0) else float(b / 2)


def _past_range(lo: float, hi: float, log: bool, above: bool) -> float:
    """A value past an end of a searched range: a decade for a log range, half its width otherwise (not across 0)."""
    if log:
        return hi * 10 if above else lo / 10
    nxt = hi + (hi - lo) / 2 if above else lo - (hi - lo) / 2
    return lo / 2 if not above and lo > 0 >= nxt else nxt


def setting_label(levels: dict[str, Any], multiple_bases: bool = True) -> str:
    """A readable name of a setting: ``base|path=value,...``."""
    parts = [f"{k}={_short(v)}" for k, v in levels.items() if k != "base"]
    head = [str(levels["base"])] if multiple_bases or not parts else []
    return "|".join([*head, ",".join(parts)]) if parts else str(levels["base"])


def _short(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return v if isinstance(v, str) else json.dumps(v, sort_keys=True, default=str)


def recording_groups(study: Study, group_by: str | None = None) -> pd.Series:
    """The group of every recording of a study: its ``group:`` or the first group of ``group_by`` in its label."""
    out = {}
    for rec in study.recordings:
        group = rec.group
        if group_by is not None:
            m = re.search(group_by, rec.label)
            if m is None:
                raise ConfigError(f"recording {rec.label!r} does not match tune.group_by {group_by!r}: "
                                  "fix the expression or give the recording a group:")
            group = m.group(1)
        if group is None:
            raise ConfigError(f"recording {rec.label!r} has no group: give its recordings entry 'group: NAME' "
                              "or the tune block 'group_by: REGEX' (first group = the group)")
        out[rec.label] = group
    return pd.Series(out, name="group")


def check_groups(groups: pd.Series, group_by: str | None = None) -> None:
    """Refuse, before any run, recordings that fall in fewer than two groups (nothing to hold out).

    Raises
    ------
    ConfigError
        Naming the single group, its recordings and how to split them.
    """
    names = list(pd.unique(groups.to_numpy()))
    if not names:
        raise ConfigError("cross-validation needs at least two groups of recordings; there are no recordings: list "
                          "them under 'recordings:'")
    if len(names) < 2:
        how = (f"tune.group_by {group_by!r} puts all {len(groups)} recording(s) in one group {names[0]!r}"
               if group_by is not None else f"all {len(groups)} recording(s) are in group {names[0]!r}")
        raise ConfigError(f"cross-validation needs at least two groups of recordings; {how} "
                          f"(e.g. {list(groups.index[:3])}): make the first (group) of group_by take different "
                          "values on different recordings, or give the recordings entries different 'group:' values")


def tune(study: Study | dict[str, Any] | str | Path, spec: TuneSpec | dict[str, Any] | None = None,
         score: Score | None = None, eligible: Callable[[str], bool] | None = None,
         groups: Callable[[str], str] | None = None,
         jobs: int | None = None, scheduler: str | None = None, out: str | Path | None = None,
         progress: bool = False, quiet: bool = False) -> TuneResult:
    """Choose a setting by leave-one-group-out cross-validation (see the module's docstring).

    Parameters
    ----------
    study : Study, dict or path
        The candidates' study (its factors are the grid), a tune file (study + ``tune:`` block) or the
        mapping such a file holds (paths relative to the working folder).
    spec : TuneSpec or dict, optional
        The ``tune:`` block (required with a Study; a tune file's own otherwise).
    score : callable, optional
        ``score(values, groups) -> float`` (lower is better) instead of the spec's aggregate.
    eligible : callable, optional
        ``eligible(setting_name) -> bool``: only those settings may be chosen (all are run).
    groups : callable, optional
        ``groups(recording_label) -> group`` instead of the recordings' ``group:`` / ``group_by``.
    jobs, scheduler, progress, quiet
        As :func:`footzoo.studies.run_study` (cached in ``out/cache``, parallel).
    out : path, optional
        Folder of the cache, ``tune_folds.csv``, ``tune_scores.csv``, ``best.yaml`` and
        ``footzoo.log`` (every warning of the call, the runs' included, or ``no warnings``),
        written together once the tune is done. Every warning of the call reaches the caller
        when the call ends.
    """
    with WarningLog() as log:  # the tune's warnings, for its footzoo.log; the caller gets them at the end
        if isinstance(study, dict) and "tune" not in study and spec is not None:
            study = Study.from_dict(study)
        elif not isinstance(study, Study):
            study, file_spec = tune_mapping(study) if isinstance(study, dict) else load_tune_file(study)
            spec = spec if spec is not None else file_spec
        if spec is None:
            raise ConfigError("tune() needs a spec (the tune: block), e.g. {'objective': 'pyshoe_error_m'}")
        spec = spec if isinstance(spec, TuneSpec) else TuneSpec.from_dict(spec)
        if spec.config is not None and Path(spec.config).suffix.lower() not in (".yaml", ".yml"):
            # a recording's name here (the arguments swapped?) would be replaced by the config: refused before the runs
            raise ConfigError(f"tune config {str(spec.config)!r}: the chosen setting is written as a YAML config; "
                              f"name the file '{Path(spec.config).stem}.yaml' (footzoo never replaces a recording or "
                              "another file with a config)")
        if groups is None:
            groups = recording_groups(study, spec.group_by)
        else:
            groups = pd.Series({r.label: str(groups(r.label)) for r in study.recordings}, name="group")
        check_groups(groups, spec.group_by)
        score = score or spec.score_function()
        options = dict(jobs=jobs, scheduler=scheduler, out=out, progress=progress, quiet=quiet)
        if out is None:
            return _tune(study, spec, score, eligible, groups, options, log)
        with folder_lock(out, "tune output folder", f"tune {study.name!r}"):  # its studies run in it too
            return _tune(study, spec, score, eligible, groups, options, log)


def _tune(study: Study, spec: TuneSpec, score: Score, eligible: Callable[[str], bool] | None, groups: pd.Series,
          options: dict[str, Any], log: WarningLog) -> TuneResult:
    """:func:`tune` once its output folder (if any) is locked."""
    out = options["out"]
    run = _Runner(study, spec, groups, options)
    if spec.search == "optuna":
        folds, held_out, best = optuna_search(run, spec, score, eligible)
        values, groups = run.values, run.groups
    else:
        run.evaluate(candidate_study(study, spec)[1])
        values, groups = run.values, run.groups
        chosen_from = [s for s in values.columns if eligible is None or eligible(s)]
        if not chosen_from:
            raise ConfigError("no setting is eligible")
        folds, held_out, best = cross_validate(values[chosen_from], groups, score)
    left_out = [r for r in run.all_groups.index if r not in values.index]
    if left_out:
        warnings.warn(FootzooWarning(
            f"tune: {len(left_out)} of {len(run.all_groups)} recording(s) gave no {spec.objective} in any setting "
            f"and are left out of the cross-validation: {left_out[:5]}; the study's note column and {LOG} say why "
            "(e.g. no reference that can score it)"), stacklevel=user_stacklevel())
    if len(values.columns) == 1:
        warnings.warn(FootzooWarning(
            f"tune: only one setting was scored ({best}): nothing was compared, so it is 'chosen' by default and the "
            "cross-validation only scores it; give a factor two or more values (or search a space) to choose"),
            stacklevel=user_stacklevel())
    settings = run.settings
    scores = pd.Series({s: score(values[s], groups) for s in values.columns}).sort_values(kind="stable")
    config = run.configs[best]
    edges = grid_edges(settings[best], study.factors if spec.search == "grid" else spec.space)
    result = TuneResult(best, config, folds, held_out, scores, values, groups, settings, spec.objective, edges)
    for edge in edges:
        warnings.warn(FootzooWarning(f"tune: the chosen {edge}"), stacklevel=user_stacklevel())
    target = spec.config or (Path(out) / "best.yaml" if out is not None else None)
    # the tables, the chosen config and the log of this tune (every warning it gave), or none of them
    with FileGroup(what="tune output") as written:
        if target is not None:
            written.path(target).write_text(result.config_text(name=study.name), encoding="utf-8")
        if out is not None:
            folder = Path(out)
            folder.mkdir(parents=True, exist_ok=True)
            written.path(folder / "tune_folds.csv").write_text(folds.to_csv(index=False), encoding="utf-8")
            written.path(folder / "tune_scores.csv").write_text(
                scores.rename("score").to_csv(index_label="setting"), encoding="utf-8")
            written.path(folder / LOG).write_bytes(log_text(log.texts()))
    return result


class _Runner:
    """Runs settings through the study runner (one cache) and keeps the objective of every one run so far.

    ``all_values`` (recording × setting; :attr:`values` and :attr:`groups`: the recordings that gave
    a value), ``settings`` (name -> levels) and ``configs`` (name -> full config) grow with every
    :meth:`evaluate`.
    """

    def __init__(self, study: Study, spec: TuneSpec, groups: pd.Series, options: dict[str, Any]):
        self.study, self.spec, self.all_groups, self.options = study, spec, groups, options
        self.all_values = pd.DataFrame(index=list(groups.index), dtype=float)
        self.settings: dict[str, dict[str, Any]] = {}
        self.configs: dict[str, dict[str, Any]] = {}
        self.causes: list[str] = []

    def evaluate(self, settings: dict[str, dict[str, Any]] | list[dict[str, Any]]) -> list[str]:
        """Run the settings not run yet; returns the names of all of them, in order."""

        levels = list(settings.values()) if isinstance(settings, dict) else list(settings)
        cands, named = settings_study(self.study, self.spec, levels)
        new = [(name, cfg) for name, cfg in cands.bases if name not in self.all_values.columns]
        if new:
            part = Study(cands.name, new, {}, cands.recordings, cands.metrics, 0, cands.plugins, cands.jobs,
                         cands.max_cells)
            table = run_study(part, report=False, **self.options)
            self.causes += list(table.attrs.get("causes", {}))
            rows = table[table["metric"] == self.spec.objective]
            got = rows.pivot_table(index="recording", columns="base", values="value", aggfunc="first", dropna=False)
            for name, cfg in new:
                self.all_values[name] = got[name].reindex(self.all_values.index) if name in got else np.nan
                self.configs[name] = cfg
        self.settings.update(named)
        if self.all_values.isna().all(axis=None):
            causes = "; ".join(self.causes[:3]) or "the metric was never computed"
            raise ConfigError(f"no setting gave {self.spec.objective!r} on any recording ({causes})")
        return list(named)

    @property
    def values(self) -> pd.DataFrame:
        """The objective (recording × setting) of the recordings with at least one value."""
        return self.all_values[~self.all_values.isna().all(axis=1)]

    @property
    def groups(self) -> pd.Series:
        """The groups of the recordings with at least one value."""
        return self.all_groups[~self.all_values.isna().all(axis=1)]


def _suggest(trial: Any, space: dict[str, Any]) -> dict[str, Any]:
    """One setting of ``space`` from an optuna trial (a list: categorical; a range: float or int, log or not)."""
    setting = {}
    for path, dist in space.items():
        if isinstance(dist, list):
            choice = trial.suggest_categorical(path, list(range(len(dist))))  # indices: any YAML value
            setting[path] = dist[choice]
        elif dist.get("integer"):
            setting[path] = trial.suggest_int(path, int(math.ceil(dist["low"])), int(math.floor(dist["high"])),
                                              log=bool(dist.get("log")))
        else:
            x = trial.suggest_float(path, dist["low"], dist["high"], log=bool(dist.get("log")))
            setting[path] = float(f"{x:.4g}")
    return setting


def optuna_search(run: _Runner, spec: TuneSpec, score: Score,
                  eligible: Callable[[str], bool] | None = None) -> tuple[pd.DataFrame, pd.Series, str]:
    """Nested leave-one-group-out with an optuna TPE search per fold; the result of :func:`cross_validate`.

    Each fold searches ``spec.trials`` settings of ``spec.space`` for the best score on its training
    groups and scores that setting on its held-out group; a last search on every group gives the
    chosen setting. Seeded with ``spec.seed`` (fold i: seed + i), so a rerun proposes the same settings.
    """
    try:
        # deferred: optuna, an optional extra (footzoo[tune])
        import optuna
    except ImportError:
        raise ConfigError("tune.search: optuna needs the optuna package: pip install 'footzoo[tune]' "
                          "(or use search: random)") from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    base = run.study.bases[0][0]

    def search(train: np.ndarray | None, seed: int) -> tuple[str, float]:
        sampler = optuna.samplers.TPESampler(seed=seed)
        opt = optuna.create_study(direction="minimize", sampler=sampler)
        names: dict[int, str] = {}

        def objective(trial: Any) -> float:
            name = run.evaluate([{"base": base, **_suggest(trial, spec.space)}])[0]
            names[trial.number] = name
            if eligible is not None and not eligible(name):
                return math.inf
            v, g = run.values[name], run.groups
            mask = np.ones(len(v), bool) if train is None else train(g)
            value = score(v[mask], g[mask])
            return value if math.isfinite(value) else math.inf

        opt.optimize(objective, n_trials=spec.trials)
        return names[opt.best_trial.number], float(opt.best_value)

    folds, held_out = [], None
    names = list(pd.unique(run.all_groups.to_numpy()))
    if len(names) < 2:
        raise ConfigError(f"cross-validation needs at least two groups; every recording is in group {names[0]!r}")
    for i, group in enumerate(names):
        chosen, train_score = search(lambda g, group=group: (g != group).to_numpy(), spec.seed + i)
        v, g = run.values[chosen], run.groups
        test = (g == group).to_numpy()
        folds.append({"group": str(group), "recordings": int(test.sum()), "chosen": chosen,
                      "train_score": train_score, "test_score": score(v[test], g[test])})
        fold = pd.Series(v[test].to_numpy(), index=v.index[test])
        held_out = fold if held_out is None else pd.concat([held_out, fold])
    best, _ = search(None, spec.seed + len(names))
    return pd.DataFrame(folds), held_out.reindex(run.values.index), best


def load_tune_file(path: str | Path) -> tuple[Study, TuneSpec]:
    """A tune file: the study (without its ``tune:`` block) and the spec; paths relative to the file."""

    p = resolve(path)
    data = load_file(p, ConfigError, "tune file")
    try:
        return tune_mapping(data, root=p.parent)
    except ConfigError as err:
        raise ConfigError(f"{p}: {err}") from None


def tune_mapping(data: Any, root: str | Path = ".") -> tuple[Study, TuneSpec]:
    """A tune file's mapping: the study (without its ``tune:`` block) and the spec; paths relative to ``root``."""
    if not isinstance(data, dict) or "tune" not in data:
        raise ConfigError("a tune file is a study file with a 'tune:' block (objective, search, group_by, ...)")
    data = dict(data)
    block = data.pop("tune")
    spec = TuneSpec.from_dict(block)
    if spec.search != "grid":
        data.pop("factors", None)
    study = Study.from_dict(data, root=root)
    if spec.config is not None and not Path(spec.config).is_absolute():
        spec.config = str(Path(root) / spec.config)
    return study, spec
