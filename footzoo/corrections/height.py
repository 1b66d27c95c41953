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

from pathlib import Path

import numpy as np
import yaml

from ..checks import check_bool, check_range
from ..errors import ConfigError, RecordingError
from ..filters.eskf import Layout, skew
from ..filters.navigation import NavState
from ..registry import Plugin, register
from ..yamlsafe import load_file

#: Duong & Suh Table 1 in their IMU frame (x toward the floor), mapped to FRD: (x, y, z)_DS -> (y, z, x).
TABLE1_POSITIONS = [[0.080, 0.0, -0.008], [-0.062, 0.0, -0.006]]
TABLE1_DIRECTIONS = [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
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


@register
class HeightDistance(Plugin):
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

    kind = "correction"
    name = "height_distance"
    role = "kalman"
    needs_recording = True
    paper = "Duong & Suh 2015, Sensors 15, eqs. 1, 9-20, 24, Table 1"
    units = {"positions": "m", "directions": "1", "baseline": "m", "range_std": "m", "max_range": "m",
             "position_std": "m", "direction_std": "1", "constraint_std": "1", "baseline_std": "m"}

    def __init__(
        self,
        positions: list | None = None,
        directions: list | None = None,
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
        self.positions = positions if positions is not None else TABLE1_POSITIONS
        self.directions = directions if directions is not None else TABLE1_DIRECTIONS
        self.calibration = calibration
        pos, dirs = self.positions, self.directions
        if calibration is not None:
            data = load_calibration(calibration)
            pos, dirs = data["positions"], data["directions"]
        self._r = _vectors("positions", pos)
        self._n = _vectors("directions", dirs, self._r.shape[0], nonzero=True)
        self._n = self._n / np.linalg.norm(self._n, axis=1, keepdims=True)
        self.baseline = check_range("baseline", baseline, 0.0, 1.0, "m", lo_open=True)
        self.range_std = check_range("range_std", range_std, 1e-9, 1.0, "m")
        self.max_range = check_range("max_range", max_range, 0.0, 10.0, "m", lo_open=True)
        self.calibrate = check_bool("calibrate", calibrate)
        self.position_std = check_range("position_std", position_std, 1e-9, 1.0, "m")
        self.direction_std = check_range("direction_std", direction_std, 1e-9, 1.0, "1")
        self.constraint_std = check_range("constraint_std", constraint_std, 1e-9, 1.0, "1")
        self.baseline_std = check_range("baseline_std", baseline_std, 1e-9, 1.0, "m")

    @property
    def k(self) -> int:
        """Number of sensors."""
        return self._r.shape[0]

    def blocks(self) -> list[tuple[str, int, float, float]]:
        """Calibration states r̄_j, n̄_j of each sensor (with ``calibrate``)."""
        if not self.calibrate:
            return []
        return ([(f"cal_r{j}", 3, self.position_std**2, 0.0) for j in range(self.k)]
                + [(f"cal_n{j}", 3, self.direction_std**2, 0.0) for j in range(self.k)])

    def bind(self, dist: np.ndarray | None, t: np.ndarray, init_window: np.ndarray) -> None:
        """Attach the recording's range columns (m, NaN between samples)."""
        if dist is None or dist.shape[1] < self.k:
            have = 0 if dist is None else dist.shape[1]
            raise RecordingError(
                f"height_distance needs {self.k} distance-sensor columns (dist_a, dist_b, … in m); the recording has "
                f"{have}: load a recording with distance sensors or remove height_distance"
            )
        self._dist = dist[:, : self.k]
        valid = np.isfinite(self._dist) & (self._dist <= self.max_range)
        self._valid = valid
        self._init_window = init_window
        if not np.any(valid[init_window]):
            raise RecordingError(
                "height_distance: no valid range reading during the initial still period, so the floor height is "
                "unknown; check the distance columns' unit (m) and max_range"
            )

    def begin(self, n: int, layout: Layout) -> None:
        """Reset the floor height (set from the first still samples)."""
        self._layout = layout
        self._floor: float | None = None

    def _row(self, nav: NavState, j: int, reading: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        from ..conventions import quat_to_matrix

        c = quat_to_matrix(nav.q)
        layout = self._layout
        u = c @ (self._r[j] + self._n[j] * reading)
        h = np.zeros((1, layout.n))
        if layout.has("att"):
            h[0, layout["att"]] = skew(u)[2]
        h[0, layout["pos"].start + 2] = -1.0
        if self.calibrate:
            h[0, layout[f"cal_r{j}"]] = c[2]
            h[0, layout[f"cal_n{j}"]] = reading * c[2]
        z = np.array([self._floor - (nav.p[2] + u[2])])
        scale = (c @ self._n[j])[2]
        return z, h, np.array([[(scale * self.range_std) ** 2]])

    def measure(self, nav: NavState) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Rows of eqs. 14–15 for each valid reading, with eqs. 18 and 20 when calibrating."""
        k = nav.k
        if self._floor is None:
            if not self._init_window[k]:
                self._floor = self._estimate_floor(nav)
            else:
                return []
        rows = [self._row(nav, j, float(self._dist[k, j])) for j in range(self.k) if self._valid[k, j]]
        if rows and self.calibrate:
            rows += self._constraints()
        return rows

    def _estimate_floor(self, nav: NavState) -> float:
        """Floor height from the initial still period: mean of [Ĉ(r̂ + n̂ z)]_z (the sensor starts at height 0)."""
        from ..conventions import quat_to_matrix

        c = quat_to_matrix(nav.q)
        heights = []
        w = self._init_window
        for j in range(self.k):
            z = self._dist[w & self._valid[:, j], j]
            heights += list((c @ (self._r[j][:, None] + np.outer(self._n[j], z)))[2])
        return float(np.mean(heights))

    def _constraints(self) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        layout = self._layout
        rows = []
        for j in range(self.k):  # eqs. 16-18: n̂ᵀ n̄ = 0
            h = np.zeros((1, layout.n))
            h[0, layout[f"cal_n{j}"]] = self._n[j]
            rows.append((np.zeros(1), h, np.array([[self.constraint_std**2]])))
        d = self._r[0] - self._r[1]  # eqs. 19-20: ‖r_A − r_B‖ = z_AB
        norm = float(np.linalg.norm(d))
        h = np.zeros((1, layout.n))
        h[0, layout["cal_r0"]] = d / norm
        h[0, layout["cal_r1"]] = -d / norm
        rows.append((np.array([self.baseline - norm]), h, np.array([[self.baseline_std**2]])))
        return rows

    def feedback(self, dx: np.ndarray, layout: Layout) -> None:
        """Add the calibration errors to the mounting estimates (eq. 1)."""
        if not self.calibrate:
            return
        for j in range(self.k):
            self._r[j] = self._r[j] + dx[layout[f"cal_r{j}"]]
            self._n[j] = self._n[j] + dx[layout[f"cal_n{j}"]]

    def after(self, nav: NavState) -> None:
        """Nothing to remember."""

    def calibration_result(self) -> dict[str, list[list[float]]]:
        """The current mounting estimate (body frame, FRD)."""
        return {"positions": self._r.tolist(), "directions": self._n.tolist()}


def save_calibration(calibration: dict, path: str | Path) -> Path:
    """Write a distance-sensor calibration (``Result.diagnostics['distance_calibration']``) as YAML."""
    p = Path(path)
    p.write_text(yaml.safe_dump({"frame": "FRD body frame of the IMU", "units": "m",
                                 "positions": calibration["positions"], "directions": calibration["directions"]}))
    return p


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


@register
class HeightFlatFloor(Plugin):
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

    kind = "correction"
    name = "height_flat_floor"
    role = "kalman"
    paper = "Duong & Suh 2015, Sensors 15, Sec. 5 (zero velocity + height updating)"
    units = {"height_std": "m"}

    def __init__(self, height_std: float = 0.001):
        self.height_std = check_range("height_std", height_std, 1e-9, 1.0, "m")

    def blocks(self) -> list[tuple[str, int, float, float]]:
        """No extra states."""
        return []

    def begin(self, n: int, layout: Layout) -> None:
        """Build the measurement row (the initial height is 0: the pipeline starts at the origin)."""
        self._h = np.zeros((1, layout.n))
        self._h[0, layout["pos"].start + 2] = 1.0
        self._r = np.array([[self.height_std**2]])

    def measure(self, nav: NavState) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """In stance: the height error ``p̂_z − 0``."""
        return [(np.array([nav.p[2]]), self._h, self._r)] if nav.stance else []

    def after(self, nav: NavState) -> None:
        """Nothing to remember."""
