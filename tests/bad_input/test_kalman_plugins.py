"""Kalman plug-ins that break their measurement model's contract cannot crash the process.

A correction's ``measure``, ``feedback`` and ``after`` functions run inside the compiled loop. A plug-in's are
compiled with bounds checks and get ``z``, ``H`` and ``R`` cut at the rows its model declares, so a write past them
(or outside ``mem``) and a row count it did not declare are each a PluginError naming the correction — in a
batch run, on both engines, live, in ``check_plugin``, on the command line (exit 4) and in a study (its cells
only). Before, such a plug-in corrupted the heap (SIGSEGV, ``free(): invalid next size``).
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml

import footzoo
from footzoo import Pipeline, PluginError
from footzoo.apps.cli import EXIT_PLUGIN, main
from footzoo.filters.measurement import VEL, MeasurementModel, feedback_function, measurement_function
from footzoo.io.canonical import write
from footzoo.plugins.base import KalmanCorrection
from footzoo.runtime.stream import Stream
from footzoo.sim import NoiseModel, simulate


@measurement_function
def three_rows(ctx, rows):
    """Writes the three velocity rows of a zero-velocity update, with a model that declares one."""
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    if not stance:
        return m
    for i in range(3):
        H[m, idx[VEL] + i] = 1.0
        z[m] = nav[7 + i]
        R[m] = 0.01
        m += 1
    return m


@measurement_function
def far_write(ctx, rows):
    """Writes a column of H far outside the error state."""
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    if stance:
        H[m, 1000] = 1.0
        z[m] = 0.0
        R[m] = 1.0
        return m + 1
    return m


@measurement_function
def claims_rows(ctx, rows):
    """Writes nothing but says it wrote five rows (one declared)."""
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    return m + 5 if stance else m


@measurement_function
def gives_back(ctx, rows):
    """Returns a row before the first free one."""
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    return m - 1 if stance else m


@measurement_function
def no_rows(ctx, rows):
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    return m


def forgets_count(ctx, rows):
    """Plain Python: writes its row but returns nothing (the row count forgotten)."""
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    if stance:
        H[m, idx[VEL]] = 1.0
        R[m] = 0.01


def fractional_count(ctx, rows):
    """Plain Python: returns a row count that is not a whole number."""
    z, H, R, m = rows
    return m + 0.5


@feedback_function
def far_memory(ctx, dx):
    """Writes past the end of its two-value memory."""
    ctx.mem[50] = dx[0]


FUNCTIONS = {"three_rows": (three_rows, None), "far_write": (far_write, None), "claims_rows": (claims_rows, None),
             "gives_back": (gives_back, None), "far_memory": (no_rows, far_memory),
             "forgets_count": (forgets_count, None), "fractional_count": (fractional_count, None)}
#: Plain-Python functions: only the reference engine runs them (``auto`` falls back to it with a warning).
PLAIN = ("forgets_count", "fractional_count")


class Careless(KalmanCorrection):
    """A zero-velocity update whose measurement model breaks the contract as ``how`` says."""

    name = "test_careless_update"
    paper = "none: a test of the measurement model's contract"
    how = "three_rows"

    def model(self, samples):
        measure, feedback = FUNCTIONS[self.how]
        extra = {"feedback": feedback} if feedback is not None else {}
        return MeasurementModel(measure=measure, max_rows=1, mem=np.zeros(2), **extra)


CLASSES = {how: type(f"Careless_{how}", (Careless,), {"name": f"test_careless_{how}", "how": how,
                                                        "__doc__": Careless.__doc__}) for how in FUNCTIONS}


@pytest.fixture(autouse=True, scope="module")
def _registered():
    from footzoo.plugins import registry

    for cls in CLASSES.values():
        footzoo.register(cls)
    yield
    for cls in CLASSES.values():
        registry._REGISTRY[cls.kind].pop(cls.name, None)


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=1))


def _config(how: str) -> dict:
    return {"name": "careless", "orientation": {"type": "ins"}, "detector": {"type": "shoe"},
            "corrections": [{"type": "ekf_zupt"}, {"type": f"test_careless_{how}"}]}


CAUSES = {"three_rows": "outside the rows its model declares", "far_write": "outside the rows its model declares",
          "claims_rows": "returned 5 rows at sample", "gives_back": "below the first free row",
          "far_memory": "outside the rows its model declares", "forgets_count": r"returned None \(NoneType\)",
          "fractional_count": r"returned \d+\.5 \(float\), not a row count"}


@pytest.mark.parametrize("how", [h for h in FUNCTIONS if h not in PLAIN])
def test_a_careless_kalman_plugin_is_a_plugin_error_naming_it(how, walk):
    pipe = Pipeline.from_dict(_config(how))
    with pytest.raises(PluginError, match=CAUSES[how]) as info:
        pipe.run(walk)
    assert info.value.plugin == f"correction 'test_careless_{how}'" and info.value.method == "measure"
    assert "max_rows" in str(info.value)
    # the process goes on: the same pipeline without the plug-in still runs and gives the right numbers
    good = Pipeline.from_dict({**_config(how), "corrections": [{"type": "ekf_zupt"}]}).run(walk)
    assert np.isfinite(good.pos).all()


@pytest.mark.parametrize("how", PLAIN)
def test_a_measure_that_returns_no_row_count_is_a_plugin_error_naming_it(how, walk):
    """None (a forgotten return) or a fraction is refused with what it returned and what to return."""
    with pytest.raises(PluginError, match=CAUSES[how]) as info:
        Pipeline.from_dict(_config(how)).run(walk, engine="reference")
    assert info.value.plugin == f"correction 'test_careless_{how}'" and info.value.method == "measure"
    assert "return m plus the number of rows" in str(info.value)


@pytest.mark.parametrize("how", ["three_rows", "claims_rows", "far_memory"])
def test_the_reference_engine_refuses_the_same_plugins(how, walk):
    with pytest.raises(PluginError, match=f"correction 'test_careless_{how}'"):
        Pipeline.from_dict(_config(how)).run(walk, engine="reference")


# slow: compiles the forward loop for a signature no shipped config has (about 12 s on a fresh install)
@pytest.mark.slow
@pytest.mark.parametrize("smoother", ["rts", "stepwise"])
@pytest.mark.parametrize("how", ["three_rows", "claims_rows", "far_memory"])
def test_a_smoothed_run_refuses_the_same_plugins(how, smoother, walk):
    """The smoothers' forward passes (RTS with its checkpoints, step-wise in the loop) check the same contract."""
    with pytest.raises(PluginError, match=CAUSES[how]):
        Pipeline.from_dict({**_config(how), "smoother": smoother}).run(walk)


