"""What a call of a measurement function through its address costs, by how its arguments are passed.

Usage: python benchmarks/calling_convention.py [--calls 2e6] [--repeat 3]

A compiled loop calls footzoo's zero-velocity ``measure`` (three rows in every other sample) through
numba first-class function values, as the error-state loop does, three ways:

* ``positional``: the function takes the fourteen fields as positional arguments;
* ``named tuples``: the function's own signature takes footzoo's ``Context`` and ``Rows``
  (:mod:`footzoo.filters.measurement`), so the loop builds them and passes them through the address;
* ``convention``: the function takes ``(ctx, rows)`` and is compiled into footzoo's calling convention
  (:func:`footzoo.filters.measurement.convention`, positional arguments), as the engine does.

Prints nanoseconds per call (the minimum over the repetitions, all three interleaved).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from numba import njit
from numba import types as nt

from footzoo.corrections.ekf_zupt import zero_velocity_measure
from footzoo.filters.measurement import VEL, Context, Rows, V, convention
from footzoo.kernels.functions import fixed_address, model_signature
from footzoo.kernels.internals import compile_options, quiet


def positional(k, t, nav, w, f, stance, idx, par, mem, data, z, H, R, m):
    """footzoo's zero-velocity rows (the ``measure`` of ``ekf_zupt`` without its bias guard), positional."""
    if not stance:
        return m
    for i in range(3):
        H[m, idx[VEL] + i] = 1.0
        z[m] = nav[V + i]
        R[m] = par[0] * par[0]
        m += 1
    return m


@njit
def loop_positional(fns, n, nav, w, f, idx, par, mem, data, z, H, R):
    total = 0
    for k in range(n):
        m = fns[0](k, 0.01 * k, nav, w, f, k % 2 == 0, idx, par, mem[0:1], data[k, 0:1], z, H, R, 0)
        total += m
        for a in range(m):
            H[a, idx[VEL] + a] = 0.0
    return total


@njit
def loop_named(fns, n, nav, w, f, idx, par, mem, data, z, H, R):
    total = 0
    for k in range(n):
        m = fns[0](Context(k, 0.01 * k, nav, w, f, k % 2 == 0, idx, par, mem[0:1], data[k, 0:1]),
                   Rows(z, H, R, 0))
        total += m
        for a in range(m):
            H[a, idx[VEL] + a] = 0.0
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=float, default=2e6)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    n = int(args.calls)
    sig = model_signature("measure")
    f1 = nt.float64[::1]
    fields = [nt.int64, nt.float64, f1, f1, f1, nt.boolean, nt.int64[::1], f1, f1, f1]
    named_sig = nt.int64(nt.NamedTuple(fields, Context), nt.NamedTuple([f1, nt.float64[:, ::1], f1, nt.int64], Rows))
    no_refcount = compile_options(refcounting=False)
    fn_positional = fixed_address(njit(sig, **no_refcount)(positional))
    with_context = zero_velocity_measure.py_func  # footzoo's own, (ctx, rows)
    fn_named = fixed_address(njit(named_sig, **no_refcount)(with_context))
    fn_convention = fixed_address(njit(sig, **no_refcount)(convention(njit(inline="always")(with_context), "measure")))
    # par: ekf_zupt's (σ_v, no zero rate, σ_ω, no bias bounds); idx: a 9-state filter
    arrays = (np.zeros(16), np.zeros(3), np.zeros(3), np.array([0, -1, 3, 6, -1], np.int64),
              np.array([1.0, 0.0, 0.05, 0.0, 0.0]), np.zeros(1),
              np.zeros((n, 1)), np.zeros(3), np.zeros((3, 9)), np.zeros(3))
    runs = {"positional": (loop_positional, fn_positional), "named tuples": (loop_named, fn_named),
            "convention": (loop_positional, fn_convention)}
    with quiet():  # numba warns that tuples of functions are experimental when it types them
        for loop, fn in runs.values():  # compile
            loop((fn,), 10, *arrays)
    best = dict.fromkeys(runs, np.inf)
    for _ in range(args.repeat):
        for name, (loop, fn) in runs.items():
            t0 = time.perf_counter()
            with quiet():
                loop((fn,), n, *arrays)
            best[name] = min(best[name], (time.perf_counter() - t0) / n * 1e9)
    for name, ns in best.items():
        print(f"{name:14s} {ns:6.1f} ns per call")


if __name__ == "__main__":
    main()
