"""The named types the Kalman core passes around: parameters, state, workspace, outputs, smoother records.

Every one is a ``NamedTuple`` of arrays and numbers, which numba compiles as a tuple (an attribute
read costs what an index did) and which reads as what it holds. Arrays are float64 unless said
int (int64) or bool; ``N`` samples, ``n`` error states, ``L`` measurement models, ``R`` update rows.

What is where:

* inputs and parameters of the forward loop (:mod:`footzoo.filters.forward`): :class:`Offsets`,
  :class:`Core` (with :class:`~footzoo.filters.process_noise.Noise`), :class:`Signals`,
  :class:`FilterState`, :class:`Models` (:class:`ModelFunctions`, :class:`ModelArrays`),
  :class:`Workspace`, :class:`Fault`;
* its outputs: :class:`Trajectory` (what a smoother corrects) inside :class:`Outputs`;
* what a smoother keeps of the forward pass (:mod:`footzoo.filters.recorders`): :class:`Transitions`
  (Φ's blocks), :class:`UpdateRows`, :class:`Record` (a row per sample), :class:`SegmentRecord` (the
  step-wise smoother inside the loop), :class:`Checkpoints` and :class:`CheckpointRecord` (the RTS
  smoother in bounded memory).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .process_noise import Noise


class Offsets(NamedTuple):
    """Offsets of the INS core's error-state blocks in the error state (−1 where a block is absent)."""

    att: int
    gyro_bias: int
    pos: int
    vel: int
    acc_bias: int

    def array(self) -> np.ndarray:
        """The offsets as an int array (the first entries of a model's ``ctx.idx``)."""
        return np.array(self, dtype=np.int64)


class Core(NamedTuple):
    """The INS core's constants: its blocks, process noise and gravity, and how the attitude is obtained.

    ``use_ext``: the attitude comes from an orientation filter (``Signals.quat_ext``), not from the
    filter's own states; ``m_max``: most measurement rows of one sample (all models' ``max_rows``).
    """

    offsets: Offsets
    noise: Noise
    gravity: float
    use_ext: bool
    m_max: int


class Signals(NamedTuple):
    """The samples a chunk runs over; sample 0 is the one the incoming state belongs to.

    ``t`` (N,) s; ``acc`` (N, 3) specific force m/s²; ``gyr`` (N, 3) rad/s; ``stance`` (N,) bool;
    ``quat_ext`` (N or 1, 4): an orientation filter's attitude (body → NED, scalar first).
    """

    t: np.ndarray
    acc: np.ndarray
    gyr: np.ndarray
    stance: np.ndarray
    quat_ext: np.ndarray


class FilterState(NamedTuple):
    """The filter's state between chunks (updated in place): ``nav`` (16,) the nominal state (offsets
    Q, P, V, BG, BA of :mod:`footzoo.filters.measurement`), ``P`` (n, n), ``mems`` all models' memory."""

    nav: np.ndarray
    P: np.ndarray
    mems: np.ndarray


class ModelFunctions(NamedTuple):
    """The corrections' compiled functions in stacking order (tuples of first-class functions)."""

    measures: tuple
    feedbacks: tuple
    afters: tuple


class ModelArrays(NamedTuple):
    """The corrections' arrays, side by side: model ``j`` owns ``par[par_off[j]:par_off[j + 1]]`` etc.

    ``idx`` (L, w) int: each model's ``ctx.idx``; ``data`` (N, d): the models' per-sample inputs;
    ``has_feedback``, ``has_after`` (L,) bool: the model has that function (the loop skips the calls
    of the others); ``rows`` (L,) int: each model's ``max_rows``.
    """

    idx: np.ndarray
    par: np.ndarray
    par_off: np.ndarray
    mem_off: np.ndarray
    data: np.ndarray
    data_off: np.ndarray
    has_feedback: np.ndarray
    has_after: np.ndarray
    rows: np.ndarray


class Models(NamedTuple):
    """The corrections' measurement models as the compiled loop calls them."""

    functions: ModelFunctions
    arrays: ModelArrays


class Fault(NamedTuple):
    """A model that broke its contract in the loop (each (1,) int; ``model`` −1: none): which model, the
    row count it returned minus the first free row, the sample."""

    model: np.ndarray
    rows: np.ndarray
    sample: np.ndarray


class Workspace(NamedTuple):
    """The forward loop's buffers (any content on entry; :func:`footzoo.filters.recorders.workspace`).

    Handed to the models: ``z``, ``H``, ``R`` (m_max,), (m_max, n), (m_max,): the stacked
    measurement; ``dx`` (n,) the update's error; ``w``, ``f`` (3,) the bias-corrected rate and
    specific force. The loop's own: ``u``, ``gain``, ``g`` (n,) one row's update; ``nonzero``,
    ``moving``, ``still`` (n,) int: a row's nonzero columns, the rows of Φ − I that are not zero and
    the others; ``c``, ``c_dt``, ``skew_dt`` (3, 3): the mid-interval rotation, ``C dt`` and
    ``−[f^n×] dt``; ``a_n``, ``f_n`` (3,): motion acceleration and specific force in NED; ``fault``.
    """

    z: np.ndarray
    H: np.ndarray
    R: np.ndarray
    dx: np.ndarray
    w: np.ndarray
    f: np.ndarray
    u: np.ndarray
    gain: np.ndarray
    g: np.ndarray
    nonzero: np.ndarray
    moving: np.ndarray
    still: np.ndarray
    c: np.ndarray
    c_dt: np.ndarray
    skew_dt: np.ndarray
    a_n: np.ndarray
    f_n: np.ndarray
    fault: Fault


