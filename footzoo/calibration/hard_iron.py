"""Magnetometer hard-iron offset fitted on the recording (Camps, Harasse & Monin 2009; Yun et al. 2012, Sec. VIII)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..core.errors import CalibrationWarning, user_stacklevel
from ..plugins.base import Calibration, Real, Vector
from ..plugins.registry import register


@dataclass(frozen=True)
class HardIronFit:
    """Result of :func:`fit_hard_iron` (magnetometer units unless said otherwise).

    Attributes
    ----------
    offset : (3,) ndarray
        Hard-iron offset ``b`` (FRD): the calibrated field is ``m − b``.
    radius : float
        Field strength ``|m − b|`` of the fitted sphere.
    offset_std : (3,) ndarray
        Standard error of ``offset`` from the least-squares fit over the inliers.
    spread : float
        Smallest eigenvalue of the covariance of the inliers' field directions ``(m − b)/|m − b|``
        (unitless, 0 … 1/3): how well the recording turned the sensor in the field.
    inliers : int
        Samples of the fit kept (of at most :data:`FIT_SAMPLES`; the rest deviate from the sphere
        by more than ``outlier_mads`` MADs: magnetic disturbances).
    residual : float
        Robust standard deviation (1.4826 MAD) of ``|m − b| − radius`` over the inliers.
    """

    offset: np.ndarray
    radius: float
    offset_std: np.ndarray
    spread: float
    inliers: int
    residual: float


def _sphere(mag: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """Least squares ``|m|² = 2 m·b + (r² − |b|²)`` (normal equations): offset, radius, offset standard error."""
    a = np.empty((len(mag), 4))
    a[:, :3] = 2.0 * mag
    a[:, 3] = 1.0
    y = np.einsum("ij,ij->i", mag, mag)
    ata = a.T @ a
    # minimum-norm solution: readings that never left a plane (one rotation axis) leave the
    # offset along its normal undetermined; the spread test then refuses the fit
    sol = np.linalg.lstsq(ata, a.T @ y, rcond=None)[0]
    b = sol[:3]
    r = float(np.sqrt(max(sol[3] + b @ b, 0.0)))
    s2 = float(np.sum((a @ sol - y) ** 2)) / max(len(mag) - 4, 1)
    return b, r, np.sqrt(np.clip(s2 * np.diag(np.linalg.pinv(ata))[:3], 0.0, None))


#: Samples a fit uses at most (drawn at random, reproducibly, from the whole recording): the
#: offset's standard error is then about σ / 40 for a magnetometer noise σ, far below any
#: hard-iron offset worth removing, and the fit costs the same on an hour as on a minute.
FIT_SAMPLES = 5_000


def fit_hard_iron(mag: np.ndarray, outlier_mads: float = 3.0, iterations: int = 10) -> HardIronFit:
    """Fit the hard-iron offset of a magnetometer from the constant strength of the field it measures.

    Whatever the sensor's attitude, an undisturbed, offset-free magnetometer measures a vector of
    one length, the local field strength: the readings lie on a sphere centred on the hard-iron
    offset. This is the offset-only case (unit scale factors, no cross-coupling) of Camps, Harasse &
    Monin's (2009) numerical calibration from the norm of the field, the in-situ calibration Yun
    et al. (2012, Sec. VIII) name as the remedy for the magnetometer bias their simulation finds to
    be a main source of position error. The sphere is fitted by linear least squares, then again
    on the samples within ``outlier_mads`` robust standard deviations of it (magnetic disturbances,
    whose strength differs, drop out), until the inliers no longer change.

    A long recording is fitted on :data:`FIT_SAMPLES` of its samples, drawn at random with a
    fixed seed (the same every run; random rather than evenly spaced, so that no sampling
    interval locks onto the gait cycle).

    Parameters
    ----------
    mag : (N, 3) ndarray
        Magnetometer readings (any unit), N ≥ 10.
    outlier_mads : float
        Inlier bound on ``| |m − b| − r |`` in robust standard deviations (1.4826 MAD).
    iterations : int
        Largest number of refits.

    Returns
    -------
    HardIronFit
    """
    mag = np.asarray(mag, dtype=float)
    if len(mag) > FIT_SAMPLES:
        mag = mag[np.sort(np.random.default_rng(0).choice(len(mag), FIT_SAMPLES, replace=False))]
    keep = np.ones(len(mag), dtype=bool)
    for _ in range(iterations):
        b, r, b_std = _sphere(mag[keep])
        dev = np.linalg.norm(mag - b, axis=1) - r
        centre = float(np.median(dev[keep]))  # disturbances pull the first sphere: judge from the typical sample
        mad = 1.4826 * float(np.median(np.abs(dev[keep] - centre)))
        new = np.abs(dev - centre) <= max(outlier_mads * mad, 1e-12 * r)
        if np.count_nonzero(new) < 10 or np.array_equal(new, keep):
            break
        keep = new
    u = mag[keep] - b
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    spread = float(np.linalg.eigvalsh(np.cov(u.T))[0])
    return HardIronFit(offset=b, radius=r, offset_std=b_std, spread=spread, inliers=int(np.count_nonzero(keep)),
                       residual=mad)


@register
class HardIron(Calibration):
    """Remove the magnetometer's hard-iron offset, fitted on the recording (in situ).

    Camps, Harasse & Monin 2009 (numerical calibration from the constant norm of the field),
    offset-only case; Yun, Calusdian, Bachmann & McGhee 2012, IEEE TIM 61(7), Sec. VIII (in-situ
    calibration [35] as the remedy for the sensor biases). See :func:`fit_hard_iron`: the readings
    of a magnetometer turned in a constant field lie on a sphere centred on its offset ``b``;
    every later stage (alignment, orientation filter) sees ``m − b``.

    A walk that turns (a loop, corners, a turn-around) rotates the foot enough; a straight walk
    does not. The fit is applied only when the inliers' field directions spread over more than
    ``min_spread`` (the smallest eigenvalue of their covariance), the readings lie on a sphere
    (their robust spread about it at most ``max_residual`` of the field strength: soft iron or
    magnetic disturbances nearby make an ellipsoid or a cloud, which an offset does not
    calibrate; Köroğlu's indoor walks give 20–30 %, the simulator 0.2 %) and the offset is
    smaller than the field; otherwise the magnetometer is left as it is, with a
    :class:`~footzoo.core.errors.CalibrationWarning` and the reason in ``report_``. Recordings without
    a magnetometer pass through unchanged.

    Parameters
    ----------
    offset : list of 3 floats, optional
        A known offset (magnetometer unit, FRD) to remove instead of fitting one (for example from
        a calibration recording); None: fit on this recording.
    min_spread : float
        Smallest accepted eigenvalue of the covariance of the field directions (unitless; 1/3 for
        directions all over the sphere, 0 for one direction).
    outlier_mads : float
        Samples deviating from the fitted sphere by more than this many robust standard
        deviations are magnetic disturbances and left out of the fit.
    max_residual : float
        Largest accepted robust standard deviation of ``|m − b|`` about the sphere, as a fraction
        of its radius (unitless).

    Attributes
    ----------
    acc_, gyr_ : (N, 3) ndarray
        The inputs (unchanged).
    mag_ : (N, 3) ndarray or None
        ``m − b`` (or the input when nothing was applied).
    fit_ : HardIronFit or None
        The fit (None with ``offset`` given or without a magnetometer).
    report_ : dict
        ``applied`` (bool), ``offset``, and ``reason`` when not applied; with a fit also
        ``radius``, ``offset_std``, ``spread``, ``inliers``.
    """

    name = "hard_iron"
    paper = ("Camps, Harasse & Monin 2009, Proc. IEEE EIT, 217-221 (offset-only); "
             "Yun et al. 2012, IEEE TIM 61(7), Sec. VIII")
    parameters = {
        "offset": Vector(3, "magnetometer unit", "a known offset b (FRD) to remove instead of fitting one",
                         optional=True, source="none: fitted on the recording"),
        "min_spread": Real("1", "[0, 1/3]", "smallest accepted eigenvalue of the field directions' covariance",
                           source="footzoo's", why="1/3 for directions all over the sphere, 0 for one direction"),
        "outlier_mads": Real("1", "(0, 100]", "samples off the sphere by more robust σ are left out of the fit",
                             source="footzoo's: 3 robust σ"),
        "max_residual": Real("1", "(0, 1]", "largest accepted robust σ about the sphere, a fraction of its radius",
                             source="footzoo's: Köroğlu's indoor walks give 20-30 %, the simulator 0.2 %"),
    }

    def __init__(self, offset: list[float] | None = None, min_spread: float = 0.01, outlier_mads: float = 3.0,
                 max_residual: float = 0.05):
        self.offset = offset
        self.min_spread = min_spread
        self.outlier_mads = outlier_mads
        self.max_residual = max_residual

    fits_on = ("mag",)

    def is_fitted(self) -> bool:
        """With ``offset`` given there is nothing to fit: it runs live as it is."""
        return self.offset is not None

    def fixed(self, report: dict) -> HardIron:
        """This calibration with the offset of an earlier fit (``report_``), for a live stream.

        A fit that was not applied (too little turning, disturbances) gives a zero offset: the
        magnetometer passes unchanged, as in the run the report comes from.
        """
        applied = bool(report.get("applied")) and report.get("offset") is not None
        offset = [float(v) for v in report["offset"]] if applied else [0.0, 0.0, 0.0]
        return HardIron(offset=offset, min_spread=self.min_spread, outlier_mads=self.outlier_mads,
                        max_residual=self.max_residual)

    def calibrate(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, mag: np.ndarray | None) -> HardIron:
        """Fit (or take) the offset and remove it from ``mag``."""
        self.acc_, self.gyr_, self.mag_, self.fit_ = acc, gyr, mag, None
        if mag is None:
            self.report_ = {"applied": False, "reason": "no magnetometer"}
            return self
        if self.offset is not None:
            self.mag_ = mag - np.asarray(self.offset)
            self.report_ = {"applied": True, "offset": list(self.offset)}
            return self
        fit = self.fit_ = fit_hard_iron(mag, self.outlier_mads)
        self.report_ = {"offset": fit.offset.tolist(), "radius": fit.radius, "offset_std": fit.offset_std.tolist(),
                        "spread": fit.spread, "inliers": fit.inliers, "fitted": min(len(mag), FIT_SAMPLES)}
        reason = None
        if fit.spread < self.min_spread:
            reason = (f"the sensor turned too little in the field for a fit (direction spread {fit.spread:.2g} < "
                      f"min_spread {self.min_spread:g}); a recording with turns or a loop fits, "
                      "a straight walk does not")
        elif not fit.residual <= self.max_residual * fit.radius:
            reason = (f"the readings lie on no sphere (spread about it {fit.residual / fit.radius:.1%} of the field, "
                      f"above max_residual {self.max_residual:.0%}): soft iron or magnetic disturbances, which an "
                      "offset does not calibrate")
        elif not np.linalg.norm(fit.offset) < fit.radius:
            reason = (f"the fitted offset ({np.linalg.norm(fit.offset):.3g}) is not smaller than the field "
                      f"({fit.radius:.3g}): the readings are no sphere (strong disturbances, or no magnetometer data)")
        self.report_["applied"] = reason is None
        if reason is not None:
            self.report_["reason"] = reason
            warnings.warn(f"hard_iron: magnetometer left uncalibrated: {reason}. Pass a known offset "
                          "(hard_iron: {offset: [x, y, z]}) or remove the calibration",
                          CalibrationWarning, stacklevel=user_stacklevel())
            return self
        self.mag_ = mag - fit.offset
        return self
