"""Stance/swing detectors."""

from .angular_rate_fsm import AngularRateFSM
from .runs import dated_and_online_states

__all__ = ["AngularRateFSM", "dated_and_online_states"]
