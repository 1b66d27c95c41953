"""Stillness hold: the zero-displacement rows the stance updates add once the foot has stood long enough.

Why a foot that stands still creeps under zero-velocity updates alone
--------------------------------------------------------------------
The strapdown integrates the position with the trapezoidal rule,
``p_k = p_{k−1} + (v_{k−1} + v_k)/2 · dt``, so the velocity error ``a·dt`` that an unmodelled
acceleration ``a`` (an accelerometer bias, a tilt error times g) builds up within one sample moves
the position by ``a·dt²/2`` before the update sees it. The filter's error model has
``δp_k = δp_{k−1} + δv_{k−1}·dt`` and no position–velocity cross term in its process noise, so no
zero-velocity update attributes that half step to anything: whatever the update's gain, the
position creeps at ``a·dt/2``. At 100 Hz that is 0.15 m in 10 minutes for Yun et al.'s 0.049 m/s²
bias; a tighter zero-velocity noise changes nothing (measured with σ_v = 0.03, 0.001 and 1e-5 m/s:
the same 0.147 m). After a walk the filter's position is also correlated with its attitude and
velocity errors, and every innovation of a long stand moves it further.

The hold
--------
A foot that stands does not move. Once it has been still — detected stance and
``|ω̂| < hold_rate`` — for ``hold_after`` seconds without a break, every further still sample
measures the position against ``p_0``, the estimate at the first sample of that still run
(``z = p̂ − p_0``, ``H`` picking ``δp``, σ ``hold_std``; the drift of the first ``hold_after``
seconds is taken back too). Any sample that is not still ends the run; the next run has its own
``p_0``. ``hold_after`` is longer than the stances of walking and running, so the hold acts where a
person stands: at the start and end of a recording and in pauses (``docs/building-blocks.md``
gives the measured stance durations and what the hold changes on the validation recordings).

``p_0`` is the filter's own estimate, taken as exact: the rows hold the foot where the forward
filter put it, which is what a live user sees, but they give an RTS smoother that absolute
position too, so the smoothed walk before a stand can no longer move the stand (measured in
``docs/building-blocks.md``: no change on the real recordings, worse only where the filter misses a
large error model, a 0.2 °/s gyroscope bias it does not estimate). A hold relative to the state at
the start of the still run (a stochastic clone of the position) would avoid that; the engine has
no hook for it yet.

A correction keeps the three constants of :data:`HOLD_PAR` in its ``par`` and the six entries of
:data:`HOLD_MEM` in its ``mem`` at offsets it chooses, writes the rows with :func:`hold_measure`
(up to three) and follows the still run with :func:`hold_track` in its ``after``.
"""

from __future__ import annotations

from ..filters.measurement import POS, P
from ..kernels.jit import njit
from ..plugins.base import Real

#: The hold's constants, in this order from a model's ``par`` offset: hold_after (s; 0: no hold),
#: hold_std (m), hold_rate (rad/s).
HOLD_AFTER, HOLD_STD, HOLD_RATE = 0, 1, 2
HOLD_PAR = 3
#: Its memory, in this order from a model's ``mem`` offset: in a still run (0/1), the run's first time (s),
#: holding (0/1), the run's first position p_0 (3, m).
STILL, SINCE, HOLDING, ANCHOR = 0, 1, 2, 3
HOLD_MEM = 6
#: Most rows :func:`hold_measure` writes at one sample.
HOLD_ROWS = 3

#: Declarations of the hold's parameters, shared by the stance updates that offer it.
HOLD_PARAMETERS = {
    "hold_after": Real("s", "[0, 3600]", "still this long, the foot's position is held; 0: no hold",
                       source="footzoo's: longer than the stances of walking and running on the validation "
                              "recordings (docs/building-blocks.md, 'Stillness hold')",
                       why="an hour of stillness before the hold acts is no hold"),
    "hold_std": Real("m", "[1e-6, 1]", "σ of the zero-displacement rows while the foot is held",
                     source="footzoo's: 1 mm, a foot standing on a floor"),
    "hold_rate": Real("rad/s", "(0, 10]", "largest |ω| of a still sample (stance and slower than this)",
                      source="footzoo's: 0.2 rad/s, the stillness of the physics checks (footzoo.core.sanity)",
                      why="a foot turning at 10 rad/s (573 °/s) is not still"),
}
#: The defaults of :data:`HOLD_PARAMETERS`.
HOLD_DEFAULTS = {"hold_after": 2.0, "hold_std": 0.001, "hold_rate": 0.2}


def hold_constants(hold_after: float, hold_std: float, hold_rate: float) -> list[float]:
    """The hold's entries of a model's ``par``, in :data:`HOLD_PAR` order."""
    return [float(hold_after), float(hold_std), float(hold_rate)]


@njit(inline=True)
def is_still(stance, w, rate):
    """A still sample: detected stance and ``|ω̂| < rate`` (rad/s)."""
    return stance and w[0] * w[0] + w[1] * w[1] + w[2] * w[2] < rate * rate


@njit(inline=True)
def hold_measure(stance, w, nav, idx, par, a, mem, b, z, H, R, m):
    """Write the three zero-displacement rows ``δp = p̂ − p_0`` from row ``m`` while the foot is held.

    ``par[a:]`` holds the constants and ``mem[b:]`` the memory (:data:`HOLD_PAR`, :data:`HOLD_MEM`);
    returns the next free row (``m`` when the foot is not held).
    """
    if mem[b + HOLDING] == 0.0 or not is_still(stance, w, par[a + HOLD_RATE]):
        return m
    pos = idx[POS]
    r = par[a + HOLD_STD] * par[a + HOLD_STD]
    for i in range(3):
        H[m, pos + i] = 1.0
        z[m] = nav[P + i] - mem[b + ANCHOR + i]
        R[m] = r
        m += 1
    return m


@njit(inline=True)
def hold_track(t, stance, w, nav, par, a, mem, b):
    """After the update of the sample at time ``t`` (s): follow the still run, keep its p_0, start the hold."""
    if par[a + HOLD_AFTER] <= 0.0 or not is_still(stance, w, par[a + HOLD_RATE]):
        mem[b + STILL] = 0.0
        mem[b + HOLDING] = 0.0
        return
    if mem[b + STILL] == 0.0:
        mem[b + STILL] = 1.0
        mem[b + SINCE] = t
        for i in range(3):
            mem[b + ANCHOR + i] = nav[P + i]
    if t - mem[b + SINCE] >= par[a + HOLD_AFTER]:
        mem[b + HOLDING] = 1.0
