"""Build hook: a wheel also carries the compiled kernels of the shipped configs.

Everything else is in setup.cfg. After the usual build, ``footzoo compile --ship`` runs every
pipeline config in ``configs/`` once on a short simulated walk (in two processes side by
side where there are two cores: see GROUPS) and writes the machine code numba produces into
``footzoo/_compiled`` of the build: an installed footzoo then loads it at its first
run instead of compiling (see footzoo/kernels/internals.py for when the code is valid). This needs the
build requirements of pyproject.toml. If it fails, or FOOTZOO_NO_PRECOMPILE=1 is set, the wheel is
built without them and kernels are compiled at first use, as in an editable install.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import find_packages, setup
from setuptools.command.build_py import build_py

#: The shipped configs in groups compiled side by side on a machine with several cores, each named by its file name
#: (``recommended_live``) or its family (the name up to the first ``_``: ``duong2015`` stands for its three configs).
#: A group's configs share the kernels one of them compiled first: every error-state config without a smoother runs
#: the same forward loop, so ``duong2015`` and ``nguyen2016`` are in one group (the second then takes 2 s, not
#: 20 s); the smoothed flagship's two loops (its forward pass and its replay) make it the longest alone. Measured on
#: 2 cores (each group's compile, side by side): 47 s and 49 s as below; 50 s and 63 s with ``nguyen2016`` beside
#: ``recommended``. A config this list does not name joins the first group.
GROUPS = (("duong2015", "nguyen2016", "recommended_live", "yun2012"), ("recommended", "huang2016"))


class BuildWithKernels(build_py):
    def run(self):
        super().run()
        build_lib = Path(self.build_lib).resolve()
        target = build_lib / "footzoo" / "_compiled"
        shutil.rmtree(target, ignore_errors=True)  # never a previous build's kernels (setuptools reuses build/)
        if getattr(self, "editable_mode", False) or os.environ.get("FOOTZOO_NO_PRECOMPILE", "") in ("1", "true", "yes"):
            return
        here = Path(__file__).resolve().parent
        builtin = here / "configs"
        configs = sorted(str(p) for p in builtin.glob("*.yaml") if not p.name.startswith("study_"))
        # the build first, then what pip's isolated build environment put on the path (its numba, numpy...)
        path = os.pathsep.join([str(build_lib), *filter(None, [os.environ.get("PYTHONPATH")]), *sys.path])
        env = {**os.environ, "PYTHONPATH": path, "FOOTZOO_DISABLE_JIT": ""}
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
        groups = [configs] if cores < 2 else [g for g in _groups(configs) if g]
        # one process per group, side by side, each into its own part of the folder (a numba index names its
        # data files by number: two processes must not write into one folder; footzoo reads every part)
        # not the live loop of a step-wise smoothed config (recommended_live): it would add about 14 s to this
        # build (35 s of CPU with the groups rebalanced for it), for a compile of 14 s at the first live run of
        # that one config
        procs = [subprocess.Popen([sys.executable, "-m", "footzoo", "compile", "--no-smoothed-live", "--ship",
                                   str(target / f"part-{k}" if len(groups) > 1 else target), *group],
                                  env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                 for k, group in enumerate(groups)]
        outputs = [(proc, *proc.communicate()) for proc in procs]
        failed = [(out, err) for proc, out, err in outputs if proc.returncode != 0]
        if failed:
            shutil.rmtree(target, ignore_errors=True)
            tail = (failed[0][1] or failed[0][0]).strip().splitlines()[-5:]
            print("footzoo: kernels not precompiled (compiled at first use instead):", *tail, sep="\n  ")
        else:
            for _, out, _ in outputs:
                print(out, end="")


def _groups(configs):
    """The configs in the groups of :data:`GROUPS`, by file name, else by family; others in the first group."""
    groups = [[] for _ in GROUPS]
    for c in configs:
        stem = Path(c).stem
        family = stem.split("_")[0]
        named = next((k for k, g in enumerate(GROUPS) if stem in g), None)
        groups[named if named is not None else next((k for k, g in enumerate(GROUPS) if family in g), 0)].append(c)
    return groups


# the shipped configs live in the repository's top-level configs/ and are installed as the data package
# footzoo.configs (footzoo.config.library finds them in either place). Every package's data is listed
# here, the one place: setup()'s package_data replaces setup.cfg's [options.package_data] as a whole.
PACKAGE_DATA = {"footzoo.configs": ["*.yaml"], "footzoo.samples": ["*.csv.gz", "*.md"],
                "footzoo.detectors": ["weights/*.npz"]}

setup(cmdclass={"build_py": BuildWithKernels},
      packages=[*find_packages(include=["footzoo", "footzoo.*"]), "footzoo.configs"],
      package_dir={"footzoo.configs": "configs"},
      package_data=PACKAGE_DATA)
