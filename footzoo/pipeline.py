"""Compose plug-ins into a pipeline and run it on a recording."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from . import __version__
from ._table import samples_frame
from .alignment import initial_attitude
from .analysis.strides import segment_steps
from .config import INIT_KEYS, check_top_level, load_yaml
from .conventions import GRAVITY
from .data import Recording, Result
from .errors import ConfigError
from .filters.strapdown import integrate_position, integrate_velocity, motion_acceleration, sample_intervals
from .registry import Plugin, build, check_positive


def _clone(p: Plugin) -> Plugin:
    return type(p)(**copy.deepcopy(p.get_params()))


class Pipeline:
    """An orientation filter, a stance detector and a list of corrections.

    One sample's way: recording -> detector (vectorised, whole recording) ->
    orientation filter (sample loop, adaptive gain from the detector's causal
    phase) -> motion acceleration in NED -> corrections (velocity, position) ->
    steps. Without corrections the acceleration is integrated as measured.

    Parameters
    ----------
    orientation, detector : Plugin
        Built plug-ins.
    corrections : list of Plugin
        Applied in order.
    name : str
        Pipeline name.
    gravity : float
        g (m/s²).
    init : dict
        ``duration`` (s) and ``max_gyr`` (rad/s) of the still start used for alignment.
    """

    def __init__(
        self,
        orientation: Plugin,
        detector: Plugin,
        corrections: list[Plugin] | None = None,
        name: str = "pipeline",
        gravity: float = GRAVITY,
        init: dict[str, float] | None = None,
        analysis: list[Plugin] | None = None,
    ):
        self.orientation = orientation
        self.detector = detector
        self.corrections = list(corrections or [])
        self.analysis = list(analysis or [])
        self.name = name
        self.gravity = check_positive("gravity", gravity)
        self.init = {**INIT_KEYS, **(init or {})}
        check_compatibility(orientation, detector, self.corrections)

    # ----------------------------------------------------------------- build
    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Pipeline:
        """Build and validate a pipeline from a config mapping (see :mod:`footzoo.config`)."""
        check_top_level(d)
        orientation = build("orientation", d["orientation"], "orientation")
        detector = build("detector", d["detector"], "detector")
        corrections = [
            build("correction", c, f"corrections[{i}]") for i, c in enumerate(d.get("corrections") or [])
        ]
        analysis = [build("analysis", a, f"analysis[{i}]") for i, a in enumerate(d.get("analysis") or [])]
        return cls(
            orientation,
            detector,
            corrections,
            name=str(d.get("name", "pipeline")),
            gravity=d.get("gravity", GRAVITY),
            init=d.get("init") or {},
            analysis=analysis,
        )

    @classmethod
    def from_yaml(cls, path: str | Path) -> Pipeline:
        """Build a pipeline from a YAML file."""
        d = load_yaml(path)
        try:
            return cls.from_dict(d)
        except ConfigError as err:
            raise ConfigError(f"{path}: {err}") from None

    def to_dict(self) -> dict[str, Any]:
        """The resolved configuration, every parameter explicit."""
        def spec(p: Plugin) -> dict[str, Any]:
            return {"type": p.name, **p.get_params()}

        return {
            "name": self.name,
            "gravity": self.gravity,
            "init": dict(self.init),
            "orientation": spec(self.orientation),
            "detector": spec(self.detector),
            "corrections": [spec(c) for c in self.corrections],
            "analysis": [spec(a) for a in self.analysis],
        }

    # ------------------------------------------------------------------- run
    def run(self, rec: Recording, engine: str = "auto") -> Result:
        """Estimate attitude, velocity, position and steps for one recording.

        Parameters
        ----------
        rec : Recording
            The input.
        engine : {"auto", "fast", "reference"}
            For Kalman-filter pipelines: the compiled loop
            (:mod:`footzoo.filters.eskf_fast`) or the reference loop on filterpy's
            ``KalmanFilter``; ``auto`` takes the compiled one whenever every
            correction is one footzoo ships. Both give the same numbers.
        """
        if engine not in ("auto", "fast", "reference"):
            raise ValueError(f"engine must be 'auto', 'fast' or 'reference', got {engine!r}")
        if not isinstance(rec, Recording):
            raise TypeError(f"Pipeline.run expects a footzoo Recording, got {type(rec).__name__}")
        t, acc, gyr, mag = rec.t, rec.acc, rec.gyr, rec.mag
        detector = _clone(self.detector)
        if getattr(detector, "needs_truth", False):
            detector.detect(t, acc, gyr, rec.truth)
        else:
            detector.detect(t, acc, gyr)
        stance = detector.stance_
        orientation = _clone(self.orientation)
        corrections = [_clone(c) for c in self.corrections]
        use_mag = mag is not None and getattr(orientation, "use_magnetometer", False)
        q0 = initial_attitude(t, acc, gyr, mag if use_mag else None, **self.init)
        diagnostics: dict[str, Any] = {"detector_statistic": detector.statistic_}
        kalman = [c for c in corrections if c.role == "kalman"]
        heading = [c for c in corrections if c.role == "heading"]
        velocity = [c for c in corrections if c.role == "velocity"]
        dt = sample_intervals(t)
        if kalman:
            quat_ext = None
            if orientation.name != "ins":
                quat_ext = orientation.estimate(t, acc, gyr, mag, stance, q0).quat_
            init_window = t <= t[0] + self.init["duration"]
            for m in kalman:
                if getattr(m, "needs_recording", False):
                    m.bind(rec.dist, t, init_window)
            nav = _run_kalman(t, acc, gyr, stance, q0, orientation, kalman + heading, quat_ext, self.gravity,
                              engine, rec.dist, init_window)
            quat, vel, pos, acc_nav = nav["quat"], nav["vel"], nav["pos"], nav["acc_nav"]
            diagnostics.update(gyro_bias=nav["gyro_bias"], acc_bias=nav["acc_bias"], P_diag=nav["P_diag"])
            if "distance_calibration" in nav:
                diagnostics["distance_calibration"] = nav["distance_calibration"]
        else:
            quat = orientation.estimate(t, acc, gyr, mag, stance, q0).quat_
            acc_nav = motion_acceleration(quat, acc, self.gravity)
            for h in heading:
                acc_nav = h.apply_acceleration(quat, acc_nav, stance)
            if velocity:
                corr = velocity[0].apply(t, acc_nav, stance)
                vel, pos = corr.vel_, corr.pos_
            else:
                vel = integrate_velocity(acc_nav, dt)
                pos = integrate_position(vel, dt)
        samples = samples_frame(t, quat, pos, vel, acc_nav, stance)
        steps = segment_steps(t, stance, pos)
        for a in self.analysis:
            a = _clone(a).analyze(t, quat, pos, stance, rec.meta)
            steps = a.annotate(steps, t)
        return Result(
            samples=samples,
            steps=steps,
            config=self.to_dict(),
            versions=versions(),
            recording=dict(rec.meta),
            diagnostics=diagnostics,
        )


def _kalman_layout(orientation, measurements, external: bool):
    """Error-state blocks from the plug-ins: (layout, initial variances, variance growth per second)."""
    from .filters.eskf import Layout
    from .orientation.ins import INS

    ins = orientation if orientation.name == "ins" else INS()
    extra = {name: (size, p0, q) for m in measurements for name, size, p0, q in m.blocks()}
    blocks: list[tuple[str, int, float, float]] = []
    if not external:
        blocks.append(("att", 3, ins.initial_attitude_std**2, ins.attitude_noise))
    if "gyro_bias" in extra:
        blocks.append(("gyro_bias", *extra.pop("gyro_bias")))
    blocks.append(("pos", 3, 0.0, ins.position_noise))
    blocks.append(("vel", 3, 0.0, ins.velocity_noise))
    if "acc_bias" in extra:
        blocks.append(("acc_bias", *extra.pop("acc_bias")))
    blocks += [(name, *spec) for name, spec in extra.items()]
    layout = Layout([(b[0], b[1]) for b in blocks])
    p0 = np.concatenate([np.full(b[1], b[2]) for b in blocks])
    q = np.concatenate([np.full(b[1], b[3]) for b in blocks])
    return layout, p0, q


def _run_kalman(t, acc, gyr, stance, q0, orientation, measurements, quat_ext, gravity, engine="auto",
                dist=None, init_window=None) -> dict[str, Any]:
    """Run the error-state filter loop over a recording (compiled or reference)."""
    from .filters.eskf import ErrorStateFilter
    from .filters.navigation import run_error_state_filter

    fast = engine != "reference" and all(type(m).__module__.startswith("footzoo.corrections") for m in measurements)
    if engine == "fast" and not fast:
        raise ConfigError("engine='fast' supports footzoo's own corrections only; use engine='reference'")
    if fast:
        from .filters import eskf_fast as ef

        window = np.asarray(init_window if init_window is not None else np.zeros(len(t), bool), dtype=np.bool_)
        dist_m = next((m for m in measurements if m.name == "height_distance"), None)
        init_dist = dist_m._dist[window] if dist_m is not None else np.zeros((int(window.sum()), 0))
        s = _run_kalman_setup(orientation, measurements, init_dist, gravity, q0, quat_ext)
        d = dist_m._dist if dist_m is not None else np.zeros((len(t), 0))
        valid = np.isfinite(d) & (d <= s["max_range"])
        res = ef.eskf_kernel(
            np.ascontiguousarray(t), acc, gyr, np.asarray(stance, dtype=np.bool_), s["ext"], s["use_ext"],
            s["idx"], s["n"], s["q"], s["gravity"], s["order"], *s["par"],
            np.ascontiguousarray(d, dtype=float), np.ascontiguousarray(valid), window, s["init_dist"],
            s["init_valid"], s["r_d"], s["n_d"], *s["dist_par"], s["nav"], s["P"], s["scal"], 0,
        )
        quat, vel, pos, acc_nav, gb, ab, pdiag = res
        out = {"quat": quat, "vel": vel, "pos": pos, "acc_nav": acc_nav, "gyro_bias": gb, "acc_bias": ab,
               "P_diag": pdiag}
        if dist_m is not None:
            out["distance_calibration"] = {"positions": s["r_d"].tolist(), "directions": s["n_d"].tolist()}
        return out
    layout, p0, q = _kalman_layout(orientation, measurements, quat_ext is not None)
    kf = ErrorStateFilter(layout, p0, q)
    out = run_error_state_filter(t, acc, gyr, stance, q0, layout, kf, measurements, quat_ext, gravity)
    for m in measurements:
        if hasattr(m, "calibration_result"):
            out["distance_calibration"] = m.calibration_result()
    return out


def _run_kalman_setup(orientation, measurements, init_dist, gravity, q0, quat_ext=None) -> dict[str, Any]:
    """Encode the plug-ins for :func:`footzoo.filters.eskf_fast.eskf_kernel`, with its initial state."""
    from .filters import eskf_fast as ef

    layout, p0, q = _kalman_layout(orientation, measurements, quat_ext is not None)
    order: list[int] = []
    par = {"vel_std": 1.0, "rate_std": 1.0, "floor_std": 1.0, "hdr_threshold": 0.0, "hdr_std": 1.0}
    dist_m = None
    for m in measurements:
        if m.name in ("ekf_zupt", "zupt"):
            order.append(ef.ZERO_VELOCITY)
            par["vel_std"] = m.velocity_std
            if m.zero_rate:
                order.append(ef.ZERO_RATE)
                par["rate_std"] = m.rate_std
        elif m.name == "height_flat_floor":
            order.append(ef.FLAT_FLOOR)
            par["floor_std"] = m.height_std
        elif m.name == "height_distance":
            order.append(ef.DISTANCE)
            dist_m = m
        elif m.name == "hdr":
            order.append(ef.HEADING)
            par["hdr_threshold"], par["hdr_std"] = m.threshold, m.yaw_std
    idx = np.array([layout[b].start if layout.has(b) else -1 for b in ("att", "gyro_bias", "pos", "vel", "acc_bias")],
                   dtype=np.int64)
    k = 0 if dist_m is None else dist_m.k
    if dist_m is not None:
        calibrate = dist_m.calibrate
        cal_r = np.array([layout[f"cal_r{j}"].start if calibrate else 0 for j in range(k)], dtype=np.int64)
        cal_n = np.array([layout[f"cal_n{j}"].start if calibrate else 0 for j in range(k)], dtype=np.int64)
        dist_par = (float(dist_m.range_std), bool(calibrate), cal_r, cal_n, float(dist_m.constraint_std),
                    float(dist_m.baseline), float(dist_m.baseline_std))
        r_d, n_d, max_range = dist_m._r.copy(), dist_m._n.copy(), float(dist_m.max_range)
    else:
        dist_par = (1.0, False, np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), 1.0, 1.0, 1.0)
        r_d, n_d, max_range = np.zeros((0, 3)), np.zeros((0, 3)), np.inf
    init_dist = np.ascontiguousarray(np.asarray(init_dist, dtype=float).reshape(-1, k) if k else
                                     np.zeros((len(init_dist), 0)))
    init_valid = np.isfinite(init_dist) & (init_dist <= max_range)
    use_ext = quat_ext is not None
    ext = np.ascontiguousarray(quat_ext) if use_ext else np.zeros((1, 4))
    nav, P, scal = ef.initial_state(ext[0] if use_ext else np.asarray(q0, float), np.diag(p0))
    return {"ext": ext, "use_ext": use_ext, "idx": idx, "n": layout.n, "q": q, "gravity": float(gravity),
            "order": np.array(order, dtype=np.int64),
            "par": (par["vel_std"], par["rate_std"], par["floor_std"], par["hdr_threshold"], par["hdr_std"]),
            "init_dist": init_dist, "init_valid": np.ascontiguousarray(init_valid), "r_d": r_d, "n_d": n_d,
            "dist_par": dist_par, "nav": nav, "P": P, "scal": scal, "k_sensors": k, "max_range": max_range}


def check_compatibility(orientation: Plugin, detector: Plugin, corrections: list[Plugin]) -> None:
    """Reject plug-in combinations that cannot work together, with the reason and the fix."""
    roles: dict[str, list[str]] = {}
    for c in corrections:
        roles.setdefault(c.role, []).append(c.name)
    names = [c.name for c in corrections]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ConfigError(f"corrections: {dupes} listed more than once; keep one of each")
    if len(roles.get("velocity", [])) > 1:
        raise ConfigError(f"corrections {roles['velocity']}: only one velocity correction can be applied")
    if roles.get("kalman") and roles.get("velocity"):
        raise ConfigError(
            f"corrections: {roles['velocity']} and the Kalman filter {roles['kalman']} both correct the velocity; "
            "choose one"
        )
    zero_velocity = [n for n in names if n in ("ekf_zupt", "zupt")]
    if len(zero_velocity) > 1:
        raise ConfigError(f"corrections {zero_velocity}: two zero-velocity updates of the same filter; keep one")
    ins = orientation.name == "ins"
    if roles.get("kalman") and roles.get("heading") and not ins:
        raise ConfigError(
            f"corrections: {roles['heading']} inside the Kalman filter {roles['kalman']} observes the attitude "
            f"error, which only orientation: ins carries (got {orientation.name!r}); use orientation: {{type: ins}}"
        )
    for c in corrections:
        if c.name == "ekf_zupt" and not ins and (c.gyro_bias or c.zero_rate):
            raise ConfigError(
                f"ekf_zupt: gyro_bias and zero_rate need the attitude in the Kalman filter (orientation: ins); "
                f"with orientation {orientation.name!r} set gyro_bias: false and zero_rate: false"
            )


def versions() -> dict[str, str]:
    """Versions of footzoo and its numerical dependencies (for reproducibility)."""
    import platform

    import scipy

    return {
        "footzoo": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pandas": pd.__version__,
    }
