"""Shared fixtures: the real recordings in ../shared/data (skipped when absent); the wheel's compiled kernels."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from footzoo.kernels.installed import use_installed_kernels

# the installed wheel's machine code, for the checkout's footzoo the tests import (and their subprocesses)
use_installed_kernels()


def made_once(tmp_path_factory: pytest.TempPathFactory, name: str, make) -> Path:
    """A folder ``make(folder)`` fills once per test session, shared by every xdist worker (read it, never write).

    The module-scoped fixtures that compile kernels in new processes (10 s each) would otherwise be made
    once by each worker that runs one of their tests. The first worker makes the folder under a lock in
    the session's shared temporary folder; the others wait for it and reuse it.
    """
    import fcntl
    import shutil

    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent  # the folder all workers' temporary folders are in
    folder, done = root / f"made-once-{name}", root / f"made-once-{name}.done"
    with open(root / f"made-once-{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not done.exists():
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir()
            make(folder)
            done.touch()
    return folder


#: The mark of the tests that run a study on :func:`process_cluster`: CI's slow run (``--dist loadgroup``) gives them
#: all to one xdist worker, which starts the cluster once for them.
ON_PROCESS_CLUSTER = pytest.mark.xdist_group("dask-processes")


@pytest.fixture(scope="session")
def process_cluster():
    """A local Dask cluster of two worker processes, one thread each, shared by a worker's tests that need one.

    Starting a cluster and importing footzoo in its two processes costs several seconds; each test that
    compares a study on a cluster with the study run in this process would pay it again. The tests use a
    cluster of processes as a user's would be (plug-in files imported in other processes, results pickled).
    """
    import logging

    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                                  silence_logs=logging.CRITICAL) as cluster:
        yield cluster


# Warning filters (pytest.mark.filterwarnings) for warnings that are the right outcome of a test's input but not what
# the test checks; each test that uses one says why. A footzoo warning no test expects fails the run (pyproject.toml).

#: A pipeline that fits a hard-iron calibration (yun2012's) on a walk that does not turn in the field (a straight
#: simulated walk: its field directions lie in one plane, the offset along the normal is undetermined) leaves the
#: magnetometer uncalibrated and says so.
HARD_IRON_NOT_FITTED = "ignore:.*hard_iron. magnetometer left uncalibrated:footzoo.core.errors.CalibrationWarning"
#: A real recording (x-io's walk, PyShoe's trials) has gaps in its time stamps; the reader bridges and reports them.
GAPS_BRIDGED = "ignore:.*bridged [0-9]+ gap:footzoo.core.errors.FootzooWarning"
#: A detector misses the stances of an unusual motion on a real trial; the stance guard marks them and says so.
STANCES_GUARDED = "ignore:.*found no stance for:footzoo.core.errors.GuardWarning"
#: A detector at an edge of its range takes every sample for stance, the swings included; the run says so.
ALL_STANCE = "ignore:.*of the samples after the still start for stance, while:footzoo.core.errors.SensorWarning"
#: PyShoe's 2018-02-22 trial has its sensor mounted upside down; the mounting report says so.
UPSIDE_DOWN_TRIAL = "ignore:recording .2018-02-22-10-09-36.. the sensor's y axis:footzoo.core.errors.SensorWarning"
#: The mounting report finds the x axis of Köroğlu's sensors (experiments 31-33) pointing backwards.
KOROGLU_MOUNTING = ("ignore:recording .SensorConnectData_3[1-3].. the foot walks backwards:"
                    "footzoo.core.errors.SensorWarning")
#: PyShoe's walking trials circle a small room: huang_fpa finds most footprints on turns and says so.
FPA_ON_TURNS = "ignore:huang_fpa. recording .* the walk turns at:footzoo.core.errors.FootzooWarning"
#: A sensor turned on the foot on purpose: huang_fpa's straight-walk FPA is no foot's, and it says so.
FPA_OF_THE_SENSOR = "ignore:huang_fpa. recording .* not along the foot:footzoo.core.errors.FootzooWarning"

#: The shared recordings: ../shared/data next to the checkout, or the folder named by FOOTZOO_DATA.
DATA = Path(os.environ.get("FOOTZOO_DATA") or Path(__file__).resolve().parents[1].parent / "shared" / "data")


def load_benchmark(name: str):
    """The script ``benchmarks/<name>.py`` imported as a module (the benchmarks are scripts, not a package)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(f"{name}_benchmark", Path(__file__).resolve().parents[1] /
                                                  "benchmarks" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def data_file(*parts: str) -> Path:
    """Path of a file under ../shared/data, skipping the test when it is absent."""
    p = DATA.joinpath(*parts)
    if not p.exists():
        pytest.skip(f"shared data not available: {p}")
    return p


def pytest_collection_modifyitems(config, items):
    """Skip ``nightly`` tests (long fuzz profiles) unless ``-m nightly`` or ``FOOTZOO_NIGHTLY=1``."""

    if os.environ.get("FOOTZOO_NIGHTLY") == "1" or "nightly" in (config.getoption("-m") or ""):
        return
    skip = pytest.mark.skip(reason="nightly profile: run with -m nightly or FOOTZOO_NIGHTLY=1")
    for item in items:
        if "nightly" in item.keywords:
            item.add_marker(skip)
