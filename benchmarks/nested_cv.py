"""Nested cross-validation of a selection procedure: outer folds the inner choice never sees.

A *selection procedure* takes a table of errors (one row per trial, one column per candidate
setting) and picks one candidate. Its honest figure is what the candidates it picks do on trials
it did not pick them on: the trials are split into outer folds (:func:`stratified_folds`), and
for each fold the procedure picks on the other folds' trials only and the picked candidate's
errors on the fold's own trials are kept (:func:`nested_choice`). Pooled over the folds, those
held-out errors are what the procedure delivers on new trials of the same kinds; a fixed setting
(no choice) has its plain errors as held-out errors, so the two compare on the same trials.

Used by ``benchmarks/select_recommended.py --nested``; tested on small synthetic tables in
``tests/benchmarks/test_nested_cv.py``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

#: An inner choice: errors of every candidate on the training trials (rows: trials) and the trials'
#: strata -> the name of the chosen candidate (a column).
Choice = Callable[[pd.DataFrame, pd.Series], str]


def stratified_folds(strata: pd.Series, k: int, seed: int) -> pd.Series:
    """Assign every trial to one of ``k`` outer folds, each stratum spread as evenly as it can be.

    The trials of each stratum (in the order of ``strata``' first appearance) are shuffled by
    ``numpy.random.default_rng(seed)`` and dealt round-robin to the folds; the dealing goes on where the
    previous stratum stopped, so a stratum of one or two trials lands in a fold the larger ones filled
    least, and the fold sizes differ by at most one.

    Parameters
    ----------
    strata : Series
        The stratum (e.g. motion class) of each trial, indexed by trial.
    k : int
        Number of folds (2 ≤ k ≤ number of trials).
    seed : int
        Seed of the shuffle: the same seed gives the same folds.

    Returns
    -------
    Series
        The fold (0 … k − 1) of each trial, same index as ``strata``.
    """
    if not 2 <= k <= len(strata):
        raise ValueError(f"k = {k} folds for {len(strata)} trials: k must be between 2 and the number of trials")
    rng = np.random.default_rng(seed)
    fold = pd.Series(-1, index=strata.index, dtype=int)
    nxt = 0
    for s in pd.unique(strata.to_numpy()):
        trials = strata.index[strata.to_numpy() == s].to_numpy()
        for t in trials[rng.permutation(len(trials))]:
            fold[t] = nxt % k
            nxt += 1
    return fold


def nested_choice(errors: pd.DataFrame, strata: pd.Series, folds: pd.Series, choose: Choice
                  ) -> tuple[pd.Series, pd.Series]:
    """The procedure ``choose`` under outer cross-validation.

    Parameters
    ----------
    errors : DataFrame
        One row per trial, one column per candidate (the objective, lower is better).
    strata : Series
        The stratum of each trial (passed to ``choose`` for the training trials only).
    folds : Series
        The outer fold of each trial (:func:`stratified_folds`).
    choose : callable
        ``choose(errors_of_training_trials, their_strata) -> candidate``: sees only the rows outside the fold.

    Returns
    -------
    chosen : Series
        Per outer fold (sorted): the candidate chosen on the other folds' trials.
    held_out : Series
        Per trial: the error of the candidate chosen without the trial's fold.
    """
    folds = folds.reindex(errors.index)
    strata = strata.reindex(errors.index)
    chosen: dict[int, str] = {}
    held_out = pd.Series(np.nan, index=errors.index)
    for f in sorted(pd.unique(folds.to_numpy())):
        test = (folds == f).to_numpy()
        pick = choose(errors.loc[~test], strata[~test])
        if pick not in errors.columns:
            raise ValueError(f"the inner choice returned {pick!r}, not one of the candidates {list(errors.columns)}")
        chosen[int(f)] = pick
        held_out[test] = errors.loc[test, pick]
    return pd.Series(chosen, name="chosen"), held_out


def held_out_of(chosen: pd.Series, folds: pd.Series, values: pd.DataFrame) -> pd.Series:
    """Another metric of the same choice: per trial, ``values`` of the candidate its fold chose (e.g. the 3-D error)."""
    folds = folds.reindex(values.index)
    return pd.Series([values.at[t, chosen[int(folds[t])]] for t in values.index], index=values.index)


def improves(candidate: pd.Series, baseline: pd.Series) -> bool:
    """The decision rule on the outer folds: the pooled held-out median *and* worst both strictly lower.

    A failed run (NaN) counts as infinitely wrong, never as absent.
    """
    candidate, baseline = candidate.fillna(np.inf), baseline.fillna(np.inf)
    return bool(candidate.median() < baseline.median() and candidate.max() < baseline.max())
