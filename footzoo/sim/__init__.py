"""Gait simulator with ground truth (Yun et al. 2012, Sec. III, extended).

* :func:`simulate` — foot-mounted IMU walks (straight, rectangle, track,
  figure eight, mixed speeds), paper or physical stance kinematics, interval or
  instantaneous sampling, eq. 18 noise, magnetometer with disturbances, toe-in/out,
  sensor mounting offsets, VL6180-like distance sensors.
* :func:`simulate_pendulum` — the pendulum of eqs. 11–13 for orientation filters.
"""

from .gait import FootGeometry, Footstep, GaitTimeline, StrideSpec
from .mounting import axis_map_name, proper_axis_permutations, remount
from .pendulum import simulate_pendulum
from .scenarios import SPEEDS, simulate, simulate_calibration
from .sensors import DistanceSensors, MagneticDisturbance, NoiseModel, magnetic_field_ned

__all__ = [
    "SPEEDS",
    "DistanceSensors",
    "FootGeometry",
    "Footstep",
    "GaitTimeline",
    "MagneticDisturbance",
    "NoiseModel",
    "StrideSpec",
    "axis_map_name",
    "magnetic_field_ned",
    "proper_axis_permutations",
    "remount",
    "simulate",
    "simulate_calibration",
    "simulate_pendulum",
]
