"""The compiled paths give the same numbers as the reference paths (speed itself: benchmarks/)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from footzoo import Pipeline
from footzoo.filters.measurement import Context, Rows, measurement_function
from footzoo.sim import MagneticDisturbance, NoiseModel, simulate

ROOT = Path(__file__).resolve().parents[2]
KALMAN = ["nguyen2016", "duong2015", "duong2015_zupt", "duong2015_zupt_height"]


@pytest.fixture(scope="module")
def walk():
    """19 m north through a magnetic disturbance from 5 to 15 m and 4 m beyond it (the engines' equality does not
    need a longer walk: the reference engine's Python loop is most of these tests' time)."""
    return simulate(n_strides=16, profile="physical", rate=100.0, noise=NoiseModel(seed=1), distance_sensors=True,
                    clearance=0.1, disturbance=MagneticDisturbance(north=(5.0, 15.0)))


@pytest.mark.parametrize("name", KALMAN)
def test_compiled_kalman_loop_equals_the_filterpy_reference(walk, name):
    p = Pipeline.from_yaml(ROOT / "configs" / f"{name}.yaml")
    ref = p.run(walk, engine="reference", covariance=True)
    fast = p.run(walk, engine="fast", covariance=True)
    for col in ("pos_n", "pos_e", "pos_d", "vel_n", "vel_e", "vel_d", "qw", "qx", "qy", "qz"):
        a, b = ref.samples[col].to_numpy(), fast.samples[col].to_numpy()
        assert np.max(np.abs(a - b)) <= 1e-9 * max(np.max(np.abs(a)), 1.0), col
    np.testing.assert_allclose(fast.diagnostics["P_diag"], ref.diagnostics["P_diag"], rtol=1e-9, atol=1e-15)
    if "distance_calibration" in ref.diagnostics:
        np.testing.assert_allclose(fast.diagnostics["distance_calibration"]["positions"],
                                   ref.diagnostics["distance_calibration"]["positions"], rtol=1e-9)


def test_a_kalman_config_with_an_external_attitude_matches_too(walk):
    cfg = {"orientation": {"type": "madgwick"}, "detector": {"type": "windowed"},
           "corrections": [{"type": "zupt"}, {"type": "height_flat_floor"}]}
    p = Pipeline.from_dict(cfg)
    a, b = p.run(walk, engine="reference"), p.run(walk, engine="fast")
    np.testing.assert_allclose(b.pos, a.pos, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("environ, enabled", [
    ({}, True), ({"FOOTZOO_DISABLE_JIT": "1"}, False), ({"NUMBA_DISABLE_JIT": "1"}, False),
    ({"NUMBA_DISABLE_JIT": "0"}, True), ({"FOOTZOO_DISABLE_JIT": "yes", "NUMBA_DISABLE_JIT": ""}, False),
])
def test_numbas_own_switch_also_selects_the_plain_python_path(environ, enabled):
    """NUMBA_DISABLE_JIT=1 makes numba's njit the identity, which footzoo's compiled paths cannot use (every run
    failed reading the recording): it selects the plain-Python path, as FOOTZOO_DISABLE_JIT does."""
    from footzoo.kernels.jit import jit_enabled

    assert jit_enabled(environ) is enabled


@pytest.mark.slow
def test_without_a_compiler_the_same_code_gives_the_same_numbers(tmp_path):
    """FOOTZOO_DISABLE_JIT=1 runs the kernels as plain Python (an install without numba)."""
    script = (
        "import json, sys, numpy as np, footzoo;"
        "from footzoo.sim import simulate, NoiseModel;"
        "rec = simulate(n_strides=4, profile='physical', rate=100.0, noise=NoiseModel(seed=2));"
        "out = {c: footzoo.Pipeline.from_yaml(c).run(rec).pos[-1].tolist()"
        " for c in ('yun2012', 'huang2016', 'nguyen2016', 'duong2015_zupt')};"
        "out['jit'] = footzoo.kernels.jit.HAVE_NUMBA; print(json.dumps(out))"
    )
    results = []
    for disable in ("0", "1"):
        env = {**os.environ, "FOOTZOO_DISABLE_JIT": disable}
        proc = subprocess.run([sys.executable, "-W", "ignore", "-c", script], capture_output=True, text=True,
                              env=env, cwd=ROOT, timeout=600)
        assert proc.returncode == 0, proc.stderr[-2000:]
        results.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    assert results[1]["jit"] is False
    for name in ("yun2012", "huang2016", "nguyen2016", "duong2015_zupt"):
        np.testing.assert_allclose(results[0][name], results[1][name], rtol=1e-9, atol=1e-12)


def test_import_footzoo_loads_no_heavy_dependency():
    """``import footzoo`` defers pandas, scipy and numba to their first use; the names still resolve."""
    script = (
        "import sys, json, footzoo; before = {m: m in sys.modules for m in ('pandas', 'scipy', 'numba')};"
        "p = footzoo.Pipeline; from footzoo import Recording, load, ConfigError;"
        "print(json.dumps({'before': before, 'pipeline': p.__module__, 'all': sorted(footzoo.__all__)}))"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["before"] == {"pandas": False, "scipy": False, "numba": False}
    assert out["pipeline"] == "footzoo.runtime.pipeline"
    assert "Pipeline" in out["all"] and "load" in out["all"]


@pytest.mark.slow  # a new process importing footzoo (about 4 s)
def test_pipeline_and_readers_load_no_compiler_until_a_kernel_runs():
    """``from footzoo import Pipeline, load`` and building every plug-in import neither numba, scipy nor filterpy.

    The measurement functions of the Kalman corrections are compiled at their first use, not when
    their modules are imported; numba comes with the first run.
    """
    script = (
        "import sys, json; from footzoo import Pipeline, load; heavy = ('numba', 'scipy', 'filterpy');"
        "out = {'import': [m for m in heavy if m in sys.modules]};"
        "from footzoo.plugins.registry import available;"
        "[available(k) for k in ('orientation', 'detector', 'correction')];"
        "p = Pipeline.from_yaml('nguyen2016'); out['build'] = [m for m in heavy if m in sys.modules];"
        "from footzoo.sim import simulate; p.run(simulate(n_strides=3, rate=100.0, profile='physical'));"
        "import footzoo.kernels.jit as j; out['run'] = 'numba' in sys.modules; out['jit'] = j.HAVE_NUMBA;"
        "print(json.dumps(out))"
    )
    proc = subprocess.run([sys.executable, "-W", "ignore", "-c", script], capture_output=True, text=True, cwd=ROOT,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["import"] == [] and out["build"] == []
    assert out["run"] == out["jit"]


def test_kernels_are_compiled_at_first_call_and_callers_see_the_compiled_callees():
    """After the first kernel call every footzoo module attribute naming a kernel is numba's dispatcher."""
    script = (
        "import sys, json, numpy as np, footzoo, footzoo.kernels.jit as j;"
        "from footzoo.orientation import fqa_complementary as fc; fqa = sys.modules['footzoo.orientation.fqa'];"
        "lazy = type(fc.complementary_kernel).__name__;"
        "q = fc.complementary_kernel(np.array([1.0, 0, 0, 0]), np.zeros((3, 3)), np.full(3, 0.01),"
        " np.tile([0.0, 0.0, -9.81], (3, 1)), np.zeros((1, 3)), np.ones(3), np.zeros(3, dtype=bool));"
        "print(json.dumps({'numba': j.HAVE_NUMBA, 'lazy': lazy, 'after': [type(fc.complementary_kernel).__name__,"
        " type(fc.fqa_sample).__name__, type(fqa.fqa_sample).__name__], 'q': q[-1].tolist()}))"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    np.testing.assert_allclose(out["q"], [1.0, 0.0, 0.0, 0.0], atol=1e-12)  # level, still: no rotation
    if out["numba"]:
        assert out["lazy"] == "_Kernel"
        assert out["after"] == ["CPUDispatcher"] * 3


@measurement_function
def _dense_rows_measure(ctx, rows):
    """Test model: in stance, three rows each a mix of the velocity (true value 0) and small attitude
    and position terms (several nonzero entries per row)."""
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    if not stance:
        return m
    for r in range(3):
        zr = 0.0
        for j in range(3):
            H[m, idx[3] + j] = par[r * 9 + j]
            zr += par[r * 9 + j] * nav[7 + j]
            if par[r * 9 + 3 + j] != 0.0:
                H[m, idx[0] + j] = par[r * 9 + 3 + j]
            if par[r * 9 + 6 + j] != 0.0:
                H[m, idx[2] + j] = par[r * 9 + 6 + j]
        z[m] = zr
        R[m] = 1e-4 * (r + 1)
        m += 1
    return m


def _dense_engine(engine):
    from footzoo.filters.engine import KalmanEngine, NavigationNoise
    from footzoo.filters.measurement import MeasurementModel, StateBlock

    rng = np.random.default_rng(3)
    par = np.zeros(27)
    for r in range(3):
        par[r * 9: r * 9 + 3] = np.eye(3)[r] + 0.3 * rng.normal(size=3)
        par[r * 9 + 3: r * 9 + 9] = 0.01 * rng.normal(size=6) * (rng.random(6) < 0.5)
    model = MeasurementModel(measure=_dense_rows_measure, max_rows=3, par=par)
    blocks = [StateBlock("gyro_bias", 3, 1e-6, 1e-10), StateBlock("acc_bias", 3, 1e-4, 1e-8)]
    return KalmanEngine(True, blocks, [model], NavigationNoise(), 9.81, engine=engine)


def test_rows_taken_one_at_a_time_equal_the_stacked_update(walk):
    """Rows with several nonzero entries each, updated in turn (fast) and stacked (filterpy): the same filter."""
    stance = np.asarray(Pipeline.from_yaml("nguyen2016").detect(walk).stance_)
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    ref = _dense_engine("reference").run(walk.t, walk.acc, walk.gyr, stance, q0)
    fast = _dense_engine("fast").run(walk.t, walk.acc, walk.gyr, stance, q0)
    for key in ("quat", "vel", "pos", "gyro_bias", "acc_bias"):
        a, b = ref[key], fast[key]
        assert np.max(np.abs(a - b)) <= 1e-9 * max(np.max(np.abs(a)), 1.0), key
    np.testing.assert_allclose(fast["P_diag"], ref["P_diag"], rtol=1e-9, atol=1e-15)


def test_compiled_loop_keeps_the_covariance_exactly_symmetric(walk):
    eng = _dense_engine("fast")
    stance = np.asarray(Pipeline.from_yaml("nguyen2016").detect(walk).stance_)
    state = eng.start(np.array([1.0] + [0.0] * 15))
    eng.advance(state, walk.t, walk.acc, walk.gyr, stance, None, [None], 0)
    assert np.array_equal(state.filter.P, state.filter.P.T)


def test_alignment_runs_fqa_of_one_sample_as_python_with_the_compiled_kernels_numbers():
    from footzoo.orientation.fqa import fqa, fqa_sample

    rng = np.random.default_rng(0)
    for _ in range(200):
        a, m = rng.normal(size=3), rng.normal(size=3)
        py = getattr(fqa_sample, "py_func", fqa_sample)
        assert np.array_equal(fqa(a[None], m[None])[0], np.array(py(*a, *m, True)))
        assert np.array_equal(fqa(a[None])[0], np.array(py(*a, 0.0, 0.0, 0.0, False)))


def _allocating_measure(ctx, rows):
    """Test model: allocates a temporary array (so it needs numba's reference counting)."""
    k, t, nav, w, f, stance, idx, par, mem, data = ctx
    z, H, R, m = rows
    v = np.zeros(3)
    for i in range(3):
        v[i] = nav[7 + i]
    if not stance:
        return m
    for i in range(3):
        H[m, idx[3] + i] = 1.0
        z[m] = v[i]
        R[m] = par[0]
        m += 1
    return m


def test_measurement_functions_compile_without_reference_counting_and_allocating_ones_still_work():
    from footzoo.corrections.ekf_zupt import zero_velocity_measure
    from footzoo.kernels import jit as _jit

    if not _jit.HAVE_NUMBA:
        pytest.skip("numba not installed")
    from footzoo.kernels.internals import counts_references

    assert not counts_references(zero_velocity_measure.compiled())
    fn = measurement_function(_allocating_measure)  # compiled with reference counting (or loaded so from the cache)
    z, H, R = np.zeros(3), np.zeros((3, 9)), np.zeros(3)
    nav = np.zeros(16)
    nav[7:10] = [1.0, 2.0, 3.0]
    idx = np.array([0, -1, 3, 6, -1], dtype=np.int64)
    conv = fn.compiled()  # the calling convention the loop calls, with the function compiled into it
    assert counts_references(conv)
    m = conv(0, 0.0, nav, np.zeros(3), np.zeros(3), True, idx, np.array([1e-4]), np.zeros(0), np.zeros(0), z, H, R, 0)
    assert m == 3 and z.tolist() == [1.0, 2.0, 3.0] and H[:, 6:9].tolist() == np.eye(3).tolist()
    # called itself, it is the function as written, in Python: the same rows
    z2, H2, R2 = np.zeros(3), np.zeros((3, 9)), np.zeros(3)
    ctx = Context(0, 0.0, nav, np.zeros(3), np.zeros(3), True, idx, np.array([1e-4]), np.zeros(0), np.zeros(0))
    assert fn(ctx, Rows(z2, H2, R2, 0)) == 3 and np.array_equal(z2, z) and np.array_equal(H2, H)


def _scaled_sum(x, pair, out):
    """out[0] = sum(x) * pair[0] + pair[1].sum(): a kernel over an array and a tuple (for DirectCall)."""
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i]
    extra = 0.0
    for i in range(pair[1].shape[0]):
        extra += pair[1][i]
    out[0] = s * pair[0] + extra


