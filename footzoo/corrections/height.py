"""Height updates of the error-state Kalman filter (Duong & Suh 2015, Sec. 4 and 5).

* ``height_distance``: two (or more) downward range sensors seeing a flat floor,
  with optional calibration states for their mounting (eqs. 1, 9–20): the 21-state
  filter, or the 9-state one with calibration off.
* ``height_flat_floor``: "zero velocity + height updating": at every stance
  sample the height is set back to its initial value.

Derivation of the distance measurement in footzoo's conventions (NED, errors
of the INS as estimate − truth, ``C_true = (I − [δφ×]) Ĉ``; calibration errors as
truth − estimate, as in the paper's eq. 1): the beam of sensor A ends on the
floor, ``p_z + [C (r_A + n_A d_A)]_z = z_floor`` (eq. 10). With
``u = Ĉ (r̂_A + n̂_A z_A)`` the residual ``z_floor − (p̂_z + u_z)`` is, to first order,

    e_zᵀ [u×] δφ − δp_z + e_zᵀ Ĉ r̄_A + z_A e_zᵀ Ĉ n̄_A − [Ĉ n̂_A]_z v_A

— eq. 13 with the paper's body-frame half-angle error ``q̄`` replaced by the NED
attitude error of footzoo's filter core (``δφ = −2 Ĉ q̄``), which is the same
linearisation in other coordinates. The floor height ``z_floor`` is measured
by the sensors during the initial still period (the paper puts the world
origin on the floor).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from ..core.atomic import write_text
from ..core.errors import ConfigError, RecordingError
from ..core.yamlsafe import load_file
from ..filters.measurement import (
    ATT,
    OWN,
    POS,
    MeasurementModel,
    P,
    Q,
    StateBlock,
    feedback_function,
    measurement_function,
)
from ..plugins.base import Boolean, File, KalmanCorrection, Real, Samples, Vectors
from ..plugins.registry import register

#: Duong & Suh Table 1 in their IMU frame (x toward the floor), mapped to FRD: (x, y, z)_DS -> (y, z, x).
TABLE1_POSITIONS = ((0.080, 0.0, -0.008), (-0.062, 0.0, -0.006))
TABLE1_DIRECTIONS = ((0.0, 0.0, 1.0), (0.0, 0.0, 1.0))
TABLE1_BASELINE = 0.142


def _vectors(name: str, value, count: int | None = None, nonzero: bool = False) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a list of [x, y, z] vectors (m), got {value!r}") from None
    if arr.ndim != 2 or arr.shape[1] != 3 or (count is not None and arr.shape[0] != count):
        raise ConfigError(f"{name} must be a list of {count or 'k'} [x, y, z] vectors, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ConfigError(f"{name} must hold finite numbers, got {arr.tolist()}")
    if nonzero and (np.linalg.norm(arr, axis=1) == 0).any():
        raise ConfigError(f"{name} must not contain [0, 0, 0]: a direction needs a non-zero vector, got {arr.tolist()}")
    return arr


#: Positions in the distance model's ``par``: σ of a range (m), calibrate on/off, σ of the constraints, the
#: baseline z_AB and its σ (m), the number of sensors k, the initial still period's length n_init, then its
#: readings (n_init × k, m) and their validity (n_init × k).
RANGE_STD, CALIBRATE, CONSTRAINT_STD, BASELINE, BASELINE_STD, N_SENSORS, N_INIT, INIT_READINGS = range(8)
#: In its ``mem``: the floor height (m), the floor is known, then the mounting r̂ (k × 3, m) and n̂ (k × 3).
FLOOR, FLOOR_KNOWN, MOUNTING = 0, 1, 2
#: In its ``data`` row: in the still start, then the k readings (m), then their validity.
IN_START, READINGS = 0, 1


@measurement_function
def distance_measure(ctx, rows):
    """Rows of eqs. 14–15 for each valid range reading, with eqs. 18 and 20 when calibrating.

    ``par``, ``mem`` and ``data``: see :data:`RANGE_STD`, :data:`FLOOR` and :data:`IN_START`;
    ``idx`` after the core: the offsets of r̄_j then n̄_j.
    """
    nav, idx, par, mem, data = ctx.nav, ctx.idx, ctx.par, ctx.mem, ctx.data
    z, H, R, m = rows
    ks = int(par[N_SENSORS])
    n_init = int(par[N_INIT])
    calibrate = par[CALIBRATE] != 0.0
    w_, x_, y_, z_ = nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3]
    # third row of C(q): the height component of a body vector in NED
    c0 = 2.0 * (x_ * z_ - w_ * y_)
    c1 = 2.0 * (y_ * z_ + w_ * x_)
    c2 = 1.0 - 2.0 * (x_ * x_ + y_ * y_)
    if mem[FLOOR_KNOWN] == 0.0:
        if data[IN_START] != 0.0:
            return m
        total = 0.0
        count = 0
        for j in range(ks):
            for s in range(n_init):
                if par[INIT_READINGS + n_init * ks + s * ks + j] != 0.0:
                    reading = par[INIT_READINGS + s * ks + j]
                    r = MOUNTING + 3 * j
                    nn = MOUNTING + 3 * ks + 3 * j
                    total += (c0 * (mem[r] + mem[nn] * reading) + c1 * (mem[r + 1] + mem[nn + 1] * reading)
                              + c2 * (mem[r + 2] + mem[nn + 2] * reading))
                    count += 1
        mem[FLOOR] = total / count
        mem[FLOOR_KNOWN] = 1.0
    # first two rows of C(q), for the attitude columns
    a00, a01, a02 = 1 - 2 * (y_ * y_ + z_ * z_), 2 * (x_ * y_ - w_ * z_), 2 * (x_ * z_ + w_ * y_)
    a10, a11, a12 = 2 * (x_ * y_ + w_ * z_), 1 - 2 * (x_ * x_ + z_ * z_), 2 * (y_ * z_ - w_ * x_)
    written = 0
    for j in range(ks):
        if data[READINGS + ks + j] == 0.0:
            continue
        reading = data[READINGS + j]
        r = MOUNTING + 3 * j
        nn = MOUNTING + 3 * ks + 3 * j
        b0 = mem[r] + mem[nn] * reading
        b1 = mem[r + 1] + mem[nn + 1] * reading
        b2 = mem[r + 2] + mem[nn + 2] * reading
        u0 = a00 * b0 + a01 * b1 + a02 * b2
        u1 = a10 * b0 + a11 * b1 + a12 * b2
        u2 = c0 * b0 + c1 * b1 + c2 * b2
        if idx[ATT] >= 0:  # e_zᵀ [u×] δφ
            H[m, idx[ATT]] = -u1
            H[m, idx[ATT] + 1] = u0
        H[m, idx[POS] + 2] = -1.0
        if calibrate:
            cr = idx[OWN + j]
            cn = idx[OWN + ks + j]
            H[m, cr], H[m, cr + 1], H[m, cr + 2] = c0, c1, c2
            H[m, cn], H[m, cn + 1], H[m, cn + 2] = reading * c0, reading * c1, reading * c2
        z[m] = mem[FLOOR] - (nav[P + 2] + u2)
        scale = c0 * mem[nn] + c1 * mem[nn + 1] + c2 * mem[nn + 2]
        R[m] = (scale * par[RANGE_STD]) ** 2
        m += 1
        written += 1
    if written > 0 and calibrate:
        for j in range(ks):  # eqs. 16-18: n̂ᵀ n̄ = 0
            cn = idx[OWN + ks + j]
            nn = MOUNTING + 3 * ks + 3 * j
            H[m, cn], H[m, cn + 1], H[m, cn + 2] = mem[nn], mem[nn + 1], mem[nn + 2]
            z[m] = 0.0
            R[m] = par[CONSTRAINT_STD] * par[CONSTRAINT_STD]
            m += 1
        a, b = MOUNTING, MOUNTING + 3  # eqs. 19-20: ‖r_A − r_B‖ = z_AB
        d0, d1, d2 = mem[a] - mem[b], mem[a + 1] - mem[b + 1], mem[a + 2] - mem[b + 2]
        norm = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        ca, cb = idx[OWN], idx[OWN + 1]
        H[m, ca], H[m, ca + 1], H[m, ca + 2] = d0 / norm, d1 / norm, d2 / norm
        H[m, cb], H[m, cb + 1], H[m, cb + 2] = -d0 / norm, -d1 / norm, -d2 / norm
        z[m] = par[BASELINE] - norm
        R[m] = par[BASELINE_STD] * par[BASELINE_STD]
        m += 1
    return m


@feedback_function
def distance_feedback(ctx, dx):
    """Add the calibration errors to the mounting estimates (eq. 1)."""
    idx, par, mem = ctx.idx, ctx.par, ctx.mem
    if par[CALIBRATE] == 0.0:
        return
    ks = int(par[N_SENSORS])
    for j in range(ks):
        cr = idx[OWN + j]
        cn = idx[OWN + ks + j]
        for i in range(3):
            mem[MOUNTING + 3 * j + i] += dx[cr + i]
            mem[MOUNTING + 3 * ks + 3 * j + i] += dx[cn + i]


@register
class HeightDistance(KalmanCorrection):
    """Height from downward distance sensors, with optional mounting calibration.

    Duong & Suh 2015, Sensors 15, eqs. 1, 9–20 and Table 1. Each valid range
    sample (finite, at most ``max_range``; the VL6180 reports 255 mm without a
    target) gives one measurement row (eqs. 13–15), at the sensor's own rate and
    in swing as well as stance. With ``calibrate`` the errors of each sensor's
    position and direction are states (12 more: the 21-state filter with the
    INS's 9), constrained by ``n̂ᵀ n̄ = 0`` (eqs. 16–18) and the measured baseline
    ``‖r_A − r_B‖ = z_AB`` (eqs. 19–20); the estimated mounting is kept in
    ``Result.diagnostics['distance_calibration']`` and can be saved with
    :func:`save_calibration` and loaded through ``calibration`` into the 9-state
    filter (the paper's eq. 24 workflow).

    Positions and directions are in footzoo's body frame (FRD); the defaults are
    Table 1 mapped from Duong & Suh's IMU frame (x toward the floor).

    Parameters
    ----------
    positions : list of [x, y, z]
        r̂ of each sensor (m, body frame).
    directions : list of [x, y, z]
        n̂ of each sensor (unit vectors, body frame).
    baseline : float
        z_AB, the measured distance between the first two sensors (m); Table 1: 0.142.
    range_std : float
        σ of v_A, v_B (m); Table 1: variance 0.0004.
    max_range : float
        Readings above it are rejected (m); VL6180: 0.2.
    calibrate : bool
        Estimate the mounting (21 states) or keep it fixed (9 states).
    position_std : float
        Initial σ of each sensor-position error component (m); Table 1: variance 1e-6.
    direction_std : float
        Initial σ of each direction error component (unitless, ≈ rad); Table 1: variance 1e-6.
        Set both as wide as the mounting may be off: with Table 1's 1 mm and
        0.001, a 4 mm or 3° error is 4σ or 50σ away and is barely corrected.
    constraint_std : float
        σ of v_constraint (eq. 18); Table 1: variance 1e-8.
    baseline_std : float
        σ of v_AB (eq. 20); Table 1: variance 1e-6.
    calibration : str, optional
        YAML file written by :func:`save_calibration`; replaces positions and directions.
    """

    name = "height_distance"
    needs_distance = True
    observes = ("floor_distance",)
    paper = "Duong & Suh 2015, Sensors 15, eqs. 1, 9-20, 24, Table 1"
    parameters = {
        "positions": Vectors(3, "m", "r̂ of each sensor in the body frame (FRD)", range="[-1, 1]",
                             source="Duong & Suh 2015, Table 1, mapped to FRD",
                             why="a sensor on the foot sits within 1 m of the IMU"),
        "directions": Vectors(3, "1", "n̂ of each sensor in the body frame (FRD)", nonzero=True,
                              source="Duong & Suh 2015, Table 1, mapped to FRD"),
        "baseline": Real("m", "(0, 1]", "z_AB: the measured distance between the first two sensors",
                         source="Duong & Suh 2015, Table 1", why="two sensors on one foot are less than 1 m apart"),
        "range_std": Real("m", "[1e-9, 1]", "σ of the range readings v_A, v_B",
                          source="Duong & Suh 2015, Table 1 (variance 0.0004)"),
        "max_range": Real("m", "(0, 10]", "readings above it are no floor (rejected)",
                          source="the VL6180's 0.2 m", why="beyond any range sensor used on a foot"),
        "calibrate": Boolean("estimate the sensors' mounting (21 states) rather than keep it fixed (9)",
                             source="Duong & Suh 2015, eqs. 16-20"),
        "position_std": Real("m", "[1e-9, 1]", "initial σ of each sensor-position error component",
                             source="Duong & Suh 2015, Table 1 (variance 1e-6)"),
        "direction_std": Real("1", "[1e-9, 1]", "initial σ of each direction error component (≈ rad)",
                              source="Duong & Suh 2015, Table 1 (variance 1e-6)"),
        "constraint_std": Real("1", "[1e-9, 1]", "σ of v_constraint (eq. 18)",
                               source="Duong & Suh 2015, Table 1 (variance 1e-8)"),
        "baseline_std": Real("m", "[1e-9, 1]", "σ of v_AB (eq. 20)",
                             source="Duong & Suh 2015, Table 1 (variance 1e-6)"),
        "calibration": File("YAML file of save_calibration; replaces positions and directions", optional=True,
                            source="none: use positions and directions"),
    }

    def __init__(
        self,
        positions: list | tuple = TABLE1_POSITIONS,
        directions: list | tuple = TABLE1_DIRECTIONS,
        baseline: float = TABLE1_BASELINE,
        range_std: float = 0.02,
        max_range: float = 0.2,
        calibrate: bool = True,
        position_std: float = 0.001,
        direction_std: float = 0.001,
        constraint_std: float = 1e-4,
        baseline_std: float = 0.001,
        calibration: str | None = None,
    ):
        self.positions = positions
        self.directions = directions
        self.calibration = calibration
        pos, dirs = positions, directions
        if calibration is not None:
            data = load_calibration(calibration)
            pos, dirs = data["positions"], data["directions"]
        self._r = _vectors("positions", pos)
        self._n = _vectors("directions", dirs, self._r.shape[0], nonzero=True)
        self._n = self._n / np.linalg.norm(self._n, axis=1, keepdims=True)
        self.baseline = baseline
        self.range_std = range_std
        self.max_range = max_range
        self.calibrate = calibrate
        self.position_std = position_std
        self.direction_std = direction_std
        self.constraint_std = constraint_std
        self.baseline_std = baseline_std

    @property
    def k(self) -> int:
        """Number of sensors."""
        return self._r.shape[0]

    def state_blocks(self) -> list[StateBlock]:
        """Calibration states r̄_j, n̄_j of each sensor (with ``calibrate``)."""
        if not self.calibrate:
            return []
        return ([StateBlock(f"cal_r{j}", 3, self.position_std**2) for j in range(self.k)]
                + [StateBlock(f"cal_n{j}", 3, self.direction_std**2) for j in range(self.k)])

    def _readings(self, dist: np.ndarray | None) -> np.ndarray:
        if dist is None or dist.ndim != 2 or dist.shape[1] < self.k:
            have = 0 if dist is None or dist.ndim != 2 else dist.shape[1]
            raise RecordingError(
                f"height_distance needs {self.k} distance-sensor columns (dist_a, dist_b, … in m); the recording has "
                f"{have}: load a recording with distance sensors or remove height_distance"
            )
        return np.asarray(dist[:, : self.k], dtype=float)

    def sample_data(self, samples: Samples) -> np.ndarray:
        """Per sample: in the still start (0/1), the k readings (m), their validity (0/1)."""
        d = self._readings(samples.dist)
        valid = np.isfinite(d) & (d <= self.max_range)
        return np.column_stack([np.asarray(samples.init_window, float), np.where(valid, d, 0.0),
                                valid.astype(float)])

    def model(self, samples: Samples) -> MeasurementModel:
        """Range rows; the floor height comes from the still start's readings (the sensor starts at height 0)."""
        d = self._readings(samples.dist)[np.asarray(samples.init_window, bool)]
        valid = np.isfinite(d) & (d <= self.max_range)
        if not valid.any():
            raise RecordingError(
                "height_distance: no valid range reading during the initial still period, so the floor height is "
                "unknown; check the distance columns' unit (m) and max_range"
            )
        n_init = d.shape[0]
        par = np.concatenate([[self.range_std, 1.0 if self.calibrate else 0.0, self.constraint_std, self.baseline,
                               self.baseline_std, self.k, n_init], np.where(valid, d, 0.0).ravel(),
                              valid.astype(float).ravel()])
        mem = np.concatenate([[0.0, 0.0], self._r.ravel(), self._n.ravel()])
        k = self.k
        return MeasurementModel(
            measure=distance_measure, feedback=distance_feedback, par=par, mem=mem,
            max_rows=k + (k + 1 if self.calibrate else 0),
            block_names=[b.name for b in self.state_blocks()],
            diagnostics=lambda mem: {"distance_calibration": {
                "positions": mem[MOUNTING:MOUNTING + 3 * k].reshape(k, 3).tolist(),
                "directions": mem[MOUNTING + 3 * k:MOUNTING + 6 * k].reshape(k, 3).tolist()}},
        )


def save_calibration(calibration: dict, path: str | Path) -> Path:
    """Write a distance-sensor calibration (``Result.diagnostics['distance_calibration']``) as YAML."""
    return write_text(path, yaml.safe_dump({"frame": "FRD body frame of the IMU", "units": "m",
                                            "positions": calibration["positions"],
                                            "directions": calibration["directions"]}),
                      what="distance-sensor calibration")


def load_calibration(path: str | Path) -> dict:
    """Read a calibration written by :func:`save_calibration`."""
    p = Path(path)
    data = load_file(p, ConfigError, "calibration file") or {}
    if not isinstance(data, dict):
        raise ConfigError(f"{p}: a calibration file is a mapping with positions and directions, got {data!r:.80}")
    missing = [k for k in ("positions", "directions") if k not in data]
    if missing:
        raise ConfigError(f"{p}: calibration file lacks {missing}")
    return data


#: Position in the flat-floor model's ``par``: σ of the height (m).
HEIGHT_STD = 0


@measurement_function
def flat_floor_measure(ctx, rows):
    """In stance: the height error ``p̂_z − 0`` (the pipeline starts at the origin); ``par`` = (σ m,)."""
    z, H, R, m = rows
    if not ctx.stance:
        return m
    H[m, ctx.idx[POS] + 2] = 1.0
    z[m] = ctx.nav[P + 2]
    R[m] = ctx.par[HEIGHT_STD] * ctx.par[HEIGHT_STD]
    return m + 1


@register
class HeightFlatFloor(KalmanCorrection):
    """Zero velocity + height updating: the foot is on a flat floor in every stance.

    Duong & Suh 2015, Sensors 15, Sec. 5 ("K.F. (zero velocity + height
    updating)"): during each zero-velocity interval the height is updated to
    its initial value — a measurement ``z = p̂_z − z_0`` of the position error's
    vertical component with a small noise ``height_std``.

    Parameters
    ----------
    height_std : float
        Measurement noise of the height (m).
    """

    name = "height_flat_floor"
    observes = ("height",)
    paper = "Duong & Suh 2015, Sensors 15, Sec. 5 (zero velocity + height updating)"
    parameters = {"height_std": Real("m", "[1e-9, 1]", "σ of the height measurement in stance",
                                     source="footzoo's (the paper gives no value)")}

    def __init__(self, height_std: float = 0.001):
        self.height_std = height_std

    def model(self, samples: Samples) -> MeasurementModel:
        """One height row in every stance sample."""
        return MeasurementModel(measure=flat_floor_measure, max_rows=1, par=np.array([self.height_std]))
