"""Build hook: a wheel also carries the compiled kernels of the shipped configs.

Everything else is in setup.cfg. After the usual build, ``footzoo compile --ship`` runs every
pipeline config in ``footzoo/config/builtin/`` once on a short simulated walk and writes the machine code numba
produces into ``footzoo/_compiled`` of the build: an installed footzoo then loads it at its first
run instead of compiling (see footzoo/kernels/cache.py for when the code is valid). This needs the
build requirements of pyproject.toml. If it fails, or FOOTZOO_NO_PRECOMPILE=1 is set, the wheel is
built without them and kernels are compiled at first use, as in an editable install.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildWithKernels(build_py):
    def run(self):
        super().run()
        if getattr(self, "editable_mode", False) or os.environ.get("FOOTZOO_NO_PRECOMPILE", "") in ("1", "true", "yes"):
            return
        build_lib = Path(self.build_lib).resolve()
        target = build_lib / "footzoo" / "_compiled"
        shutil.rmtree(target, ignore_errors=True)
        here = Path(__file__).resolve().parent
        configs = sorted(str(p) for p in (here / "footzoo" / "config" / "builtin").glob("*.yaml") if not p.name.startswith("study_"))
        # the build first, then what pip's isolated build environment put on the path (its numba, numpy...)
        path = os.pathsep.join([str(build_lib), *filter(None, [os.environ.get("PYTHONPATH")]), *sys.path])
        env = {**os.environ, "PYTHONPATH": path, "FOOTZOO_DISABLE_JIT": ""}
        cmd = [sys.executable, "-m", "footzoo", "compile", "--ship", str(target), *configs]
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if proc.returncode != 0:
            shutil.rmtree(target, ignore_errors=True)
            tail = (proc.stderr or proc.stdout).strip().splitlines()[-5:]
            print("footzoo: kernels not precompiled (compiled at first use instead):", *tail, sep="\n  ")
        else:
            print(proc.stdout, end="")


setup(cmdclass={"build_py": BuildWithKernels})