def test_a_direct_call_runs_the_machine_code_numba_would_choose_for_every_call():
    """DirectCall skips numba's typing of arguments that have not changed: on every call the signature it
    used is the one numba computes from the arguments (also for the same array once made read-only), the
    result is the kernel's, and a signature not compiled yet (another dtype, a strided view, a read-only
    array) goes through the dispatcher."""
    from footzoo.kernels import jit as _jit
    from footzoo.kernels.functions import direct

    kernel = _jit.njit(_scaled_sum)
    call = direct(kernel)
    out, expected = np.zeros(1), np.zeros(1)
    x64 = np.arange(10.0)
    frozen = np.arange(4.0)
    frozen.setflags(write=False)
    pair = (2.0, np.ones(3))
    flipped = np.arange(6.0)  # the same array again after it was made read-only: its type changed
    cases = [(x64, pair), (x64, pair), (x64[2:], pair), (x64[::2], pair), (x64.astype(np.float32), pair),
             (x64, (2.0, np.ones(3)[::2])), (frozen, (3, np.ones(2))), (x64[1:], pair), (flipped, pair),
             (flipped, pair)]
    for i, (x, p) in enumerate(cases):
        if i == len(cases) - 1:
            flipped.setflags(write=False)
        call(x, p, out)
        _scaled_sum(x, p, expected)  # the same function as Python
        assert out[0] == expected[0]
        if _jit.HAVE_NUMBA:
            numba = _jit.load_numba()
            assert call._types == tuple(numba.typeof(a) for a in (x, p, out))
    if _jit.HAVE_NUMBA:  # the first call compiled every new signature; the rest ran the code compiled for it
        assert len(_jit.compiled(kernel).overloads) == 6


def test_a_direct_call_of_a_python_function_calls_it():
    from footzoo.kernels.functions import direct

    assert direct(lambda a, b: a + b)(2, 3) == 5


def test_the_forward_loop_counts_no_references_and_other_kernels_do():
    """The Kalman filter's loop is compiled without reference counting (njit(refcounts=False): it allocates
    nothing), a kernel declared without the option keeps it."""
    from footzoo.filters import forward
    from footzoo.kernels import jit as _jit

    if not _jit.HAVE_NUMBA:
        pytest.skip("numba not installed")
    from footzoo.kernels.internals import counts_references

    assert not counts_references(_jit.compiled(forward.forward_span))
    assert counts_references(_jit.compiled(forward.run))