@pytest.mark.parametrize("how", ["three_rows", "claims_rows"])
def test_live_a_careless_kalman_plugin_is_a_plugin_error(how, walk):
    stream = Stream(Pipeline.from_dict(_config(how)), rate=walk.rate)
    with pytest.raises(PluginError, match=f"correction 'test_careless_{how}'"):
        stream.run(walk)


class Honest(Careless):
    """The three velocity rows of a zero-velocity update, declared."""

    name = "test_careless_honest"

    def model(self, samples):
        return MeasurementModel(measure=three_rows, max_rows=3)


CLASSES["honest"] = Honest


def test_a_model_that_keeps_its_contract_is_unchanged_by_the_checks(walk):
    """A plug-in that writes its declared rows gives the numbers of the same rows from the built-in update."""
    mine = Pipeline.from_dict({**_config("honest"), "corrections": [{"type": "test_careless_honest"}]}).run(walk)
    plain = {"type": "ekf_zupt", "velocity_std": 0.1, "gyro_bias": False, "accel_bias": False, "zero_rate": False}
    ref = Pipeline.from_dict({**_config("honest"), "corrections": [plain]}).run(walk)
    np.testing.assert_allclose(mine.pos, ref.pos, rtol=0, atol=1e-12)


def test_check_plugin_reports_the_fault_instead_of_crashing():
    """check_plugin stops at the fault with the plug-in's error (it used to die with the process)."""
    with pytest.raises((AssertionError, PluginError), match="outside the rows its model declares"):
        footzoo.check_plugin(CLASSES["three_rows"], verbose=False)


def test_cli_exits_4_and_a_study_fails_only_the_careless_cells(tmp_path, capsys):
    sim = tmp_path / "walk.csv"
    write(simulate(n_strides=3, rate=100.0), sim)
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(_config("far_write")))
    assert main(["run", str(tmp_path / "c.yaml"), "--data", str(sim)]) == EXIT_PLUGIN
    err = capsys.readouterr().err
    assert "correction 'test_careless_far_write'" in err and "Traceback" not in err and "internal error" not in err

    from footzoo.studies import Study, run_study

    study = Study.from_dict({
        "name": "careless", "base": {**_config("three_rows"), "corrections": [{"type": "ekf_zupt"}]},
        "factors": {"corrections": [[{"type": "ekf_zupt"}],
                                    [{"type": "ekf_zupt"}, {"type": "test_careless_far_write"}]]},
        "recordings": [{"simulate": {"path": "straight", "n_strides": 3, "rate": 100}, "seeds": [0]}],
        "metrics": ["path_length_m"],
    })
    table = run_study(study)
    failed = table["error"].notna()
    assert failed.any() and (~failed).any()
    assert table.loc[failed, "error"].str.contains("test_careless_far_write").all()


