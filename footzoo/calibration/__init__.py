"""In-situ sensor calibrations, fitted on the recording and applied before every other stage."""

from .hard_iron import HardIron, fit_hard_iron

__all__ = ["HardIron", "fit_hard_iron"]
