"""ARED: the angular rate energy detector (ARE) of Skog et al. 2010."""

from __future__ import annotations

import numpy as np

from ..plugins.registry import register
from .skog import FUSED_TESTS, SkogTest
from .windows import ARE_TEST


@register
class ARED(SkogTest):
    """Zero velocity from the angular rate energy detector (ARE).

    Skog, Händel, Nilsson & Rantakokko, IEEE TBME 57(11), 2010, Sec. III (named
    ARED in PyShoe, Wagstaff et al. 2017):
    T_k = (1/σ_ω²) · (1/W) Σ ‖y_ω,l‖²: the foot is still when it does not
    rotate; it is blind to translation without rotation. Window and σ defaults
    as for ``shoe`` (0.025 s, σ_ω = 0.1 °/s; σ_a unused); the default γ is
    footzoo's, chosen by cross-validation over PyShoe's motion classes (walking, running, slow, inverted; PyShoe's
    2-D error with the ``yun2012`` and ``duong2015_zupt`` pipelines), never per
    trial. T is in units of σ_ω²: γ = 3e4 is an RMS rate of about 0.3 rad/s.

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

    name = "ared"
    paper = "Skog et al. 2010, IEEE TBME 57(11), Sec. III (angular rate energy detector (ARE))"
    parameters = {"threshold": SkogTest.parameters["threshold"].replace(
        source="footzoo's: cross-validated over PyShoe's motion classes (the paper tunes γ per data set)")}

    def __init__(self, threshold: float = 3e4, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1))):
        super().__init__(threshold, window, sigma_a, sigma_g)

    def test(self, m: np.ndarray) -> np.ndarray:
        """T_k from the window moments."""
        return m[:, 4] / self.sigma_g**2


FUSED_TESTS[ARED.test] = ARE_TEST
