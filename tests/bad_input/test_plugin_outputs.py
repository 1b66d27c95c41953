"""Plug-ins that break their outputs' contract in ways that look like results: each is named, in every back end.

* an analysis that drops (or adds, or reorders) a stride, or changes a column it was given;
* a plug-in that writes into its input ``meta`` (in a study the same recording goes to the next config);
* a Kalman correction whose model declares an impossible ``max_rows`` (it sized the engine's buffers: a crash);
* a detector that sets ``stance_`` but no ``statistic_``: it runs, and says so (a note, no silent ROC gap).

The plug-ins live in a file (``plugins:``), as a user's would, so the study's worker processes load them too.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from footzoo import Pipeline, PluginError
from footzoo.plugins.contract import MAX_MODEL_ROWS, check_annotated
from footzoo.sim import NoiseModel, simulate
from footzoo.studies import Study, run_study

from ..conftest import ON_PROCESS_CLUSTER

PLUGINS = '''
"""Plug-ins that break their outputs' contract (bad-input tests)."""
import numpy as np

import footzoo
from footzoo.corrections.ekf_zupt import EKFZUPT
from footzoo.detectors.angular_rate_fsm import AngularRateFSM
from footzoo.plugins.base import Analysis


class _Analysis(Analysis):
    def analyze(self, t, quat, pos, stance, meta):
        return self

    def annotate(self, steps, t):
        return steps


@footzoo.register
class MetaWriter(_Analysis):
    """Writes its name into the recording's metadata."""

    name = "test_out_meta_writer"

    def analyze(self, t, quat, pos, stance, meta):
        meta["name"] = "changed by a plug-in"
        return self


@footzoo.register
class StrideDropper(_Analysis):
    """Drops the last stride."""

    name = "test_out_stride_dropper"

    def annotate(self, steps, t):
        return steps.iloc[:-1].assign(mine=1.0)


@footzoo.register
class ColumnChanger(_Analysis):
    """Rounds the stride length in place."""

    name = "test_out_column_changer"

    def annotate(self, steps, t):
        steps["stride_length_m"] = steps["stride_length_m"].round(1)
        return steps


@footzoo.register
class Honest(_Analysis):
    """Adds a column to every stride."""

    name = "test_out_honest"

    def annotate(self, steps, t):
        return steps.assign(doubled_m=2 * steps["stride_length_m"])


@footzoo.register
class NoStatistic(AngularRateFSM):
    """angular_rate_fsm without its optional statistic_."""

    name = "test_out_no_statistic"

    def detect(self, t, acc, gyr, ctx=None):
        super().detect(t, acc, gyr, ctx=ctx)
        del self.statistic_
        return self


@footzoo.register
class BadRows(EKFZUPT):
    """ekf_zupt whose model declares max_rows = ROWS (a module-level setting)."""

    name = "test_out_bad_rows"
    rows = -1

    def model(self, samples):
        model = super().model(samples)
        model.max_rows = type(self).rows
        return model
