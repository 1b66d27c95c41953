"""Corrections applied to the navigation solution."""

from .ekf_zupt import EKFZUPT
from .hdr import HDR
from .zvu_dedrift import ZVUDedrift, zvu_dedrift

__all__ = ["EKFZUPT", "HDR", "ZVUDedrift", "zvu_dedrift"]
