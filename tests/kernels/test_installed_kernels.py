"""The installed wheel's machine code covers the shipped configs' batch runs, and their live runs but the step-wise one.

Runs only beside a wheel install (``pip install .``, as CI does): an editable install ships no kernels.
"""

import json
import os
import subprocess
import sys

import pytest

from footzoo.kernels import jit as _jit
from footzoo.kernels.installed import installed_kernels

pytestmark = [pytest.mark.skipif(not _jit.HAVE_NUMBA, reason="needs numba"),
              pytest.mark.skipif(installed_kernels() is None, reason="no installed wheel with compiled kernels "
                                 "(an editable install): pip install . ships them")]

# every shipped pipeline config, batch and (where it can run) live in packets and sample by sample, on walks
# that are not those the wheel was compiled on (with every sensor, with none, frozen as a study's, and with an
# accelerometer the run rescales); print the footzoo kernels numba compiled for each run
RUN = """
import json, warnings
warnings.simplefilter("ignore")
from numba.core import event
import footzoo
from footzoo.config.library import names
from footzoo.sim import simulate
compiled = {}
class Listener(event.Listener):
    def on_start(self, ev):
        d = ev.data.get("dispatcher")
        if d is not None and getattr(d.py_func, "__module__", "").startswith("footzoo"):
            compiled.setdefault(RUN, []).append(d.py_func.__qualname__)
    def on_end(self, ev):
        pass
recordings = [simulate(n_strides=4, rate=200.0, profile="physical", distance_sensors=True),
              simulate(n_strides=4, rate=200.0, profile="physical", magnetometer=False)]
# as a study gives it (every array frozen), and read 5 % high (the run rescales the accelerometer: a writable copy)
frozen, high = (simulate(n_strides=4, rate=200.0, profile="physical", magnetometer=False) for _ in range(2))
for a in (frozen.t, frozen.acc, frozen.gyr):
    a.flags.writeable = False
high.acc *= 1.05
recordings += [frozen, high]
with event.install_listener("numba:compile", Listener()):
    for NAME in names("pipeline"):
        p = footzoo.Pipeline.from_yaml(NAME)
        for rec in recordings if "distance" not in json.dumps(p.to_dict()) else recordings[:1]:
            RUN = NAME + " batch"
            p.run(rec)
            if not p.live_problems() and p.smoother == "none":  # the step-wise smoother's live loop is not shipped
                RUN = NAME + " live"
                footzoo.Stream(p, rate=rec.rate).run(rec, chunk=[60, 1])
print(json.dumps(compiled))
"""


@pytest.mark.slow  # a new process loads every shipped config's kernels (about 4 s)
def test_no_shipped_config_compiles_a_kernel_in_a_batch_run_or_live(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PYTHONWARNINGS": "ignore"}
    env.pop("NUMBA_DISABLE_JIT", None)
    proc = subprocess.run([sys.executable, "-c", RUN], env=env, capture_output=True, text=True, timeout=600,
                          cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert json.loads(proc.stdout.strip().splitlines()[-1]) == {}
    assert not any((tmp_path / "cache").rglob("*.nbi"))  # nothing compiled, so nothing cached
