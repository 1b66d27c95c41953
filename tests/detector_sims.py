"""Simulated walks shared by the detector tests: three speeds, four rates (cached per process)."""

from __future__ import annotations

from functools import cache

from footzoo.sim import NoiseModel, simulate

#: name: (stride length m, cycle s, stance fraction, clearance m) — 0.3, 1.38 and 4 m/s.
GAITS = {
    "slow_0.3": (0.5, 1.67, 0.65, 0.08),
    "walk_1.4": (1.38, 1.0, 0.60, 0.15),
    "run_4.0": (2.8, 0.70, 0.35, 0.30),
}
RATES = (50.0, 100.0, 200.0, 1000.0)


@cache
def walk(gait: str, rate: float):
    """A straight 8-stride physical walk with Table II-like sensor noise (magnetometer off)."""
    length, cycle, stance, clearance = GAITS[gait]
    return simulate(path="straight", n_strides=8, stride_length=length, cycle=cycle, stance_fraction=stance,
                    clearance=clearance, rate=rate, profile="physical", noise=NoiseModel(seed=0),
                    magnetometer=False, seed=0)