def test_the_fault_capture_survives_a_replaced_hook_and_restores_it(walk):
    """Something else (a test runner, an application) may swap sys.unraisablehook between runs: a write
    outside the arrays is still caught, and the caller's hook is back afterwards."""
    import sys

    def theirs(unraisable):
        raise AssertionError("a compiled plug-in's fault reached the caller's hook")

    before = sys.unraisablehook
    sys.unraisablehook = theirs
    try:
        for _ in range(2):
            with pytest.raises(PluginError, match="test_careless_far_memory"):
                Pipeline.from_dict(_config("far_memory")).run(walk)
            assert sys.unraisablehook is theirs
    finally:
        sys.unraisablehook = before


def unusable_rows(ctx, rows):
    """Plain Python: a zero-velocity update whose row values come from ``par``: H's entry, the factor of z, R."""
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    if not stance:
        return m
    for i in range(3):
        H[m, idx[VEL] + i] = par[0]
        z[m] = nav[7 + i] * par[1]
        R[m] = par[2]
        m += 1
    return m


#: (H entry, factor of z, R) -> the problem the error names; z's factor inf gives inf or NaN (0 * inf)
UNUSABLE = {"R zero": ((1.0, 1.0, 0.0), "R .* not a positive number"),
            "R negative": ((1.0, 1.0, -0.01), "R .* not a positive number"),
            "R NaN": ((1.0, 1.0, np.nan), "R that is NaN or infinite"),
            "R inf": ((1.0, 1.0, np.inf), "R that is NaN or infinite"),
            "z inf": ((1.0, np.inf, 0.01), "z .* NaN or infinite"),
            "H NaN": ((np.nan, 1.0, 0.01), "H .* NaN or infinite entry")}


class Unusable(KalmanCorrection):
    """Rows no Kalman update can use, their values given as ``values`` (H entry, factor of z, R)."""

    name = "test_unusable_rows"
    paper = "none: a test of the measurement model's contract"
    values = (1.0, 1.0, 0.01)
    measure = staticmethod(unusable_rows)

    def model(self, samples):
        return MeasurementModel(measure=self.measure, max_rows=3, par=np.array(self.values, float))


@pytest.mark.parametrize("problem", UNUSABLE)
def test_a_row_no_update_can_use_is_a_plugin_error_naming_the_problem(problem, walk):
    """A variance that is not positive or a NaN/inf residual or matrix entry used to run on silently (a negative R
    makes the update's covariance indefinite; a NaN one spreads through the whole state)."""
    values, cause = UNUSABLE[problem]
    cls = type("UnusableNow", (Unusable,), {"values": values})
    footzoo.register(cls)
    try:
        with pytest.raises(PluginError, match=f"test_unusable_rows': its measure function wrote a row no Kalman "
                                              f"update can use at sample \\d+: row 0 of its own has {cause}") as info:
            Pipeline.from_dict({**_config("honest"), "corrections": [{"type": "test_unusable_rows"}]}).run(
                walk, engine="reference")
        assert info.value.method == "measure" and "positive, finite variance R" in str(info.value)
    finally:
        from footzoo.plugins import registry

        registry._REGISTRY[cls.kind].pop(cls.name, None)


# slow: compiles the forward loop for a signature no shipped config has (as the smoothed runs above)
@pytest.mark.slow
@pytest.mark.parametrize("how", ["batch", "rts", "live"])
def test_the_compiled_loops_refuse_a_row_no_update_can_use(how, walk):
    from footzoo.filters.measurement import measurement_function
    from footzoo.plugins import registry

    cls = type("UnusableCompiled", (Unusable,), {"values": (1.0, 1.0, -0.01),
                                                 "measure": staticmethod(measurement_function(unusable_rows))})
    footzoo.register(cls)
    config = {**_config("honest"), "corrections": [{"type": "ekf_zupt"}, {"type": "test_unusable_rows"}]}
    try:
        with pytest.raises(PluginError, match="test_unusable_rows'.*R .* not a positive number"):
            if how == "live":
                Stream(Pipeline.from_dict(config), rate=walk.rate).run(walk)
            else:
                Pipeline.from_dict({**config, **({"smoother": "rts"} if how == "rts" else {})}).run(walk)
    finally:
        registry._REGISTRY[cls.kind].pop(cls.name, None)
