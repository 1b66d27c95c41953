"""Gait analysis on a pipeline's output: strides and gait events, foot vector, foot progression angle."""

from .foot_vector import FootVector, calibrate_foot_vector
from .fpa import HuangFPA
from .gait_events import GaitEvents, detect_gait_events
from .strides import STEP_COLUMNS, real_stances, segment_steps

__all__ = ["STEP_COLUMNS", "FootVector", "GaitEvents", "HuangFPA", "calibrate_foot_vector", "detect_gait_events",
           "real_stances", "segment_steps"]
