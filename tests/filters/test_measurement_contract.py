"""The measurement functions' contract: ``measure(ctx, rows)``, ``feedback(ctx, dx)``, ``after(ctx)``.

Checked against hand-made cases on both engines; a function written with the engine's positional
arguments instead is refused, naming the contract; and the compiled calling convention of a plug-in's
function is cached across processes like footzoo's own.
"""

from __future__ import annotations

import inspect
import json
import os
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

from footzoo.core.errors import PluginError
from footzoo.filters.engine import KalmanEngine, NavigationNoise
from footzoo.filters.measurement import (
    VEL,
    Context,
    MeasurementModel,
    Rows,
    StateBlock,
    V,
    after_function,
    calling,
    convention,
    feedback_function,
    measurement_function,
)
from footzoo.kernels import jit as _jit
from footzoo.sim import simulate


def _velocity_rows(ctx, rows):
    """In stance, ``δv = v̂`` with σ = par[0]; counts the stance samples in mem[0]."""
    z, H, R, m = rows
    if not ctx.stance:
        return m
    ctx.mem[0] += 1.0
    for i in range(3):
        H[m, ctx.idx[VEL] + i] = 1.0
        z[m] = ctx.nav[V + i]
        R[m] = ctx.par[0] * ctx.par[0]
        m += 1
    return m


def _bias_feedback(ctx, dx):
    """Adds the update's own-block error to mem[1:4] (an own block of three states)."""
    for i in range(3):
        ctx.mem[1 + i] += dx[ctx.idx[5] + i]


def _last_speed(ctx):
    """The corrected speed into mem[4] and the sample's time into mem[5]."""
    ctx.mem[4] = np.sqrt(ctx.nav[V] ** 2 + ctx.nav[V + 1] ** 2 + ctx.nav[V + 2] ** 2)
    ctx.mem[5] = ctx.t


def _velocity_rows_positional(k, t, nav, w, f, stance, idx, par, mem, data, z, H, R, m):
    """The same as :func:`_velocity_rows`, written with the engine's positional arguments (refused)."""
    return m


def _bias_feedback_positional(dx, idx, par, mem):
    return None


def _last_speed_positional(k, nav, stance, idx, par, mem):
    return None


def _engine(measure, feedback, after, engine):
    model = MeasurementModel(measure=measure, feedback=feedback, after=after, max_rows=3, par=np.array([0.01]),
                             mem=np.zeros(6), block_names=["own"], diagnostics=lambda mem: {"mem": mem.copy()})
    blocks = [StateBlock("own", 3, 1e-4, 0.0)]
    return KalmanEngine(True, blocks, [model], NavigationNoise(), 9.81, engine=engine)


@pytest.fixture(scope="module")
def walk():
    rec = simulate("straight", n_strides=8, rate=100, seed=4)
    return rec, np.asarray(rec.truth.stance, bool)


def _run(walk, measure, feedback, after, engine):
    rec, stance = walk
    eng = _engine(measure, feedback, after, engine)
    return eng.run(rec.t, rec.acc, rec.gyr, stance, np.array([1.0, 0.0, 0.0, 0.0])), eng


def test_the_context_and_rows_hold_the_fields_the_engine_passes_in_order():
    nav, w, f = np.arange(16.0), np.arange(3.0), -np.arange(3.0)
    idx, par, mem, data = np.arange(6), np.ones(2), np.zeros(1), np.full(2, 7.0)
    z, H, R = np.zeros(2), np.zeros((2, 6)), np.zeros(2)
    seen = {}

    def measure(ctx, rows):
        seen["ctx"], seen["rows"] = ctx, rows
        return rows.m + 1

    def after(ctx):
        seen["after"] = ctx

    assert convention(measure, "measure")(3, 0.5, nav, w, f, True, idx, par, mem, data, z, H, R, 1) == 2
    ctx, rows = seen["ctx"], seen["rows"]
    assert isinstance(ctx, Context) and isinstance(rows, Rows)
    assert (ctx.k, ctx.t, ctx.stance, rows.m) == (3, 0.5, True, 1)
    assert all(a is b for a, b in zip((ctx.nav, ctx.w, ctx.f, ctx.idx, ctx.par, ctx.mem, ctx.data),
                                      (nav, w, f, idx, par, mem, data), strict=True))
    assert rows.z is z and rows.H is H and rows.R is R
    convention(after, "after")(4, 0.6, nav, w, f, False, idx, par, mem, data)
    assert seen["after"]._replace(k=3, t=0.5, stance=True) == ctx


@pytest.mark.parametrize("engine", ["fast", "reference"])
def test_a_model_in_the_context_form_runs_and_its_functions_see_the_sample(walk, engine):
    if engine == "fast" and not _jit.HAVE_NUMBA:
        pytest.skip("numba not installed")
    fns = (measurement_function(_velocity_rows), feedback_function(_bias_feedback), after_function(_last_speed))
    out, _ = _run(walk, *fns, engine)
    rec, stance = walk
    mem = out["diagnostics"]["mem"]
    assert mem[0] == stance[1:].sum()  # one call in every stance sample (sample 0 is the start)
    assert mem[5] == rec.t[-1]  # after saw the last sample's time
    assert mem[4] == pytest.approx(np.linalg.norm(out["vel"][-1]), abs=1e-12)  # ... and its corrected state
    assert np.abs(out["vel"][stance]).max() < 0.05  # the rows pulled the stance velocity to zero


