"""Level-stance height update: a stance that ends near the previous stance's height is on the same level.

Why
---
A zero-velocity update bounds the velocity error but not the height: each swing's strapdown leaves a
small vertical error (a tilt error of a few milliradians, an accelerometer bias, the sensor moving in
the stance the detector calls still), and the heights of successive stances random-walk away from the
floor. On PyShoe's VICON walks ``recommended`` ends up to 0.3 m off in height over 30 m, x-io's closed
walk ends 0.39 m high, and the simulator's 437 m track 1.2 m (``benchmarks/height_level.md``).

Duong & Suh 2015 (Sensors 15, Sec. 5, "zero velocity + height updating"; ``height_flat_floor``) set the
height back to its initial value in every stance: right on one flat floor, wrong on the first stair.
This update keeps their measurement and takes its reference from the stance before, with the gate of
Nguyen & La's heuristic heading reduction (2016, IEEE THMS 46(6), eq. 24: a change larger than a
threshold is real, a smaller one is drift) applied to the height instead of the heading:

    δh = p̂_d − h_{i−1},    used when |δh| ≤ th_h,    H = [0 0 1] on δp,    R = σ_h²

in every stance sample after the first stance, where ``h_{i−1}`` is the filter's height (NED ``p_d``, m)
at the last sample of the previous stance and ``p̂_d`` the current estimate. A stance within ``th_h`` of
the previous one is held on its level; a larger step (a stair) is taken as measured and starts a new
level. Like HDR's previous headings, ``h_{i−1}`` is the filter's own estimate, taken as exact.

The threshold
-------------
``th_h`` = 0.10 m: the lowest stair riser building codes allow (International Building Code 2021,
1011.5.2: risers 4–7 in, 102–178 mm), so a stride that climbs one riser or more
is never held, while the per-stride height error of a walk (1–3 cm on PyShoe's and x-io's walks) is. It
is a property of buildings, not of a recording: ``benchmarks/height_level.md`` shows 0.05–0.15 m side
by side under nested cross-validation.

Limits
------
* A slope that climbs less than ``th_h`` per stride is flattened: a 5 % ramp at 1.4 m strides (7 cm)
  is held level, a 1:12 ramp (8.3 %, 12 cm) is not. Hills and ramps: leave the update out, or see Park
  & Suh 2011 (Sensors 11(8), 8045–8059), who estimate the ground's inclination instead.
* A stride whose own height error exceeds ``th_h`` (a fast run's can) starts a new level at the wrong
  height, as a real step would; the levels after it are held there.
* The update observes the height only: the horizontal estimate changes only through the filter's
  correlations (PyShoe's 2-D error per trial: 0.6 mm at most, the median and worst of the 36 within 0.2 mm;
  ``benchmarks/height_level.md``).

Result diagnostics ``height_level``: ``stances_on_level`` (stances that ended within ``th_h`` of the
one before), ``level_changes`` (those that did not), and over the stances held the mean and the largest
magnitude of the height each swing landed at above its level, before the stance's updates
(``held_landing_mean_m``, ``held_landing_max_m``; m, up positive): the swings' own height error, which the
update removes with what creeps within the stances. Measured: within ±1 cm on the level walks of PyShoe,
x-io and Köroğlu, down to −4.5 cm on PyShoe's runs; a ramp walked up at 5 % with 1.4 m strides would give
+7 cm. A mean of several centimetres on a walk says the ground may slope: compare with a run without it.
"""

from __future__ import annotations

import numpy as np

from ..filters.measurement import (
    POS,
    MeasurementModel,
    P,
    after_function,
    gated_row,
    measurement_function,
    stance_ended,
)
from ..plugins.base import KalmanCorrection, Real, Samples
from ..plugins.registry import register

#: Positions in the model's ``par``: the threshold th_h (m) and σ_h (m).
THRESHOLD, HEIGHT_STD = 0, 1
#: Positions in its ``mem``: the previous sample was stance (0/1), its height p_d (m), stances ended, the height
#: h_{i−1} at the end of the previous stance (m), stances that ended on their level, level changes, the current
#: stance's landing height above h_{i−1} (m, up), its sum over the stances held and their largest magnitude (m).
WAS_STANCE, LAST_HEIGHT, ENDS_SEEN, LEVEL, ON_LEVEL, CHANGES, LANDING, HELD_SUM, HELD_MAX = range(9)


