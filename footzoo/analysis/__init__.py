"""Gait analysis on a pipeline's output: strides, foot vector, foot progression angle."""

from .foot_vector import FootVector, calibrate_foot_vector
from .fpa import HuangFPA
from .strides import segment_steps

__all__ = ["FootVector", "HuangFPA", "calibrate_foot_vector", "segment_steps"]
