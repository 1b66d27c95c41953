"""Stance/swing detectors."""

from .adaptive_shoe import AdaptiveSHOE
from .amvd import AMVD
from .angular_rate_fsm import AngularRateFSM
from .ared import ARED
from .dgp import DGP
from .learned_zv import LearnedZV
from .mbgtd import MBGTD
from .oracle import Oracle
from .runs import dated_and_online_states
from .shoe import SHOE, HuangStance
from .windowed import Windowed

__all__ = ["AMVD", "ARED", "DGP", "MBGTD", "SHOE", "AdaptiveSHOE", "AngularRateFSM", "HuangStance", "LearnedZV",
           "Oracle", "Windowed", "dated_and_online_states"]
