"""Orientation filters: attitude (body -> NED quaternion) per sample."""

from .fqa import fqa
from .fqa_complementary import FQAComplementary

__all__ = ["FQAComplementary", "fqa"]
