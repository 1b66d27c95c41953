"""Shared fixtures: the real recordings in ../shared/data (skipped when absent)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

#: The shared recordings: ../shared/data next to the checkout, or the folder named by FOOTZOO_DATA.
DATA = Path(os.environ.get("FOOTZOO_DATA") or Path(__file__).resolve().parents[1].parent / "shared" / "data")


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
