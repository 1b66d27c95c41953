"""Foot vector calibration (Huang et al. 2016, Sec. II-C, eqs. 11–12)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from ..core.atomic import write_text
from ..core.checks import check_vector
from ..core.data import Recording
from ..core.errors import ConfigError, RecordingError
from ..core.yamlsafe import load_file
from ..evaluation.metrics import intervals


@dataclass
class FootVector:
    """A foot vector in the sensor frame and how it was found.

    Attributes
    ----------
    vector : (3,) ndarray
        Unit foot vector ``f`` in the sensor (body, FRD) frame, toward the toe.
    gravity_axis : (3,) ndarray
        Unit gravity direction ``g`` in the sensor frame, foot flat (down).
    rotation_axis : (3,) ndarray
        Unit common rotation axis ``k`` of the flexions (pointing to the sensor's right).
    still, flex : tuple of float
        The periods used (s).
    """

    vector: np.ndarray
    gravity_axis: np.ndarray
    rotation_axis: np.ndarray
    still: tuple[float, float] = (float("nan"), float("nan"))
    flex: tuple[float, float] = (float("nan"), float("nan"))

    def save(self, path: str | Path) -> Path:
        """Write as YAML (loaded by ``huang_fpa``'s ``calibration``)."""
        return write_text(path, yaml.safe_dump({
            "foot_vector": [float(v) for v in self.vector],
            "gravity_axis": [float(v) for v in self.gravity_axis],
            "rotation_axis": [float(v) for v in self.rotation_axis],
            "still_s": [float(v) for v in self.still], "flex_s": [float(v) for v in self.flex],
            "frame": "sensor body frame (FRD)", "method": "Huang et al. 2016 eq. 11: f = k x g",
        }, sort_keys=False), what="foot-vector calibration")

    @classmethod
    def load(cls, path: str | Path) -> FootVector:
        """Read a file written by :meth:`save`."""
        p = Path(path)
        data = load_file(p, ConfigError, "foot-vector calibration (create it with footzoo calibrate)") or {}
        if not isinstance(data, dict) or "foot_vector" not in data:
            raise ConfigError(f"{p}: no 'foot_vector' entry; was it written by footzoo calibrate?")
        try:
            v = np.asarray(check_vector("foot_vector", data["foot_vector"], nonzero=True))
            g = np.asarray(check_vector("gravity_axis", data.get("gravity_axis", [0, 0, 1]), nonzero=True))
            k = np.asarray(check_vector("rotation_axis", data.get("rotation_axis", [0, 1, 0]), nonzero=True))
            periods = [data.get(key, (np.nan, np.nan)) for key in ("still_s", "flex_s")]
            for key, value in zip(("still_s", "flex_s"), periods, strict=True):
                if not isinstance(value, (list, tuple)) or len(value) != 2 or not all(
                        isinstance(x, (int, float)) and not isinstance(x, bool) for x in value):
                    raise ConfigError(f"{key} must be [t0, t1] in s, got {value!r}")
        except ConfigError as err:
            raise ConfigError(f"{p}: {err}; recreate the file with footzoo calibrate") from None
        return cls(v / np.linalg.norm(v), g, k, tuple(float(x) for x in periods[0]),
                   tuple(float(x) for x in periods[1]))


def calibrate_foot_vector(
    rec: Recording,
    still: tuple[float, float] | None = None,
    flex: tuple[float, float] | None = None,
    still_duration: float = 1.0,
    max_gyr: float = 0.1,
) -> FootVector:
    """Foot vector ``f = k × g`` from a still period and slow dorsi-/plantar-flexions (eq. 11).

    Parameters
    ----------
    rec : Recording
        The calibration recording.
    still : (t0, t1), optional
        Foot flat and still (s). Default: the first run of at least
        ``still_duration`` s with |ω| ≤ ``max_gyr``.
    flex : (t0, t1), optional
        The flexions (s). Default: from the end of that still period to the
        start of the next such still run (or the end of the recording).

    The gravity axis ``g`` is the mean specific force's opposite (down, in the
    sensor frame); the common rotation axis ``k`` is the principal direction of
    the angular rate during the flexions (eigenvector of ``Σ ω ωᵀ`` with the
    largest eigenvalue), its sign chosen to point to the sensor's right (+y),
    which assumes the sensor's y axis within 90° of the foot's right side.
    """
    if not isinstance(rec, Recording):
        raise RecordingError(f"calibrate_foot_vector expects a footzoo Recording, got {type(rec).__name__}: build one "
                             "with footzoo.load(path) or footzoo.Recording(t=..., acc=..., gyr=...)")
    t = rec.t
    if still is None or flex is None:
        runs = intervals(np.linalg.norm(rec.gyr, axis=1) <= max_gyr)
        long = [(int(a), int(b)) for a, b in runs if t[b - 1] - t[a] >= still_duration]
        if not long:
            raise RecordingError(
                f"no still period of {still_duration} s (|ω| ≤ {max_gyr} rad/s) in the calibration recording; "
                "give the periods with --still T0 T1 --flex T0 T1"
            )
        if still is None:
            still = (float(t[long[0][0]]), float(t[long[0][1] - 1]))
        if flex is None:
            after = [a for a, _ in long if t[a] > still[1]]
            flex = (still[1], float(t[after[0]]) if after else float(t[-1]))
    ws = (t >= still[0]) & (t <= still[1])
    wf = (t >= flex[0]) & (t <= flex[1])
    if ws.sum() < 2 or wf.sum() < 10:
        raise RecordingError(
            f"foot-vector calibration needs a still period and a flexion period with samples; got still {still} s "
            f"({int(ws.sum())} samples) and flex {flex} s ({int(wf.sum())} samples): give them with --still/--flex"
        )
    g = -rec.acc[ws].mean(axis=0)
    g = g / np.linalg.norm(g)
    w = rec.gyr[wf]
    if np.sqrt(np.mean(np.sum(w**2, axis=1))) < 0.05:
        raise RecordingError(f"no rotation in the flexion period {flex} s (rms rate below 0.05 rad/s)")
    eigval, eigvec = np.linalg.eigh(w.T @ w)
    k = eigvec[:, -1]
    if k[1] < 0:
        k = -k
    f = np.cross(k, g)
    f = f / np.linalg.norm(f)
    return FootVector(f, g, k, tuple(still), tuple(flex))


#: What makes a recording a calibration trial (Huang et al. 2016, Sec. III: stand still, slow flexions
#: about the ankle, stand): the flexions' peak angular rate (rad/s), the 95th percentile of the specific
#: force's departure from gravity during them (m/s², the ankle stays put), and the share of the angular
#: rate's energy about one axis (a flexion turns about the ankle's axis only).
CALIBRATION_TRIAL = {"max_flex_rate": 3.0, "max_acc_departure": 2.5, "min_axis_share": 0.9}


def calibration_trial_problems(rec: Recording, fv: FootVector, gravity: float = 9.81) -> list[str]:
    """Why ``rec`` is not a calibration trial (empty when it is one), judged on the periods ``fv`` used.

    A walk has a still start too, but its "flexion period" holds swings: angular rates of 5–10 rad/s
    and heel strikes far from 1 g; the rules are in :data:`CALIBRATION_TRIAL`.
    """
    t = rec.t
    wf = (t >= fv.flex[0]) & (t <= fv.flex[1])
    w, a = rec.gyr[wf], rec.acc[wf]
    out = []
    peak = float(np.max(np.linalg.norm(w, axis=1)))
    if peak > CALIBRATION_TRIAL["max_flex_rate"]:
        out.append(f"the foot turns at up to {peak:.1f} rad/s in the flexion period "
                   f"{fv.flex[0]:.2f}-{fv.flex[1]:.2f} s;"
                   f" slow flexions stay below {CALIBRATION_TRIAL['max_flex_rate']:g} rad/s")
    departure = float(np.percentile(np.abs(np.linalg.norm(a, axis=1) - gravity), 95))
    if departure > CALIBRATION_TRIAL["max_acc_departure"]:
        out.append(f"the specific force departs from gravity by {departure:.1f} m/s² (95th percentile) in the flexion "
                   f"period: the foot moves (walks?) instead of pivoting about the ankle "
                   f"(at most {CALIBRATION_TRIAL['max_acc_departure']:g} m/s²)")
    eig = np.linalg.eigvalsh(w.T @ w)
    share = float(eig[-1] / eig.sum()) if eig.sum() > 0 else 0.0
    if share < CALIBRATION_TRIAL["min_axis_share"]:
        out.append(f"only {share:.0%} of the rotation is about one axis; flexions turn about the ankle's axis "
                   f"(at least {CALIBRATION_TRIAL['min_axis_share']:.0%})")
    return out