@measurement_function
def level_measure(ctx, rows):
    """In stance, once a stance has ended: ``δh = p̂_d − h_{i−1}`` when ``|δh| ≤ th_h`` (one row on δp_d)."""
    par, mem = ctx.par, ctx.mem
    if not ctx.stance or mem[ENDS_SEEN] < 1.0:
        return rows.m
    return gated_row(rows, ctx.idx[POS] + 2, ctx.nav[P + 2] - mem[LEVEL], par[THRESHOLD], par[HEIGHT_STD])


@after_function
def level_after(ctx):
    """At the first swing sample after a stance: that stance's final height becomes ``h_{i−1}`` (after the update)."""
    mem = ctx.mem
    if ctx.stance and mem[WAS_STANCE] == 0.0:  # the stance's first sample: where the swing landed, above the level
        mem[LANDING] = mem[LEVEL] - mem[LAST_HEIGHT]
    if stance_ended(ctx, WAS_STANCE):
        if mem[ENDS_SEEN] >= 1.0:
            if abs(mem[LAST_HEIGHT] - mem[LEVEL]) <= ctx.par[THRESHOLD]:
                mem[ON_LEVEL] += 1.0
                mem[HELD_SUM] += mem[LANDING]
                mem[HELD_MAX] = max(mem[HELD_MAX], abs(mem[LANDING]))
            else:
                mem[CHANGES] += 1.0
        mem[LEVEL] = mem[LAST_HEIGHT]
        mem[ENDS_SEEN] += 1.0
    mem[LAST_HEIGHT] = ctx.nav[P + 2]


def _diagnostics(mem: np.ndarray) -> dict:
    held = int(mem[ON_LEVEL])
    return {"height_level": {"stances_on_level": held, "level_changes": int(mem[CHANGES]),
                             "held_landing_mean_m": float(mem[HELD_SUM] / held) if held else float("nan"),
                             "held_landing_max_m": float(mem[HELD_MAX])}}


@register
class HeightLevel(KalmanCorrection):
    """Level-stance height update: a stance within ``threshold`` of the previous stance's height is on its level.

    Duong & Suh 2015, Sensors 15, Sec. 5 (the height measurement of "zero velocity + height updating"), with
    its reference the previous stance's final height and the gate of Nguyen & La 2016, IEEE THMS 46(6),
    eq. 24 (a larger change is real): the module's docstring gives the equations, the threshold's source and
    the limits (slopes gentler than ``threshold`` per stride are flattened).

    Parameters
    ----------
    threshold : float
        th_h (m): a stance whose height is within this of the previous stance's final height is held on that
        level; a larger step (a stair riser) is kept.
    height_std : float
        σ_h (m) of the height measurement in each stance sample.
    """

    name = "height_level"
    observes = ("height",)
    paper = ("Duong & Suh 2015, Sensors 15, Sec. 5 (height updating), with the gate of Nguyen & La 2016, "
             "IEEE THMS 46(6), eq. 24")
    parameters = {
        "threshold": Real("m", "(0, 1]", "a stance within this of the previous stance's height is on its level",
                          source="the lowest stair riser building codes allow (IBC 2021, 1011.5.2: 4 in)"),
        "height_std": Real("m", "[1e-6, 1]", "σ of the height measurement in a stance sample",
                           source="footzoo's (the order of a stance's real height change, 1 cm)"),
    }

    def __init__(self, threshold: float = 0.1, height_std: float = 0.01):
        self.threshold = threshold
        self.height_std = height_std

    def model(self, samples: Samples) -> MeasurementModel:
        """One height row in each stance sample within ``threshold`` of the previous stance's final height."""
        return MeasurementModel(measure=level_measure, after=level_after, max_rows=1,
                                par=np.array([self.threshold, self.height_std], dtype=float),
                                mem=np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]), diagnostics=_diagnostics)
