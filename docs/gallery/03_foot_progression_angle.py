"""Foot progression angle (Huang et al. 2016) on a toe-out walk

The sensor sits yawed by 15° on the foot. A simulated calibration trial (standing, three slow
dorsi-/plantar-flexions) gives the foot vector (eq. 11); the `huang2016` pipeline then estimates
the foot progression angle of each stride of a walk with 12° toe-out. The FPA figure shows each
stride against the truth and the distribution.
"""

import sys
import tempfile
from pathlib import Path

import numpy as np

import footzoo
from footzoo.analysis import calibrate_foot_vector
from footzoo.evaluation.plots import fpa_figure, save
from footzoo.sim import NoiseModel, simulate, simulate_calibration

out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
mount_yaw = np.radians(15.0)
foot_yaml = Path(tempfile.mkdtemp()) / "foot.yaml"
calibrate_foot_vector(simulate_calibration(mount_yaw=mount_yaw, noise=NoiseModel(seed=5))).save(foot_yaml)
config = footzoo.config.load_yaml("huang2016")
config["analysis"][0]["calibration"] = str(foot_yaml)
rec = simulate(n_strides=30, rate=100.0, profile="physical", fpa=np.radians(12.0), mount_yaw=mount_yaw,
               noise=NoiseModel(seed=1), seed=1, clearance=0.12)
result = footzoo.Pipeline.from_dict(config).run(rec)
save(fpa_figure(result, rec), out / "fpa.png")
