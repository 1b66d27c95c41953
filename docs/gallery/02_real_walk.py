"""A real recording without reference: x-io's short walk

footzoo's built-in sample is x-io Technologies' Gait-Tracking example (NGIMU on the foot,
400 Hz, a closed walk of about 25 m). Without a reference the figures show the estimate
alone: the stride borders along the path, the height drift (the loop closes horizontally to
about 0.1 m but not vertically), the detector's statistic on a log scale and the stance it
produces. In the stride figure, outliers (a "stride" that includes a standing pause, say) are
set aside as triangles on the axis edge so that they do not flatten the other strides.
"""

import sys
from pathlib import Path

import footzoo
from footzoo.evaluation.plots import plot_run
from footzoo.io import builtin_sample

out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
rec = builtin_sample()
result = footzoo.Pipeline.from_yaml("yun2012").run(rec)
plot_run(result, out, rec, window=(18.0, 23.0))
