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
