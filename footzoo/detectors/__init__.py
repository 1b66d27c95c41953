"""Stance/swing detectors."""

from .angular_rate_fsm import AngularRateFSM
from .dgp import DGP
from .oracle import Oracle
from .runs import dated_and_online_states
from .shoe import SHOE, HuangStance
from .windowed import Windowed

__all__ = ["DGP", "SHOE", "AngularRateFSM", "HuangStance", "Oracle", "Windowed", "dated_and_online_states"]
