"""Corrections applied to the navigation solution."""

from .ekf_zupt import EKFZUPT, ZUPT
from .hdr import HDR
from .height import HeightDistance, HeightFlatFloor, load_calibration, save_calibration
from .height_level import HeightLevel
from .rolling_stance import RollingStance
from .zvu_dedrift import ZVUDedrift, zvu_dedrift

__all__ = [
    "EKFZUPT",
    "HDR",
    "ZUPT",
    "HeightDistance",
    "HeightFlatFloor",
    "HeightLevel",
    "RollingStance",
    "ZVUDedrift",
    "load_calibration",
    "save_calibration",
    "zvu_dedrift",
]
