"""Corrections applied to the navigation solution."""

from .zvu_dedrift import ZVUDedrift, zvu_dedrift

__all__ = ["ZVUDedrift", "zvu_dedrift"]
