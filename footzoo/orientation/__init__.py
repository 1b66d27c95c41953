"""Orientation filters: attitude (body -> NED quaternion) per sample."""

from .fqa import fqa
from .fqa_complementary import FQAComplementary
from .ins import INS
from .madgwick import Madgwick

__all__ = ["INS", "FQAComplementary", "Madgwick", "fqa"]
