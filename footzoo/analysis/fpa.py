"""Heading vector and foot progression angle (Huang et al. 2016, Sec. II-D/E, eqs. 12–16)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from ..core.errors import ConfigError, FootzooWarning, user_stacklevel
from ..core.usage import fix
from ..evaluation.metrics import intervals, nearest_index
from ..kernels.jit import njit
from ..plugins.base import Analysis, Choice, File, Real, Vector
from ..plugins.registry import register
from .foot_side import infer_foot
from .foot_vector import FootVector
from .inputs import check_mask, check_samples, check_time

#: Largest angle (rad) between the heading vector and the line of progression for which an FPA is kept: 15°.
MAX_HEADING_OFFSET = math.radians(15.0)


#: Largest magnitude (rad) of the median FPA of a recording's straight strides read as the foot's: 35°. Human FPA
#: lies about −10° to +25° (toe-out positive); beyond 35° the sensor's x axis is turned on the foot.
MAX_PLAUSIBLE_FPA = math.radians(35.0)
#: Fewest straight strides for that judgement.
MIN_STRAIGHT_STRIDES = 5


def heading_offsets(pos: np.ndarray, heel_strikes: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """The heading vector's angle from the line of progression at each footprint (M,) (rad; NaN where undefined).

    The line of progression at footprint ``i`` is the horizontal direction from the previous footprint of
    the same foot to the next one, ``p_{i+1} − p_{i−1}`` (the last footprint: ``p_i − p_{i−1}``), with
    ``p_i`` the position at heel strike ``i``. Walking straight the two agree to a few degrees; on a turn
    the heading vector, built from the stride before the footprint and smoothed over the strides before
    it (eqs. 13–14), lags the walk by half the turn and more.

    Parameters
    ----------
    pos : (N, 3) ndarray
        Position in NED (m).
    heel_strikes : (M,) int ndarray
        Sample index of each heel strike.
    heading : (M,) ndarray
        Direction of the heading vector at each heel strike (rad, from north toward east).
    """
    p = pos[np.asarray(heel_strikes, dtype=np.int64), :2]
    m = len(p)
    out = np.full(m, np.nan)
    if m < 2:
        return out
    after = np.vstack([p[2:], p[-1:]])  # p_{i+1}, the last footprint's own
    chord = after - p[:-1]  # rows i = 1 .. m-1
    moved = np.hypot(chord[:, 0], chord[:, 1]) > 1e-3
    travel = np.arctan2(chord[:, 1], chord[:, 0])
    out[1:] = np.where(moved, (heading[1:] - travel + np.pi) % (2 * np.pi) - np.pi, np.nan)
    return out


def foot_fix() -> str:
    """How to declare the foot the sensor is on, where footzoo is used from (:mod:`footzoo.core.usage`)."""
    config = "or foot: right|left in the analysis config (every recording the config runs on)"
    return fix(python=f"footzoo.load(path, foot='right'|'left') (meta['foot']), {config}",
               command_line=f"--foot right|left, {config}",
               study="the recording entry's foot: key in the study (recordings: [{path: ..., foot: right}])")


@register
class HuangFPA(Analysis):
    """Foot progression angle per step from a foot vector and a filtered heading vector.

    Huang et al. 2016, IEEE TBME, Sec. II-C–E: the foot vector ``f`` fixed in
    the sensor frame is turned into the earth frame with the attitude (eq. 12);
    at each heel strike i the heading vector is ``h_i = α r_i + (1 − α) h_{i−1}``
    with ``r_i = p_i − p_{i−1}`` the displacement since the previous heel strike
    (eqs. 13–14, α = 0.35); the angle between ``f`` and ``h_i`` in the horizontal
    plane (eq. 15) is averaged over 20–80 % of the stance (eq. 16), the stance
    being 60 % of the stride time after the heel strike.

    Sign: positive is toe-out. For a right foot that is ``f`` turned clockwise
    seen from above (toward the walker's right) from ``h``; for a left foot,
    counter-clockwise: ``FPA = s · wrap(ψ_f − ψ_h)`` with ``s = +1`` (right) or
    ``−1`` (left). With ``foot: auto`` the side comes from the recording's
    metadata (``meta["foot"]``); a recording that does not name it is read all the
    same: the side is read from the walk (the swing arcs outward,
    :mod:`footzoo.analysis.foot_side`) and reported with its evidence in a warning, or,
    when the walk does not tell, every FPA is NaN with the reason (``steps.attrs["notes"]``,
    ``Result.metric_notes``) and the rest of the run (trajectory, strides) is unaffected.

    Parameters
    ----------
    alpha : float
        α of eq. 14; paper: 0.35.
    window : [float, float]
        Averaging window as fractions of the stance; paper: [0.2, 0.8].
    stance_fraction : float
        Stance as a fraction of the stride time; paper: 0.6.
    foot_vector : [x, y, z]
        Foot vector in the sensor frame (FRD); default the sensor's x axis.
    calibration : str, optional
        YAML file from ``footzoo calibrate`` (replaces ``foot_vector``).
    foot : {"auto", "right", "left"}
        Which foot the sensor is on.
    max_heading_offset : float
        Largest angle (rad) between the heading vector and the line of progression (the previous
        footprint to the next) for which the FPA is kept; beyond it the footprint is on a turn and its
        FPA is NaN (default 15°). The paper walked on a treadmill: "FPA is only valid clinically during
        straight line walking", and its heading vector, slow to follow a turn, gives "invalid FPA
        estimates" after one (Sec. IV). When most footprints of a recording are on turns, a warning
        says so.

    Attributes
    ----------
    fpa_ : (M,) ndarray
        FPA per stance after the first two heel strikes (rad; NaN before).
    heel_strikes_ : (M,) ndarray
        Sample index of each heel strike (stance onset).
    foot_ : {"right", "left"} or None
        The side used (None: unknown, the FPA is NaN).
    foot_source_ : {"config", "recording", "walk", "unknown"}
        Where the side came from.
    foot_evidence_ : dict or None
        What the walk said (:meth:`footzoo.analysis.foot_side.FootSide.as_dict`) when the side was read from it.
    heading_offset_ : (M,) ndarray
        Angle of the heading vector from the line of progression at each footprint
        (:func:`heading_offsets`, rad; NaN where undefined).
    turning_ : (M,) bool ndarray
        Footprints on a turn (``|heading_offset_| > max_heading_offset``): their FPA is NaN.
    note_ : str
        Why every FPA is NaN ("" when one is not).
    """

    name = "huang_fpa"
    paper = "Huang et al. 2016, IEEE TBME, Sec. II-C to II-E, eqs. 11-16"
    parameters = {
        "alpha": Real("1", "(0, 1]", "α: weight of the newest displacement in the heading vector (eq. 14)",
                      source="Huang et al. 2016, Sec. II-D"),
        "window": Vector(2, "1", "averaging window [start, end] as fractions of the stance (eq. 16)",
                         range="[0, 1]", source="Huang et al. 2016, Sec. II-E"),
        "stance_fraction": Real("1", "(0, 1]", "the stance as a fraction of the stride time",
                                source="Huang et al. 2016, Sec. II-E"),
        "foot_vector": Vector(3, "1", "the foot vector f in the sensor frame (FRD)", nonzero=True,
                              source="footzoo's: the sensor's x axis (calibrate for the real one)"),
        "calibration": File("YAML file of footzoo calibrate (replaces foot_vector)", optional=True,
                            source="none: use foot_vector"),
        "foot": Choice(("auto", "right", "left"), "which foot the sensor is on (auto: the recording's meta['foot'])",
                       source="footzoo's: from the recording"),
        "max_heading_offset": Real("rad", "(0, pi]", "largest angle between the heading vector (eq. 14) and the "
                                   "line of progression at a footprint for which the FPA is kept (a turn: NaN)",
                                   source="footzoo's: measured on the visible recordings (docs/gait.md)"),
    }

    def __init__(
        self,
        alpha: float = 0.35,
        window: list[float] | tuple[float, float] = (0.2, 0.8),
        stance_fraction: float = 0.6,
        foot_vector: list[float] | tuple[float, float, float] = (1.0, 0.0, 0.0),
        calibration: str | None = None,
        foot: str = "auto",
        max_heading_offset: float = MAX_HEADING_OFFSET,
    ):
        if not window[0] < window[1]:
            raise ConfigError(f"window must be [start, end] fractions of the stance with start < end, got {window}")
        if calibration is not None:
            FootVector.load(calibration)  # fail early on a bad file
        self.alpha = alpha
        self.window = window
        self.stance_fraction = stance_fraction
        self.foot_vector = foot_vector
        self.calibration = calibration
        self.foot = foot
        self.max_heading_offset = max_heading_offset

    def _declared(self, meta: dict) -> tuple[str | None, str]:
        """The side the config or the recording names, and which one named it."""
        if self.foot != "auto":
            return self.foot, "config"
        foot = meta.get("foot")
        if foot is not None and foot not in ("right", "left"):
            raise ConfigError(f"huang_fpa: the recording says the sensor is on the foot {foot!r}; it must be 'left' or "
                              f"'right': {foot_fix()}")
        return foot, "recording"

    def check(self, meta: dict) -> None:
        """A side the recording names must be left or right; one that names none is read from the walk."""
        self._declared(meta)

    def analyze(self, t: np.ndarray, quat: np.ndarray, pos: np.ndarray, stance: np.ndarray,
                meta: dict) -> HuangFPA:
        """FPA per stance (eqs. 12–16)."""
        fn = "HuangFPA.analyze"
        t = check_time(fn, t)
        stance = check_mask(fn, "stance", stance, len(t))
        quat = check_samples(fn, "quat", quat, len(t), (4,), "(attitude quaternions, scalar first)")
        pos = check_samples(fn, "pos", pos, len(t), (3,), "(position in NED, m)")
        foot, self.foot_source_ = self._declared(meta)
        self.foot_evidence_, self.note_ = None, ""
        self.heel_strikes_ = intervals(stance)[:, 0]
        if foot is None:
            foot = self._side_from_walk(pos, stance, str(meta.get("name", "recording")))
        self.foot_ = foot
        if foot is None:
            self.fpa_ = np.full(len(self.heel_strikes_), np.nan)
            return self
        f_s = FootVector.load(self.calibration).vector if self.calibration else np.asarray(self.foot_vector, float)
        f_s = f_s / np.linalg.norm(f_s)
        fpa, heading = _fpa_kernel(np.ascontiguousarray(t, dtype=float), np.ascontiguousarray(quat, dtype=float),
                                   np.ascontiguousarray(pos, dtype=float), self.heel_strikes_.astype(np.int64),
                                   f_s, float(self.alpha), self.window[0], self.window[1], float(self.stance_fraction),
                                   1.0 if foot == "right" else -1.0)
        self.heading_offset_ = heading_offsets(np.asarray(pos, dtype=float), self.heel_strikes_, heading)
        self.turning_ = np.abs(self.heading_offset_) > self.max_heading_offset  # NaN compares False
        self.fpa_ = np.where(self.turning_, np.nan, fpa)
        name = str(meta.get("name", "recording"))
        if not self._say_turning(np.isfinite(fpa), name):  # a walk of turns says nothing of the mounting
            self._say_implausible(name)
        return self

    def _side_from_walk(self, pos: np.ndarray, stance: np.ndarray, name: str) -> str | None:
        """The side read from the walk (:func:`footzoo.analysis.foot_side.infer_foot`), with a warning either way."""
        found = infer_foot(pos, stance)
        self.foot_evidence_ = found.as_dict()
        declare = "declare the foot: " + foot_fix()
        if found.side is None:
            self.foot_source_ = "unknown"
            self.note_ = (f"the foot side is unknown (the recording does not name it, and {found.reason}); the foot "
                          "progression angle's sign depends on it")
            warnings.warn(FootzooWarning(f"huang_fpa: recording {name!r}: {self.note_}: every FPA is NaN, the rest "
                                         f"of the run is unaffected; {declare}"), stacklevel=user_stacklevel())
            return None
        self.foot_source_ = "walk"
        warnings.warn(FootzooWarning(
            f"huang_fpa: recording {name!r} does not say which foot the sensor is on; read as the {found.side} foot "
            f"from the walk: {found.reason}. To be sure, {declare}"), stacklevel=user_stacklevel())
        return found.side

    def _say_turning(self, had: np.ndarray, name: str) -> bool:
        """Warn when most FPAs are dropped for a turn (and say so: True), and say why the column is NaN when every
        one is."""
        turned = int(np.count_nonzero(self.turning_ & had))
        total = int(np.count_nonzero(had))
        if total == 0 or 2 * turned <= total:
            return False
        offsets = np.degrees(np.abs(self.heading_offset_[self.turning_ & had]))
        why = (f"the walk turns at {turned} of {total} footprints (the heading vector, eq. 14, is "
               f"{np.median(offsets):.0f}° (median) from the line of progression there, more than "
               f"{math.degrees(self.max_heading_offset):.0f}°): the FPA is defined on straight walking (Huang et al. "
               "2016, Sec. IV), on a turn it measures the turn, not the foot")
        if turned == total:
            self.note_ = why
        warnings.warn(FootzooWarning(
            f"huang_fpa: recording {name!r}: {why}; those FPAs are NaN, the rest of the run is unaffected. For a "
            "foot progression angle, record straight walking (a walkway or a treadmill, turns apart)"),
            stacklevel=user_stacklevel())
        return True

    def _say_implausible(self, name: str) -> None:
        """Warn when the straight strides' median FPA is beyond :data:`MAX_PLAUSIBLE_FPA`: it measures the sensor."""
        kept = self.fpa_[np.isfinite(self.fpa_)]
        if len(kept) < MIN_STRAIGHT_STRIDES or abs(np.median(kept)) <= MAX_PLAUSIBLE_FPA:
            return
        angle = math.degrees(float(np.median(kept)))
        vector = ("the calibrated foot vector" if self.calibration
                  else f"the foot vector {list(self.foot_vector)} (sensor axes)")
        warnings.warn(FootzooWarning(
            f"huang_fpa: recording {name!r}: the foot progression angle is {angle:+.0f}° (median of {len(kept)} "
            f"straight strides), far outside a human's (about −10° to +25°, toe-out positive): it is the angle of "
            f"{vector} from the line of progression, and that axis is not along the foot. The FPA measures the "
            "sensor, not the foot: mount the sensor with its x axis along the foot, or give the foot's long axis "
            "in sensor axes: calibrate it (footzoo calibrate --data CALIBRATION_RECORDING --out foot.yaml, then "
            "calibration: foot.yaml in the analysis config) or set foot_vector"), stacklevel=user_stacklevel())

    def annotate(self, steps: pd.DataFrame, t: np.ndarray) -> pd.DataFrame:
        """Add ``fpa_rad`` to the step table: the FPA of the stance that ends each stride.

        That stance is the one whose onset is nearest to the stride's initial
        contact ``end_s`` (the detector's onset follows the contact by a fraction
        of the stance; the other onsets are a stride away).
        """
        out = steps.copy()
        if self.note_:  # why the column is NaN, for the metrics (Result.metric_notes) and a saved result
            out.attrs["notes"] = {**out.attrs.get("notes", {}), "fpa_rad": self.note_}
        onsets = t[self.heel_strikes_]
        if len(onsets) == 0:
            out["fpa_rad"] = np.nan
            return out
        out["fpa_rad"] = self.fpa_[nearest_index(onsets, out["end_s"].to_numpy(dtype=float))]
        return out


@njit
def _fpa_kernel(t: np.ndarray, quat: np.ndarray, pos: np.ndarray, hs: np.ndarray, f_s: np.ndarray, alpha: float,
                w0: float, w1: float, stance_fraction: float, side: float) -> tuple[np.ndarray, np.ndarray]:
    """Eqs. 12–16 for every heel strike ``hs[i]`` (sample indices): the FPA and the heading vector's
    direction ``ψ_h`` (rad, from north toward east); NaN where undefined."""
    m = hs.shape[0]
    fpa = np.empty(m)
    fpa[:] = np.nan
    heading = np.empty(m)
    heading[:] = np.nan
    hx, hy = 0.0, 0.0
    for i in range(1, m):
        rx = pos[hs[i], 0] - pos[hs[i - 1], 0]  # eq. 13
        ry = pos[hs[i], 1] - pos[hs[i - 1], 1]
        if i == 1:
            hx, hy = rx, ry
        else:  # eq. 14
            hx, hy = alpha * rx + (1 - alpha) * hx, alpha * ry + (1 - alpha) * hy
        if hx == 0.0 and hy == 0.0:
            continue
        heading[i] = math.atan2(hy, hx)
        stride = t[hs[i + 1]] - t[hs[i]] if i + 1 < m else t[hs[i]] - t[hs[i - 1]]
        stance_time = stance_fraction * stride
        lo = _bisect(t, t[hs[i]] + w0 * stance_time, False)
        hi = _bisect(t, t[hs[i]] + w1 * stance_time, True)
        if hi <= lo:
            continue
        psi_h = heading[i]
        total = 0.0
        for k in range(lo, hi):
            w, x, y, z = quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3]
            # eq. 12: the first two rows of R(q) applied to f_s
            fx = (1 - 2 * (y * y + z * z)) * f_s[0] + 2 * (x * y - w * z) * f_s[1] + 2 * (x * z + w * y) * f_s[2]
            fy = 2 * (x * y + w * z) * f_s[0] + (1 - 2 * (x * x + z * z)) * f_s[1] + 2 * (y * z - w * x) * f_s[2]
            d = math.atan2(fy, fx) - psi_h
            total += side * -((-d + math.pi) % (2 * math.pi) - math.pi)  # eq. 15, wrapped to (-π, π]
        fpa[i] = total / (hi - lo)  # eq. 16
    return fpa, heading


@njit(inline=True)  # inlined: no compilation per constant value of right
def _bisect(t: np.ndarray, v: float, right: bool) -> int:
    """``np.searchsorted(t, v, side="right" if right else "left")`` for sorted ``t`` (cheaper to compile)."""
    lo, hi = 0, t.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if t[mid] < v or (right and t[mid] == v):
            lo = mid + 1
        else:
            hi = mid
    return lo
