"""A run with ground truth: the simulator's figure-eight walk

The simulator (`footzoo.sim.simulate`) produces a foot-mounted IMU recording with the true
position, velocity, attitude and stance of every sample. The Duong & Suh 2015 pipeline
without distance sensors (`duong2015_zupt`: windowed detector, 9-state Kalman filter with
zero-velocity updates) runs on it; `plot_run` draws the
trajectory with numbered stride borders and the reference, the position error over time,
attitude, velocity and gait phase for a few strides (truth dashed), and the stride parameters
with the true stride lengths.
"""

import sys
from pathlib import Path

import footzoo
from footzoo.evaluation.plots import plot_run
from footzoo.sim import NoiseModel, simulate

out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
rec = simulate(path="figure_eight", rate=100.0, profile="physical", noise=NoiseModel(seed=3), seed=3)
result = footzoo.Pipeline.from_yaml("duong2015_zupt").run(rec)
plot_run(result, out, rec, window=(4.0, 8.0))