@pytest.mark.parametrize(("fn", "role", "contract"), [
    (_velocity_rows_positional, "measure", r"\(ctx, rows\)"), (_bias_feedback_positional, "feedback", r"\(ctx, dx\)"),
    (_last_speed_positional, "after", r"\(ctx\)")])
def test_a_function_with_positional_arguments_is_refused_naming_the_contract(fn, role, contract):
    mark = {"measure": measurement_function, "feedback": feedback_function, "after": after_function}[role]
    with pytest.raises(PluginError, match=rf"{role} function .*{fn.__name__} takes \d+ argument\(s\); a {role} "
                                          rf"function takes {contract}"):
        mark(fn)
    with pytest.raises(PluginError, match=contract):
        calling(fn, role)


def test_a_function_with_another_number_of_arguments_is_the_plugins_error_naming_the_contract():
    def measure(ctx):
        return 0

    def after(k, nav):
        return None

    with pytest.raises(PluginError, match=r"measure function .*measure takes 1 argument\(s\); a measure function "
                                          r"takes \(ctx, rows\)"):
        measurement_function(measure)
    with pytest.raises(PluginError, match=r"takes 2 argument\(s\); a after function takes \(ctx\)"):
        calling(after, "after")


def test_an_unmarked_function_is_called_in_python_through_the_same_convention():
    conv = calling(_velocity_rows, "measure")
    z, H, R = np.zeros(3), np.zeros((3, 9)), np.zeros(3)
    nav = np.zeros(16)
    nav[V:V + 3] = [1.0, -2.0, 0.5]
    idx = np.array([0, -1, 3, 6, -1], dtype=np.int64)
    m = conv(0, 0.0, nav, np.zeros(3), np.zeros(3), True, idx, np.array([0.1]), np.zeros(1), np.zeros(0), z, H, R, 0)
    assert m == 3 and z.tolist() == [1.0, -2.0, 0.5] and H[:, 6:9].tolist() == np.eye(3).tolist()
    np.testing.assert_allclose(R, 0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        calling(_velocity_rows, "measure")  # the context form warns about nothing


@pytest.mark.slow  # two new processes (about 4 s)
def test_a_plugins_compiled_convention_is_cached_and_a_new_process_compiles_nothing(tmp_path):
    if not _jit.HAVE_NUMBA:
        pytest.skip("numba not installed")
    # a plug-in module outside footzoo: this file's _velocity_rows, marked there
    (tmp_path / "my_rows.py").write_text("import numpy as np\nfrom footzoo.filters.measurement import V, VEL, "
                                         "measurement_function\n\n\n" + inspect.getsource(_velocity_rows)
                                         + "\n\nmy_rows = measurement_function(_velocity_rows)\n")
    script = textwrap.dedent('''
        import json, sys
        sys.path.insert(0, sys.argv[1])
        import numpy as np
        from my_rows import my_rows
        conv = my_rows.compiled()
        z, H, R = np.zeros(3), np.zeros((3, 9)), np.zeros(3)
        nav = np.zeros(16); nav[7:10] = [1.0, 2.0, 3.0]
        idx = np.array([0, -1, 3, 6, -1], dtype=np.int64)
        empty = np.zeros(0)
        m = conv(0, 0.0, nav, np.zeros(3), np.zeros(3), True, idx, np.array([0.1]), np.zeros(1), empty, z, H, R, 0)
        print(json.dumps({"m": int(m), "z": z.tolist(), "hits": sum(conv.stats.cache_hits.values()),
                          "misses": sum(conv.stats.cache_misses.values())}))
    ''')
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    runs = []
    for _ in range(2):
        proc = subprocess.run([sys.executable, "-c", script, str(tmp_path)], capture_output=True, text=True,
                              env=env, timeout=300)
        assert proc.returncode == 0, proc.stderr[-2000:]
        runs.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    assert runs[0]["m"] == runs[1]["m"] == 3 and runs[0]["z"] == runs[1]["z"] == [1.0, 2.0, 3.0]
    assert runs[0]["misses"] >= 1 and runs[1]["hits"] >= 1 and runs[1]["misses"] == 0


@pytest.mark.skipif(not _jit.HAVE_NUMBA, reason="numba not installed")
def test_looking_at_a_model_function_compiles_nothing_and_numbas_attributes_compile_it():
    """A test collector, ``hasattr`` or a documentation tool probes names a function does not have: an
    AttributeError at once, not a compile (it took about 1 s per function, in every process that looked)."""

    def one_row(ctx, rows):
        m = rows.m
        rows.z[m] = 0.0
        rows.R[m] = 1.0
        return m + 1

    f = measurement_function(one_row)
    for probe in ("pytestmark", "footzoo_convention", "_pytestfixturefunction", "__wrapped_by__", "anything"):
        assert not hasattr(f, probe)
    rows = Rows(np.full(2, 9.0), np.zeros((2, 3)), np.zeros(2), 1)
    assert f(None, rows) == 2 and rows.z.tolist() == [9.0, 0.0] and rows.R.tolist() == [0.0, 1.0]  # as written
    assert f._dispatcher is None  # nothing compiled by the probes nor by the call
    assert len(f.signatures) >= 1 and f._dispatcher is not None  # numba's attribute: compiled, for it
