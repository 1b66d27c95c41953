"""Gait analysis on a pipeline's output: steps and their parameters."""

from .strides import segment_steps

__all__ = ["segment_steps"]
