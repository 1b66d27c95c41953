"""IMU sampling, the noise model (Yun et al. 2012, eq. 18, Table II), magnetometer and distance sensors.

Sampling
--------
``"interval"`` (default): each sample is what an IMU reporting delta-angles and
delta-velocities delivers for the interval ``(t[k-1], t[k]]``:

* gyro ``ω_k = log(q_{k-1}* ⊗ q_k) / dt`` — the constant body rate that carries
  the attitude exactly from one sample to the next (coning-compensated);
* accelerometer ``f_k = C(q̄_k)^T ((v_k − v_{k-1}) / dt − g^n)`` — the interval's
  velocity change minus gravity, resolved in the mid-interval attitude
  ``q̄_k = normalise(q_{k-1} + q_k)`` (sculling-compensated).

With these definitions footzoo's strapdown (:mod:`footzoo.filters.strapdown`)
reproduces the true attitude and velocity exactly and the position to the
trapezoidal rule's error, which vanishes over a stride whose acceleration starts
and ends at zero.

``"instantaneous"``: the true body rate and specific force at ``t[k]``. Strapdown
integration then makes errors of order ``dt²`` per sample (rectangle rule on
a changing rate), which is how a sensor without delta outputs behaves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.conventions import GRAVITY, gravity_ned, quat_conj, quat_mul, quat_normalize, quat_rotate
from ..core.errors import ConfigError

#: Named magnetic field locations: total intensity (Gauss) and inclination (deg, down positive).
MAGNETIC_FIELDS = {
    "monterey": (0.48, 61.0),  # Naval Postgraduate School, Monterey CA (Yun et al.), NOAA WMM approx.
    "seoul": (0.50, 53.5),  # Duong & Suh
    "reno": (0.51, 64.0),  # Nguyen & La
}


def quat_log_rate(q0: np.ndarray, q1: np.ndarray, dt: np.ndarray) -> np.ndarray:
    """Body rate (rad/s) that rotates ``q0`` into ``q1`` in ``dt``: ``log(q0* ⊗ q1)/dt``."""
    dq = quat_mul(quat_conj(q0), q1)
    dq = np.where(dq[:, :1] < 0, -dq, dq)
    vec = dq[:, 1:]
    s = np.linalg.norm(vec, axis=1)
    angle = 2 * np.arctan2(s, dq[:, 0])
    scale = np.where(s > 1e-15, angle / np.where(s > 1e-15, s, 1.0), 2.0)
    return vec * (scale / dt)[:, None]


def sample_imu(state: dict[str, np.ndarray], t: np.ndarray, g: float = GRAVITY, mode: str = "interval"):
    """Noise-free accelerometer (m/s²) and gyroscope (rad/s) samples (FRD) from the exact state.

    ``state`` holds ``q`` (body->NED), ``v`` (m/s) and, for instantaneous sampling,
    ``a`` (m/s²) and ``w`` (rad/s) at the times ``t``.
    """
    q = state["q"]
    if mode == "instantaneous":
        acc = quat_rotate(quat_conj(q), state["a"] - gravity_ned(g))
        return acc, state["w"].copy()
    if mode != "interval":
        raise ValueError(f"sampling must be 'interval' or 'instantaneous', got {mode!r}")
    dt = np.diff(t)
    gyr = np.zeros((t.size, 3))
    gyr[1:] = quat_log_rate(q[:-1], q[1:], dt)
    acc = np.empty((t.size, 3))
    acc[0] = quat_rotate(quat_conj(q[0]), -gravity_ned(g))
    prev = np.where(np.sum(q[:-1] * q[1:], axis=1, keepdims=True) < 0, -q[:-1], q[:-1])
    q_mid = quat_normalize(prev + q[1:])
    dv = np.diff(state["v"], axis=0) / dt[:, None]
    acc[1:] = quat_rotate(quat_conj(q_mid), dv - gravity_ned(g))
    return acc, gyr


@dataclass
class NoiseModel:
    """Sensor errors ``μ + σ · randn`` per axis (Yun et al. 2012, eq. 18, Table II).

    Parameters
    ----------
    acc_bias : float
        μ of the accelerometer (m/s²): 0.1 % of a ±5 g full scale = 0.049.
    acc_sigma : float
        σ (m/s²): 0.033.
    gyr_bias : float
        μ (rad/s): 7.25e-6.
    gyr_sigma : float
        σ (rad/s): 0.0076.
    mag_bias : float
        μ (Gauss): 0.1 % of the 3DM-GX1's ±1.2 G full scale = 0.0012.
    mag_sigma : float
        σ (Gauss): 0.82e-3.
    scale : float
        Factor on every σ (Fig. 12: 0, 0.1, 1, 10).
    biases : tuple of str
        Which biases are on: any of ``"acc"``, ``"gyr"``, ``"mag"``.
    seed : int
        Random seed (every run is reproducible).
    paired_rate : float, optional
        Draw the white noise at this rate (Hz, at least the recording's) and give each sample the mean
        of that noise over its interval ``(t[k-1], t[k]]``, scaled to the σ above. One seed then gives
        the same noise path at every sampling rate, so walks at several rates differ only by the rate
        (a paired comparison, as a real sensor sampled at two rates at once). Default: independent
        draws per sample. Each sensor has its own random stream (``[seed, 0..2]``).
    """

    acc_bias: float = 0.001 * 5 * GRAVITY
    acc_sigma: float = 0.033
    gyr_bias: float = 7.25e-6
    gyr_sigma: float = 0.0076
    mag_bias: float = 0.001 * 1.2
    mag_sigma: float = 0.82e-3
    scale: float = 1.0
    biases: tuple[str, ...] = ("acc", "gyr", "mag")
    seed: int = 0
    paired_rate: float | None = None

    def __post_init__(self) -> None:
        if isinstance(self.biases, str) or not isinstance(self.biases, (tuple, list)):
            raise ConfigError(f"noise biases must be a list of names from 'acc', 'gyr', 'mag' (e.g. [acc, gyr]; [] for "
                              f"none), got {self.biases!r}")
        unknown = [b for b in self.biases if b not in ("acc", "gyr", "mag")]
        if unknown:
            raise ConfigError(f"unknown bias name(s) {unknown}; use 'acc', 'gyr', 'mag'")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            raise ConfigError(f"noise seed must be a whole number >= 0 (it seeds numpy's generator), got {self.seed!r}")
        for name in ("acc_bias", "acc_sigma", "gyr_bias", "gyr_sigma", "mag_bias", "mag_sigma", "scale"):
            value = getattr(self, name)
            try:
                arr = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                arr = np.asarray(np.nan)
            per_axis = name != "scale" and arr.shape == (3,)  # a bias or σ may differ per axis (x, y, z)
            bound = " >= 0" if name.endswith(("sigma", "scale")) else ""
            if isinstance(value, bool) or (arr.shape != () and not per_axis) or not np.isfinite(arr).all() \
                    or (bound and (arr < 0).any()):
                raise ConfigError(f"noise {name} must be a finite number{bound}"
                                  f"{'' if name == 'scale' else ' (or one per axis: [x, y, z])'}, got {value!r}")
        if self.paired_rate is not None and not (isinstance(self.paired_rate, (int, float, np.number))
                                                 and np.isfinite(self.paired_rate) and self.paired_rate > 0):
            raise ConfigError(f"paired_rate must be a rate in Hz > 0, got {self.paired_rate!r}")

    @property
    def random(self) -> bool:
        """Whether the seed changes the noise (some σ is above zero): with none, every seed gives one recording."""
        return self.scale > 0 and max(float(np.max(s)) for s in (self.acc_sigma, self.gyr_sigma, self.mag_sigma)) > 0

    def apply(self, acc: np.ndarray, gyr: np.ndarray, mag: np.ndarray | None, t: np.ndarray | None = None):
        """Noisy copies of the signals (eq. 18); ``t`` (s), the sample times, is needed with ``paired_rate``."""
        if self.paired_rate is not None and t is None:
            raise ValueError("NoiseModel.apply needs the sample times t with paired_rate")
        rng = np.random.default_rng(self.seed)
        out = []
        for k, (name, x, mu, sigma) in enumerate((("acc", acc, self.acc_bias, self.acc_sigma),
                                                  ("gyr", gyr, self.gyr_bias, self.gyr_sigma),
                                                  ("mag", mag, self.mag_bias, self.mag_sigma))):
            if x is None:
                out.append(None)
                continue
            unit = rng.standard_normal(x.shape) if self.paired_rate is None else \
                interval_means(np.random.default_rng([self.seed, k]), t, self.paired_rate)
            out.append(x + unit * sigma * self.scale + (mu if name in self.biases else 0.0))
        return tuple(out)

    @classmethod
    def none(cls) -> NoiseModel:
        """No noise and no bias."""
        return cls(scale=0.0, biases=())


#: Length of the paired noise path before the first sample (s): the same for every rate, so paths align.
PATH_LEAD = 1.0
#: Draws of the paired noise path made at a time (an hour's walk at 4 kHz is 14.4 million per axis).
PATH_BLOCK = 1 << 18


def interval_means(rng: np.random.Generator, t: np.ndarray, rate: float) -> np.ndarray:
    """(N, 3) noise of unit σ per sample: the mean over each interval ``(t[k-1], t[k]]`` of one white-noise
    path drawn at ``rate`` (Hz) from :data:`PATH_LEAD` before ``t[0]``, scaled by sqrt(interval × rate).

    The path's running sum is a random walk on the grid of ``rate``; a sample's mean is its increment over
    the interval (linear between grid points), so intervals on the grid get exactly the mean of the draws
    they cover, and the same path serves every sampling rate whose intervals fall on it (the first
    sample's interval is taken as long as the second's). Intervals off the grid get slightly less
    variance (linear interpolation of the walk): at most half a grid step's worth.
    """
    t = np.asarray(t, float)
    first = t[1] - t[0] if t.size > 1 else 1.0 / rate
    if first * rate < 1.0 - 1e-9:
        raise ValueError(f"paired_rate {rate:g} Hz must be at least the recording's rate ({1.0 / first:g} Hz)")
    if first > PATH_LEAD:
        raise ValueError(f"paired noise needs a sampling rate of at least {1.0 / PATH_LEAD:g} Hz, "
                         f"got {1.0 / first:g} Hz")
    edges = (np.r_[t[0] - first, t] - (t[0] - PATH_LEAD)) * rate  # interval edges on the grid of the path
    if np.any(np.diff(edges) <= 0):
        raise ValueError("paired noise needs increasing sample times")
    n = int(np.ceil(edges[-1] - 1e-9)) + 1  # draws of the path
    at = np.empty((edges.size, 3))  # the walk (running sum of the draws) at each edge
    level, done = np.zeros(3), 0  # the walk at grid point ``b0``; edges handled so far
    for b0 in range(0, n, PATH_BLOCK):  # block by block: memory of one block, whatever the walk's length
        walk = np.vstack([level, level + np.cumsum(rng.standard_normal((min(PATH_BLOCK, n - b0), 3)), axis=0)])
        upto = int(np.searchsorted(edges, b0 + walk.shape[0] - 1, side="right"))
        grid = np.arange(walk.shape[0], dtype=float)
        at[done:upto] = np.column_stack([np.interp(edges[done:upto] - b0, grid, walk[:, j]) for j in range(3)])
        level, done = walk[-1], upto
    return np.diff(at, axis=0) / np.sqrt(np.diff(edges))[:, None]


def magnetic_field_ned(location: str | tuple[float, float] = "monterey") -> np.ndarray:
    """Earth field in NED (Gauss) for a named location or ``(intensity G, inclination deg)``.

    North is magnetic north (declination 0), as in Yun's simulation (eq. 13).
    """
    if isinstance(location, str):
        if location not in MAGNETIC_FIELDS:
            raise ValueError(f"unknown magnetic location {location!r}; known: {sorted(MAGNETIC_FIELDS)}")
        intensity, incl = MAGNETIC_FIELDS[location]
    else:
        intensity, incl = location
    i = np.radians(incl)
    return intensity * np.array([np.cos(i), 0.0, np.sin(i)])


@dataclass
class MagneticDisturbance:
    """An extra field (Gauss, NED) inside a horizontal rectangle ``[n0, n1] × [e0, e1]`` (m)."""

    field: tuple[float, float, float] = (0.0, 0.25, 0.0)
    north: tuple[float, float] = (0.0, 10.0)
    east: tuple[float, float] = (-1.0, 1.0)

    def at(self, pos: np.ndarray) -> np.ndarray:
        """Disturbance field (N, 3) at positions (N, 3)."""
        inside = ((pos[:, 0] >= self.north[0]) & (pos[:, 0] <= self.north[1])
                  & (pos[:, 1] >= self.east[0]) & (pos[:, 1] <= self.east[1]))
        return inside[:, None] * np.asarray(self.field, float)[None, :]


@dataclass
class DistanceSensors:
    """Time-of-flight range sensors (VL6180 kind) looking at a flat floor (Duong & Suh 2015, Table 1).

    Duong & Suh give the positions and directions in their IMU frame, whose x
    axis points at the floor: ``r_A = [-0.008, 0.080, 0]``, ``r_B = [-0.006, -0.062, 0]``,
    ``n_A = n_B = [1, 0, 0]``. footzoo maps their axes (x, y, z) to FRD (z, x, y):
    x_FRD = y_DS (forward), y_FRD = z_DS, z_FRD = x_DS (down), a proper rotation.

    Parameters
    ----------
    positions : (k, 3) array
        Sensor positions in the body frame (FRD, m).
    directions : (k, 3) array
        Beam directions in the body frame (unit vectors).
    rate : float
        Sampling rate (Hz), 33.33.
    noise_var : float
        Range noise variance (m²), 0.0004.
    max_range : float
        Range limit (m), 0.2; beyond it the sensor reports ``out_of_range_value``.
    out_of_range_value : float
        What the sensor reports without a target within range (m); VL6180: 0.255.
    floor_z : float
        Floor height in NED (m, down positive).
    """

    positions: np.ndarray = None  # type: ignore[assignment]
    directions: np.ndarray = None  # type: ignore[assignment]
    rate: float = 33.33
    noise_var: float = 0.0004
    max_range: float = 0.2
    out_of_range_value: float = 0.255
    floor_z: float = 0.06

    def __post_init__(self) -> None:
        if self.positions is None:
            self.positions = np.array([[0.080, 0.0, -0.008], [-0.062, 0.0, -0.006]])
        if self.directions is None:
            self.directions = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
        self.positions = np.atleast_2d(np.asarray(self.positions, float))
        self.directions = np.atleast_2d(np.asarray(self.directions, float))
        self.directions = self.directions / np.linalg.norm(self.directions, axis=1, keepdims=True)

    def true_range(self, pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
        """Geometric distance along each beam to the floor (m), (N, k); inf when the beam misses it."""
        out = np.empty((pos.shape[0], self.positions.shape[0]))
        for j, (r, n) in enumerate(zip(self.positions, self.directions, strict=True)):
            origin = pos + quat_rotate(quat, r)
            d = quat_rotate(quat, n)
            with np.errstate(divide="ignore", invalid="ignore"):
                rng = (self.floor_z - origin[:, 2]) / d[:, 2]
            out[:, j] = np.where((d[:, 2] > 1e-9) & (rng >= 0), rng, np.inf)
        return out

    def sample(self, t: np.ndarray, pos: np.ndarray, quat: np.ndarray, seed: int = 0):
        """Readings (m, NaN between samples) and true ranges at the sensor's own rate."""
        k = np.floor((t - t[0]) * self.rate + 1e-9).astype(int)
        has = np.ones(t.size, bool)
        has[1:] = k[1:] != k[:-1]
        true = self.true_range(pos, quat)
        rng = np.random.default_rng(seed + 7919)
        reading = true + rng.standard_normal(true.shape) * np.sqrt(self.noise_var)
        reading = np.where(true > self.max_range, self.out_of_range_value, reading)
        reading[~has] = np.nan
        true = np.where(has[:, None], true, np.nan)
        return reading, true
