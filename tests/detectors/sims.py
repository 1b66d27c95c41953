"""Simulated walks shared by the detector tests: three speeds, four rates (cached per process)."""

from __future__ import annotations

from functools import cache

from footzoo.sim import NoiseModel, simulate

#: name: (stride length m, cycle s, stance fraction, clearance m, foot-flat share of stance) — 0.3, 1.38, 4 m/s.
#: The run: 0.28 s of contact with 0.09 s still (PyShoe's running trials: 0.10–0.15 s still).
GAITS = {
    "slow_0.3": (0.5, 1.67, 0.65, 0.08, 2 / 3),
    "walk_1.4": (1.38, 1.0, 0.60, 0.15, 2 / 3),
    "run_4.0": (2.8, 0.70, 0.40, 0.30, 1 / 3),
}
RATES = (50.0, 100.0, 200.0, 1000.0)


@cache
def walk(gait: str, rate: float):
    """A straight 8-stride physical walk with Table II-like sensor noise (magnetometer off)."""
    length, cycle, stance, clearance, flat = GAITS[gait]
    return simulate(path="straight", n_strides=8, stride_length=length, cycle=cycle, stance_fraction=stance,
                    clearance=clearance, flat_fraction=flat, rate=rate, profile="physical", noise=NoiseModel(seed=0),
                    magnetometer=False, seed=0)
