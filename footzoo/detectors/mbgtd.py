"""MBGTD: the acceleration magnitude detector (MAG) of Skog et al. 2010."""

from __future__ import annotations

import numpy as np

from ..plugins.registry import register
from .skog import FUSED_TESTS, SkogTest
from .windows import MAG_TEST


@register
class MBGTD(SkogTest):
    """Zero velocity from the acceleration magnitude detector (MAG).

    Skog, Händel, Nilsson & Rantakokko, IEEE TBME 57(11), 2010, Sec. III (named
    MBGTD in PyShoe, Wagstaff et al. 2017):
    T_k = (1/σ_a²) · (1/W) Σ (‖y_a,l‖ − g)²: the specific force has the
    magnitude of gravity. It ignores the gyro and misses motion at constant
    ‖y_a‖. Window and σ defaults as for ``shoe`` (0.025 s, σ_a = 0.01 m/s²,
    σ_ω = 0.1 °/s, unused); the default γ is footzoo's,
    chosen by cross-validation over PyShoe's motion classes (walking, running, slow, inverted; PyShoe's
    2-D error with the ``yun2012`` and ``duong2015_zupt`` pipelines), never per
    trial. T is in units of σ_a²: γ = 1e2 is an RMS deviation of ‖y_a‖ from g of
    about 0.1 m/s² (30 scores slightly better on PyShoe but is below the simulated sensor's noise).

    Parameters
    ----------
    threshold : float
        γ (dimensionless).
    window : float
        W (s).
    sigma_a : float
        Accelerometer noise σ_a (m/s²).
    sigma_g : float
        Gyro noise σ_ω (rad/s).
    """

    name = "mbgtd"
    paper = "Skog et al. 2010, IEEE TBME 57(11), Sec. III (acceleration magnitude detector (MAG))"
    parameters = {"threshold": SkogTest.parameters["threshold"].replace(
        source="footzoo's: cross-validated over PyShoe's motion classes (the paper tunes γ per data set)")}

    def __init__(self, threshold: float = 1e2, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1))):
        super().__init__(threshold, window, sigma_a, sigma_g)

    def test(self, m: np.ndarray) -> np.ndarray:
        """T_k from the window moments."""
        return m[:, 5] / self.sigma_a**2


FUSED_TESTS[MBGTD.test] = MAG_TEST
