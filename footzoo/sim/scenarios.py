"""Composable simulated recordings with ground truth.

``simulate(path=..., ...)`` builds a :class:`~footzoo.core.data.Recording` whose
:class:`~footzoo.core.data.Truth` holds, for every sample, the sensor's position,
velocity, attitude and stance flag (stance = the sensor's velocity is zero
over the whole sample interval), and per step the start and end, stride
length, heading and foot progression angle; with distance sensors, the true
range of every distance sample.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import asdict, fields
from typing import Any

import numpy as np
import pandas as pd

from ..core.conventions import GRAVITY, quat_conj, quat_rotate
from ..core.data import Recording, Truth
from ..core.errors import ConfigError, did_you_mean
from . import paths
from .gait import FootGeometry, Footstep, GaitTimeline, StrideSpec, calibration_timeline
from .sensors import DistanceSensors, MagneticDisturbance, NoiseModel, magnetic_field_ned, sample_imu

#: Walking speeds Nguyen & La tested (m/s) and a run, as
#: (stride length m, cycle s, stance fraction, foot-flat share of stance).
SPEEDS = {
    "slow": (1.0, 1.18, 0.62, 2 / 3),  # 0.85 m/s
    "normal": (1.38, 1.0, 0.60, 2 / 3),  # 1.38 m/s
    "fast": (1.6, 0.833, 0.58, 0.6),  # 1.92 m/s
    "run": (2.4, 0.75, 0.40, 1 / 3),  # 3.2 m/s: 0.3 s contact, 0.1 s still (PyShoe fast trials: 0.10-0.15 s)
}

PATHS = ("straight", "rectangle", "track", "figure_eight", "mixed_speed", "run", "stairs")


#: Most strides one simulation makes (about a day of walking): more is a typo that would run for hours.
MAX_STRIDES = 100_000


#: The simulator's numeric arguments: the range each must lie in (as text) and its test.
LIMITS: dict[str, tuple[str, Callable[[float], bool]]] = {
    "stride_length": ("(0, 5] m", lambda v: 0 < v <= 5), "cycle": ("(0, 10] s", lambda v: 0 < v <= 10),
    "stance_fraction": ("(0, 1)", lambda v: 0 < v < 1), "rate": ("(0, 20000] Hz", lambda v: 0 < v <= 20000),
    "stand_start": ("[0, 3600] s", lambda v: 0 <= v <= 3600), "stand_end": ("[0, 3600] s", lambda v: 0 <= v <= 3600),
    "clearance": ("[0, 2] m", lambda v: 0 <= v <= 2),
}


def check_arguments(**kw: Any) -> None:
    """Refuse simulator arguments that cannot make a walk, with a ConfigError naming the argument (before any work).

    Checks ``path``, ``foot``, ``n_strides`` (a whole number up to :data:`MAX_STRIDES`) and the numbers of
    :data:`LIMITS`; a study checks its ``simulate:`` entries with it before running anything.
    """
    if "path" in kw and kw["path"] not in PATHS:
        raise ConfigError(f"simulate: unknown path {kw['path']!r}; known: {list(PATHS)}")
    if "foot" in kw and kw["foot"] not in ("right", "left"):
        raise ConfigError(f"simulate: foot must be 'right' or 'left', got {kw['foot']!r}")
    n = kw.get("n_strides", 1)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 0 <= n <= MAX_STRIDES:
        raise ConfigError(f"simulate: n_strides must be a whole number in [0, {MAX_STRIDES}] (about a day of "
                          f"walking), got {n!r}; simulate a longer walk in parts")
    for name, (bounds, ok) in LIMITS.items():
        v = kw.get(name, None)
        if name in kw and (isinstance(v, bool) or not isinstance(v, (int, float, np.number)) or not np.isfinite(v)
                           or not ok(float(v))):
            raise ConfigError(f"simulate: {name} must be a number in {bounds}, got {v!r}")
    seed = kw.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ConfigError(f"simulate: seed must be a whole number >= 0, got {seed!r}")
    noise = kw.get("noise")
    if isinstance(noise, dict):
        noise_model(noise)
    elif noise is not None and not isinstance(noise, NoiseModel):
        raise ConfigError(f"simulate: noise must be a mapping of NoiseModel's options (e.g. {{scale: 1}}) or "
                          f"nothing, got {noise!r:.80}")


def noise_model(options: dict[str, Any]) -> NoiseModel:
    """A :class:`NoiseModel` from a mapping (a study's ``noise:``), its unknown options named (ConfigError)."""
    known = [f.name for f in fields(NoiseModel)]
    for key in options:
        if key not in known:
            raise ConfigError(f"simulate: noise: unknown option {key!r}{did_you_mean(str(key), known)}; "
                              f"options: {known}")
    return NoiseModel(**{k: (tuple(v) if k == "biases" and isinstance(v, list) else v) for k, v in options.items()})


def seed_matters(spec: dict[str, Any]) -> bool:
    """Whether the seed changes a ``simulate(**spec)`` recording: its noise or its distance sensors are random.

    Without either, every seed gives the same recording (a study would average identical runs).
    """
    noise = spec.get("noise")
    if isinstance(noise, dict):
        noise = noise_model(noise)
    if isinstance(noise, NoiseModel) and noise.random:
        return True
    sensors = spec.get("distance_sensors")
    if sensors:
        return (sensors if isinstance(sensors, DistanceSensors) else DistanceSensors()).noise_var > 0
    return False


#: The path-shape options ``simulate`` takes besides its named arguments (see its ``**path_options``).
PATH_OPTIONS = ("length", "width", "radius", "heading", "rise", "going", "landing_strides", "laps")


def check_spec(spec: dict[str, Any]) -> None:
    """A ``simulate(**spec)`` mapping (a study's ``simulate:`` entry): unknown names and bad values refused."""

    known = [p for p in inspect.signature(simulate).parameters if p != "path_options"] + list(PATH_OPTIONS)
    for key in spec:
        if key not in known:
            raise ConfigError(f"simulate: unknown option {key!r}{did_you_mean(str(key), known)}; options: {known}")
    check_arguments(**spec)


def _footsteps(path: str, n_strides: int, stride_length: float, **kw) -> tuple[list[Footstep], bool]:
    laps = int(kw.get("laps", 1))
    if laps != 1 and path not in ("rectangle", "track", "figure_eight"):
        raise ValueError(f"laps applies to closed paths (rectangle, track, figure_eight), not {path!r}")
    if path == "straight":
        return paths.straight(n_strides, stride_length, kw.get("heading", 0.0)), False
    if path == "stairs":
        return paths.stairs(n_strides, kw.get("rise", 0.17), kw.get("going", 0.28), kw.get("landing_strides", 2),
                            stride_length, kw.get("heading", 0.0)), False
    if path == "rectangle":
        steps = paths.rectangle(kw.get("length", 40.0), kw.get("width", 20.0), stride_length)
    elif path == "track":
        steps = paths.track(stride_length=stride_length)
    elif path == "figure_eight":
        steps = paths.figure_eight(kw.get("radius", 5.0), stride_length)
    else:
        raise ValueError(f"unknown path {path!r}; known: {list(PATHS)}")
    return paths.repeat_laps(steps, laps), True


def simulate(
    path: str = "straight",
    n_strides: int = 100,
    stride_length: float = 1.2,
    cycle: float = 1.0,
    stance_fraction: float = 0.6,
    clearance: float = 0.25,
    flat_fraction: float = 2.0 / 3.0,
    rate: float = 50.0,
    profile: str = "paper",
    sampling: str = "interval",
    noise: NoiseModel | dict | None = None,
    magnetometer: bool = True,
    location: str | tuple[float, float] = "monterey",
    disturbance: MagneticDisturbance | None = None,
    distance_sensors: DistanceSensors | bool = False,
    fpa: float | list[float] = 0.0,
    mount_yaw: float = 0.0,
    mount_pitch: float = 0.0,
    foot: str = "right",
    speeds: list[tuple[str, int]] | None = None,
    stand_start: float = 2.0,
    stand_end: float = 1.0,
    gravity: float = GRAVITY,
    seed: int = 0,
    **path_options,
) -> Recording:
    """Simulate one foot-mounted IMU walk.

    Parameters
    ----------
    path : {"straight", "rectangle", "track", "figure_eight", "mixed_speed", "run", "stairs"}
        Footstep layout; ``mixed_speed`` walks straight through ``speeds``; ``run``
        runs ``n_strides`` straight strides at :data:`SPEEDS` ``["run"]`` (3.2 m/s);
        ``stairs`` climbs ``n_strides`` strides of two steps, crosses a landing of
        ``landing_strides`` strides of ``stride_length`` and descends as many (options
        ``rise`` = 0.17 m and ``going`` = 0.28 m per step; see :func:`footzoo.sim.paths.stairs`).
    n_strides : int
        Strides of a straight walk (closed paths take as many as they need).
    stride_length : float
        Stride length (m); Table II: 1.2.
    cycle, stance_fraction, clearance : float
        Gait cycle (s), stance share, swing clearance (m); Table I/II: 1.0, 0.6, 0.25.
    flat_fraction : float
        Foot-flat share of the stance (Table I: 2/3; running about 1/3).
    rate : float
        Sampling rate (Hz); Table II: 50.
    profile : {"paper", "physical"}
        Stance kinematics (see :mod:`footzoo.sim.gait`).
    sampling : {"interval", "instantaneous"}
        See :mod:`footzoo.sim.sensors`.
    noise : NoiseModel or dict, optional
        Sensor errors (eq. 18); default: none.
    magnetometer : bool
        Include a magnetometer (eq. 13 generalised: the field rotated into the body).
    location : str or (intensity G, inclination deg)
        Earth field (default Monterey, where Yun et al. worked).
    disturbance : MagneticDisturbance, optional
        Extra field in a region.
    distance_sensors : DistanceSensors or bool
        Two VL6180-like sensors seeing a flat floor (Duong & Suh Table 1) when True.
    fpa : float or list of float
        Foot progression angle per footstep (rad, toe-out positive).
    mount_yaw, mount_pitch : float
        Sensor mounting on the foot (rad).
    foot : {"right", "left"}
        Which foot (sets the sign of toe-out).
    speeds : list of (name, n_strides)
        For ``mixed_speed``: e.g. ``[("slow", 8), ("normal", 8), ("fast", 8), ("run", 8)]``
        with names from :data:`SPEEDS`.
    stand_start, stand_end : float
        Standing still before and after (s).
    seed : int
        Seed of the noise (reproducible).
    **path_options
        Path shape: ``length``/``width`` (rectangle, m), ``radius`` (figure eight, m),
        ``heading`` (straight and stairs, rad), ``rise``/``going``/``landing_strides``
        (stairs), ``laps`` (closed paths walked that many times: ``track`` with
        ``laps=10`` is a 4.4 km, one-hour walk at 1.2 m/s).
    """
    check_arguments(path=path, n_strides=n_strides, stride_length=stride_length, cycle=cycle,
                    stance_fraction=stance_fraction, clearance=clearance, rate=rate, stand_start=stand_start,
                    stand_end=stand_end, foot=foot, seed=seed, noise=noise)
    rec_name = f"sim_{path}"
    if path == "run":
        path, speeds = "mixed_speed", [("run", n_strides)]
    if path == "mixed_speed":
        speeds = speeds or [("slow", 9), ("normal", 9), ("fast", 9), ("run", 9)]
        specs, lengths = [], []
        for name, n in speeds:
            if name not in SPEEDS:
                raise ValueError(f"unknown speed {name!r}; known: {sorted(SPEEDS)}")
            L, c, sf, flat = SPEEDS[name]
            specs += [StrideSpec(c, sf, clearance, flat)] * n
            lengths += [L] * n
        steps, closed = paths.straight(len(lengths), lengths), False
    else:
        steps, closed = _footsteps(path, n_strides, stride_length, **path_options)
        specs = [StrideSpec(cycle, stance_fraction, clearance, flat_fraction)] * (len(steps) - 1)
    fpas = np.broadcast_to(np.asarray(fpa, float), (len(steps),))
    for s, a in zip(steps, fpas, strict=True):
        s.fpa = float(a)
    geometry = FootGeometry(mount_yaw=mount_yaw, mount_pitch=mount_pitch, side=1 if foot == "right" else -1)
    timeline = GaitTimeline(steps, specs, geometry, profile=profile, stand_start=stand_start, stand_end=stand_end)

    t = np.arange(0.0, timeline.t_end, 1.0 / rate)
    state = timeline.evaluate(t)
    acc, gyr = sample_imu(state, t, gravity, sampling)
    mag = None
    if magnetometer:
        field = np.tile(magnetic_field_ned(location), (t.size, 1))
        if disturbance is not None:
            field = field + disturbance.at(state["p"])
        mag = quat_rotate(quat_conj(state["q"]), field)
    if noise is not None:
        noise = noise_model(noise) if isinstance(noise, dict) else noise
        acc, gyr, mag = noise.apply(acc, gyr, mag, t)
    dist = true_dist = None
    if distance_sensors:
        ds = distance_sensors if isinstance(distance_sensors, DistanceSensors) else DistanceSensors()
        ds.floor_z = float(geometry.heel[2])
        dist, true_dist = ds.sample(t, state["p"], state["q"], seed=seed)

    mid = timeline.evaluate(np.concatenate([[t[0]], t[:-1] + 0.5 / rate]))["still"]
    stance = state["still"] & mid & np.concatenate([[True], state["still"][:-1]])
    step_table = pd.DataFrame(timeline.steps)
    truth = Truth(pos=state["p"], vel=state["v"], quat=state["q"], stance=stance, steps=step_table,
                  closed_loop=closed, dist=true_dist, stride_count=len(step_table), source="simulator")
    meta = {
        "name": rec_name, "source": "footzoo.sim", "format": "simulated", "profile": profile,
        "sampling": sampling, "foot": foot, "seed": seed,
        "noise": asdict(noise) if isinstance(noise, NoiseModel) else "none",
    }
    if dist is not None:
        meta["dist_columns"] = [f"dist_{chr(97 + j)}" for j in range(dist.shape[1])]
    return Recording(t=t, acc=acc, gyr=gyr, mag=mag, dist=dist, meta=meta, truth=truth)


def simulate_calibration(
    mount_yaw: float = 0.0,
    mount_pitch: float = 0.0,
    foot: str = "right",
    rate: float = 100.0,
    noise: NoiseModel | dict | None = None,
    magnetometer: bool = True,
    location: str | tuple[float, float] = "monterey",
    gravity: float = GRAVITY,
    **options,
) -> Recording:
    """The calibration trial of Huang et al. 2016 (Sec. III): stand still, three slow flexions, stand.

    ``meta["calibration_still"]`` and ``meta["calibration_flex"]`` hold the two
    periods (s); the truth's quaternion gives the mounting to recover.
    """

    geometry = FootGeometry(mount_yaw=mount_yaw, mount_pitch=mount_pitch, side=1 if foot == "right" else -1)
    timeline = calibration_timeline(geometry, **options)
    t = np.arange(0.0, timeline.t_end, 1.0 / rate)
    state = timeline.evaluate(t)
    acc, gyr = sample_imu(state, t, gravity, "interval")
    mag = quat_rotate(quat_conj(state["q"]), magnetic_field_ned(location)) if magnetometer else None
    if noise is not None:
        noise = noise_model(noise) if isinstance(noise, dict) else noise
        acc, gyr, mag = noise.apply(acc, gyr, mag, t)
    truth = Truth(pos=state["p"], vel=state["v"], quat=state["q"], stance=state["still"])
    meta = {"name": "sim_calibration", "source": "footzoo.sim", "format": "simulated", "foot": foot,
            "calibration_still": list(timeline.phases["still"]), "calibration_flex": list(timeline.phases["flex"])}
    return Recording(t=t, acc=acc, gyr=gyr, mag=mag, meta=meta, truth=truth)