class Trajectory(NamedTuple):
    """Per-sample estimates a smoother corrects: ``quat`` (N, 4) body → NED, ``vel``, ``pos`` (N, 3) NED
    m/s and m, ``gyro_bias`` (N, 3) rad/s and ``acc_bias`` (N, 3) m/s² (body)."""

    quat: np.ndarray
    vel: np.ndarray
    pos: np.ndarray
    gyro_bias: np.ndarray
    acc_bias: np.ndarray


class Outputs(NamedTuple):
    """What the forward loop writes per sample (row 0: the incoming state).

    ``trajectory``; ``acc_nav`` (N, 3) the motion acceleration (m/s², NED); ``p_diag`` (N or 0, n) the
    covariance's diagonal, ``nis`` (N or 0,) each update's normalised innovation squared and ``nis_rows``
    (N or 0,) int its number of rows (not written with 0 rows). A bias without its error-state block
    stays zero.
    """

    trajectory: Trajectory
    acc_nav: np.ndarray
    p_diag: np.ndarray
    nis: np.ndarray
    nis_rows: np.ndarray


class Transitions(NamedTuple):
    """Φ_k = I + Δ_k per kept sample (Nguyen & La eq. 33): ``dt`` (M,) s, ``skew_dt`` (M, 3, 3)
    ``−[f^n×] dt`` (Δ[vel, att]), ``c_dt`` (M, 3, 3) ``C dt`` (Δ[vel, acc_bias], Δ[att, gyro_bias])."""

    dt: np.ndarray
    skew_dt: np.ndarray
    c_dt: np.ndarray


class UpdateRows(NamedTuple):
    """Scalar update rows, one after the other: ``h`` (R, n), its ``gain`` k = P hᵀ / s (R, n), ``scaled``
    ν / s (R,), and the innovation ``nu`` ν and its variance ``s`` (R,) (filterpy's ``y`` and ``S``)."""

    h: np.ndarray
    gain: np.ndarray
    scaled: np.ndarray
    nu: np.ndarray
    s: np.ndarray


class Record(NamedTuple):
    """What the RTS recursion reads of the forward pass, a row per sample: sample k in row ``k − offset[0]``.

    ``cov`` (M, n(n+1)/2): ``P⁺_k``, its upper triangle row by row; ``transitions``; ``rows``: the
    update rows; ``first``, ``count`` (M,) int: each sample's first row and number of rows;
    ``offset`` (1,) int.
    """

    cov: np.ndarray
    transitions: Transitions
    rows: UpdateRows
    first: np.ndarray
    count: np.ndarray
    offset: np.ndarray


class SegmentRecord(NamedTuple):
    """The step-wise smoother inside the loop over a whole recording: the open segment's ``record``
    (its first sample is ``record.offset[0]``), the ``smoothed`` trajectory the closed segments go to
    and the backward pass's ``work`` (3, n): λ, μ, e (the loop allocates nothing)."""

    record: Record
    smoothed: Trajectory
    work: np.ndarray


class Checkpoints(NamedTuple):
    """The filter's state where each piece of the RTS smoother in bounded memory starts (J pieces).

    ``nav`` (J, 16), ``P`` (J, n, n), ``mems`` (J, s); ``first`` (J,) int the piece's first sample,
    ``last_update`` (J,) int its last sample with an update so far (``first`` when none).
    """

    nav: np.ndarray
    P: np.ndarray
    mems: np.ndarray
    first: np.ndarray
    last_update: np.ndarray


class CheckpointRecord(NamedTuple):
    """The forward pass of the RTS smoother in bounded memory: no rows, a checkpoint where a piece starts.

    ``taken`` (1,) int: pieces started; ``block``: most samples per piece; ``min_gap``: fewest samples
    from a piece's start before a stance's start begins the next one
    (:func:`footzoo.filters.recorders.take_checkpoint`).
    """

    checkpoints: Checkpoints
    taken: np.ndarray
    block: int
    min_gap: int


class ForwardPass(NamedTuple):
    """What the closed-form smoothing of a swing reads of the forward pass: ``t`` (N,) s, ``quat`` (N, 4)
    its attitudes (before smoothing), ``acc_nav`` (N, 3) its motion accelerations (m/s², NED) and ``acc``
    (N, 3) the specific force as sampled (m/s², body)."""

    t: np.ndarray
    quat: np.ndarray
    acc_nav: np.ndarray
    acc: np.ndarray


class FreeSpanWork(NamedTuple):
    """Buffers of :func:`footzoo.filters.smoother.smooth_free_span` over at most M samples: ``mus`` (M, n),
    ``transitions`` (M rows), ``e``, ``mu`` (n,), ``c`` (3, 3)."""

    mus: np.ndarray
    transitions: Transitions
    e: np.ndarray
    mu: np.ndarray
    c: np.ndarray


class Pieces(NamedTuple):
    """The pieces of the RTS smoother in bounded memory (J,) int each: a piece's ``first`` sample, its last
    sample with an update ``last_update`` (``first`` if none) and its ``last`` sample (the next piece's first;
    the recording's last for the last piece)."""

    first: np.ndarray
    last_update: np.ndarray
    last: np.ndarray