'''


@pytest.fixture(scope="module")
def plugin_file(tmp_path_factory):
    """The plug-ins' file; registered while this module's tests run only (studies of every registered combination
    in other test modules must not meet them)."""
    from footzoo.plugins import registry

    p = tmp_path_factory.mktemp("plugins") / "outputs.py"
    p.write_text(PLUGINS)
    yield str(p)
    for kind in registry._REGISTRY.values():
        for name in [n for n in kind if n.startswith("test_out_")]:
            kind.pop(name)


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=1))


def _config(plugin_file, **parts):
    return {"name": "out", "plugins": [plugin_file], "orientation": {"type": "madgwick", "use_magnetometer": False},
            "detector": {"type": "angular_rate_fsm"}, "corrections": [{"type": "zvu_dedrift"}], **parts}


BATCH = [
    ("meta-writer", {"analysis": [{"type": "test_out_meta_writer"}]}, "analyze",
     r"changed its input meta \(keys \['name'\]\); footzoo passes inputs read-only"),
    ("stride-dropper", {"analysis": [{"type": "test_out_stride_dropper"}]}, "annotate",
     r"dropped 1 of the \d+ strides it was given; an analysis adds columns to every stride and drops none"),
    ("column-changer", {"analysis": [{"type": "test_out_column_changer"}]}, "annotate",
     "changed the column 'stride_length_m' it was given; an analysis adds its own columns"),
]


@pytest.mark.parametrize("parts, method, cause", [c[1:] for c in BATCH], ids=[c[0] for c in BATCH])
def test_an_output_that_looks_like_a_result_is_a_plugin_error(parts, method, cause, plugin_file, walk):
    meta = dict(walk.meta)
    with pytest.raises(PluginError, match=cause) as info:
        Pipeline.from_dict(_config(plugin_file, **parts)).run(walk)
    assert info.value.method == method and parts["analysis"][0]["type"] in info.value.plugin
    assert walk.meta == meta  # the recording's metadata is as it was


def test_an_analysis_that_adds_its_columns_keeps_every_stride(plugin_file, walk):
    plain = Pipeline.from_dict(_config(plugin_file)).run(walk)
    mine = Pipeline.from_dict(_config(plugin_file, analysis=[{"type": "test_out_honest"}])).run(walk)
    pd.testing.assert_frame_equal(mine.steps.drop(columns="doubled_m"), plain.steps)
    np.testing.assert_array_equal(mine.steps["doubled_m"], 2 * plain.steps["stride_length_m"])


@pytest.mark.parametrize("rows", [-1, 1.5, True, MAX_MODEL_ROWS + 1, 10**12])
def test_a_model_declaring_impossible_rows_is_a_plugin_error_before_the_engine(rows, plugin_file, walk):
    import footzoo.plugins.registry as registry

    Pipeline.from_dict(_config(plugin_file))  # loads the file
    registry.available("correction")["test_out_bad_rows"].rows = rows
    cfg = _config(plugin_file, orientation={"type": "ins"}, corrections=[{"type": "test_out_bad_rows"}])
    with pytest.raises(PluginError, match=rf"declares max_rows={rows!r}; it must be the whole number of rows") as info:
        Pipeline.from_dict(cfg).run(walk)
    assert info.value.method == "model" and "test_out_bad_rows" in info.value.plugin


def test_a_detector_without_statistic_runs_and_says_so(plugin_file, walk):
    res = Pipeline.from_dict(_config(plugin_file, detector={"type": "test_out_no_statistic"})).run(walk)
    assert np.isnan(res.diagnostics["detector_statistic"]).all() and res.diagnostics["detector_stance"].any()
    assert "sets no statistic_" in res.diagnostics["detector_statistic_note"]
    ref = Pipeline.from_dict(_config(plugin_file)).run(walk)
    np.testing.assert_array_equal(res.pos, ref.pos)  # its stance is the detector's: the same track
    assert "detector_statistic_note" not in ref.diagnostics


def _study(plugin_file):
    return Study.from_dict({
        "name": "outputs", "plugins": [plugin_file],
        "base": _config(plugin_file),
        "factors": {"analysis": [[], [{"type": "test_out_meta_writer"}], [{"type": "test_out_stride_dropper"}]],
                    "detector.type": ["angular_rate_fsm", "test_out_no_statistic"]},
        "recordings": [{"simulate": {"path": "straight", "n_strides": 4, "rate": 50, "noise": {"scale": 1}},
                        "seeds": [0]}],
        "metrics": ["strides", "path_length_m"], "sweep": {"points": 5},
    })


def _check_study(table: pd.DataFrame) -> None:
    faulty = table["analysis"] != "[]"
    assert table.loc[faulty, "error"].notna().all() and table.loc[~faulty, "error"].isna().all()
    assert table.loc[table["analysis"].str.contains("meta_writer"), "error"].str.contains(
        "changed its input meta").all()
    assert table.loc[table["analysis"].str.contains("stride_dropper"), "error"].str.contains(
        "dropped 1 of the").all()
    good = table[~faulty & (table["metric"] == "strides")]
    assert len(good) == 2 and (good["value"] == good["value"].iloc[0]).all()  # the same strides with either detector


def test_in_a_study_run_serially_the_faulty_cells_fail_and_say_why(plugin_file):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        table = run_study(_study(plugin_file), jobs=1)
    _check_study(table)
    assert any("test_out_no_statistic' sets no statistic_" in str(w.message) for w in caught)


@pytest.mark.slow
@ON_PROCESS_CLUSTER
def test_in_a_study_on_local_workers_and_on_a_dask_cluster_the_same(plugin_file, process_cluster):
    _check_study(run_study(_study(plugin_file), jobs=2, quiet=True))
    _check_study(run_study(_study(plugin_file), scheduler=process_cluster.scheduler_address, quiet=True))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.integers(0, 6), st.sampled_from(["none", "drop", "add", "shuffle", "change", "extra", "remove"]))
def test_property_annotate_is_accepted_exactly_when_it_keeps_the_strides_and_their_columns(n, change):
    steps = pd.DataFrame({"end_s": np.arange(n, dtype=float), "stride_length_m": np.linspace(1.0, 1.5, n)})
    out = steps.copy()
    if change == "drop" and n:
        out = out.iloc[1:]
    elif change == "add":
        out = pd.concat([out, out.iloc[:1].assign(end_s=99.0)]) if n else out.iloc[:0]
    elif change == "shuffle" and n > 1:
        out = out.iloc[::-1]
    elif change == "change" and n:
        out["stride_length_m"] = out["stride_length_m"] + 0.1
    elif change == "extra":
        out["mine"] = 1.0
    elif change == "remove":
        out = out.drop(columns="stride_length_m")
    broken = not (out.index.equals(steps.index) and all(c in out and out[c].equals(steps[c]) for c in steps))

    class Fake:
        kind, name = "analysis", "fake"

    try:
        check_annotated(Fake(), steps, out)
    except PluginError:
        assert broken
        return
    assert not broken


def test_a_sweep_that_cannot_draw_a_curve_says_why(tmp_path):
    """An oracle detector (it reads the reference) has no threshold; a recording without a stance reference has
    nothing to score: each is said, never a silently empty roc.parquet."""
    from footzoo.io.canonical import write
    from footzoo.sim import simulate

    walk = simulate(path="straight", n_strides=4, rate=50)
    walk.truth = None
    write(walk, tmp_path / "plain.csv")
    study = Study.from_dict({
        "name": "sweep", "base": {"orientation": {"type": "madgwick"}, "detector": {"type": "angular_rate_fsm"},
                                  "corrections": [{"type": "zvu_dedrift"}]},
        "factors": {"detector.type": ["oracle", "angular_rate_fsm"]},  # the oracle fails on plain.csv, said too
        "recordings": [{"simulate": {"path": "straight", "n_strides": 4, "rate": 50}}, str(tmp_path / "plain.csv")],
        "metrics": ["strides"], "sweep": {"points": 5}})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run_study(study, jobs=1)
    said = [str(w.message) for w in caught]
    assert any("detector 'oracle' reads the reference stance itself, so it has no threshold to sweep" in m
               for m in said)
    assert any("recording 'plain' has no reference stance, so no ROC curve is drawn" in m for m in said)
