"""Study inputs that would give a silently wrong or runaway study: refused before anything runs, with the count or
the fix.

* simulated recordings whose seeds differ but whose simulation has nothing random (no noise): the study would
  average identical runs as if they were independent;
* a grid of millions of cells, from the factors or from ``seeds`` x ``repeats``: refused with the count before
  any list is expanded (bounded memory);
* noise options, seeds and worker counts out of their range.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from footzoo.core.errors import ConfigError
from footzoo.sim import NoiseModel, simulate
from footzoo.sim.scenarios import seed_matters
from footzoo.studies.study import MAX_CELLS, Study, max_jobs

SIM = {"path": "straight", "n_strides": 3, "rate": 50}


def _study(recordings, **extra):
    return lambda: Study.from_dict({"name": "s", "base": "yun2012", "recordings": recordings, **extra})


CASES = [
    ("seeds-without-noise", _study([{"simulate": SIM, "seeds": [0, 1, 2]}]),
     "recordings[0]: its 3 seeds give 3 identical recordings: the simulation has no random part"),
    ("seeds-with-zero-noise", _study([{"simulate": {**SIM, "noise": {"scale": 0}}, "seeds": [0, 1]}]),
     "give 2 identical recordings"),
    ("repeats-without-noise", _study([{"simulate": SIM, "repeats": 3}]), "its 3 seeds give 3 identical"),
    ("seeds-without-noise-in-two-entries", _study([{"simulate": {**SIM, "noise": {"scale": 0}}, "seeds": [0]},
                                                   {"simulate": {**SIM, "noise": {"scale": 0}}, "seeds": [1],
                                                    "label": "again"}]),
     "recordings 'sim_straight_s0' and 'again_s1' are identical: the same simulation (seeds 0 and 1) without a random "
     "part"),
    ("base-twice", lambda: Study.from_dict({"name": "s", "base": ["yun2012", "yun2012"],
                                            "recordings": [{"simulate": SIM}]}),
     "base: 'yun2012' is given twice; its runs would be counted twice in every summary"),
    ("base-same-config-two-names", lambda: Study.from_dict({"name": "s", "recordings": [{"simulate": SIM}], "base": [
        {"name": "a", "orientation": {"type": "madgwick"}, "detector": {"type": "shoe"}},
        {"name": "b", "orientation": {"type": "madgwick"}, "detector": {"type": "shoe"}}]}),
     "base: 'a' and 'b' are the same config; their runs would be counted as two settings"),
    ("seeds-empty", _study([{"simulate": SIM, "seeds": []}]),
     "recordings[0].seeds is empty, so the entry gives no recording: list at least one seed"),
    ("run-study-of-a-pipeline", lambda: __import__("footzoo").run_study(__import__("footzoo").Pipeline.from_yaml(
        "yun2012")), "run_study takes a Study, a study file's path or name, or its mapping; got Pipeline: a pipeline "
                     "runs on a recording with pipeline.run(rec)"),
    ("seed-negative", _study([{"simulate": {**SIM, "noise": {"scale": 1}}, "seeds": [-1]}]),
     "recordings[0].seeds must be a list of whole numbers >= 0, got [-1]"),
    ("seed-key-singular", _study([{"simulate": {**SIM, "noise": {"scale": 1}}, "seed": 7}]),
     "recordings[0]: unknown key 'seed' (did you mean 'seeds'?) in a simulate: entry"),
    ("noise-option-misspelt", _study([{"simulate": {**SIM, "noise": {"sclae": 1}}}]),
     "recordings[0].simulate: noise: unknown option 'sclae' (did you mean 'scale'?)"),
    ("noise-biases-text", _study([{"simulate": {**SIM, "noise": {"biases": "acc"}}}]),
     "noise biases must be a list of names from 'acc', 'gyr', 'mag'"),
    ("noise-scale-negative", _study([{"simulate": {**SIM, "noise": {"scale": -1}}}]),
     "noise scale must be a finite number >= 0, got -1"),
    ("grid-ten-million-by-factors", _study([{"simulate": SIM}], factors={
        "detector.threshold": [0.1 + 0.001 * i for i in range(100)], "gravity": [9.7 + 0.001 * i for i in range(100)],
        "init.duration": [0.1 + 0.01 * i for i in range(100)], "detector.min_duration": [0.01 * (i + 1)
                                                                                         for i in range(10)]}),
     "the study has 10,000,000 runs (1 base(s) x 100 detector.threshold x 100 gravity x 100 init.duration x 10 "
     "detector.min_duration x 1 recording(s)), more than the limit of 10,000"),
    ("grid-ten-million-by-repeats", _study([{"simulate": {**SIM, "noise": {"scale": 1}}, "seeds": [0],
                                             "repeats": 10_000_000}]),
     "the study has 10,000,000 runs (1 base(s) x no factors x 10,000,000 recording(s))"),
    ("jobs-huge", _study([{"simulate": SIM}], jobs=10**6), f"jobs must be a number of worker processes on this "
                                                             f"machine: 1 (serial) to {max_jobs()}"),
]


@pytest.mark.parametrize("make, fragment", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_study_that_would_mislead_or_run_away_is_refused_before_it_runs(make, fragment):
    with pytest.raises(ConfigError) as info:
        make()
    assert fragment in str(info.value)


def test_a_huge_grid_is_refused_in_bounded_memory():
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError, match="1,000,000,000 runs"):
            Study.from_dict({"name": "s", "base": "yun2012", "factors": {"detector.threshold": [0.5, 0.6]},
                             "recordings": [{"simulate": {**SIM, "noise": {"scale": 1}}, "seeds": list(range(500)),
                                             "repeats": 1_000_000}]})
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 50 * 2**20  # bytes: the expanded list would hold 5e8 recordings


def test_seeds_with_noise_or_distance_sensors_give_different_recordings():
    """The rule's premise, checked on the simulator: the seed changes a recording exactly when seed_matters says so."""
    for spec in ({}, {"noise": {"scale": 0}}, {"noise": {"scale": 1}}, {"distance_sensors": True}):
        kw = dict(spec)
        noise = kw.pop("noise", None)
        a, b = (simulate(n_strides=2, rate=50.0, seed=s, noise=None if noise is None else NoiseModel(**noise, seed=s),
                         **kw) for s in (0, 1))
        differ = not np.array_equal(a.acc, b.acc) or (a.dist is not None and not np.array_equal(a.dist, b.dist,
                                                                                                 equal_nan=True))
        assert differ == seed_matters(spec), spec


def test_the_default_limit_holds_and_a_raised_one_lets_a_grid_through():
    levels = [0.1 + 0.01 * i for i in range(101)]
    study = {"name": "s", "base": "yun2012", "factors": {"detector.threshold": levels},
             "recordings": [{"simulate": {**SIM, "noise": {"scale": 1}}, "seeds": list(range(100))}]}
    with pytest.raises(ConfigError, match=f"more than the limit of {MAX_CELLS:,}"):
        Study.from_dict(study)
    assert Study.from_dict(study, max_cells=20_000).size == 10_100


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.lists(st.integers(-3, 10**6), max_size=6), st.integers(-2, 10**9), st.integers(1, 300), st.booleans())
def test_property_seeds_and_repeats_are_counted_before_they_are_expanded(seeds, repeats, limit, noise):
    spec = {**SIM, "noise": {"scale": 1}} if noise else SIM
    try:
        study = Study.from_dict({"name": "s", "base": "yun2012", "max_cells": limit,
                                 "recordings": [{"simulate": spec, "seeds": seeds, "repeats": repeats}]})
    except ConfigError:
        return
    assert study.size <= limit and len({r.label for r in study.recordings}) == len(study.recordings)
    assert noise or len(study.recordings) == 1
