"""Strapdown mechanisation and (later) the error-state Kalman core."""

from .strapdown import integrate_position, integrate_velocity, motion_acceleration, sample_intervals

__all__ = ["integrate_position", "integrate_velocity", "motion_acceleration", "sample_intervals"]
