"""Canonical CSV/Parquet: columns ``t, acc_x..z, gyr_x..z[, mag_x..z][, dist_*][, true_*]``.

SI units and FRD axes unless declared otherwise (``acc_unit``, ``gyr_unit``).
A file written by ``footzoo simulate`` also carries its ground truth in
``true_*`` columns, a sidecar ``<file>.meta.yaml`` (metadata and the
``closed_loop`` marker) and the true steps in ``<file>.steps.csv`` (every true
stride: its row count becomes ``truth.stride_count``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd
import yaml

from ..data import Recording
from ..errors import FormatError


def matches(header: str) -> bool:
    """True for a canonical CSV header."""
    cols = [c.strip() for c in header.split(",")]
    return "t" in cols and "acc_x" in cols and "gyr_x" in cols


def read(path: Path, **options: Any) -> Recording:
    """Read a canonical CSV or Parquet file (options go to ``Recording.from_dataframe``)."""
    try:
        if path.suffix.lower() in (".parquet", ".pq"):
            df = pd.read_parquet(path)
        else:
            df = pd.read_csv(path, comment="#")
    except (ValueError, OSError, pd.errors.ParserError) as err:
        raise FormatError(f"{path}: cannot read as canonical CSV/Parquet: {err}") from None
    meta: dict[str, Any] = {"name": path.stem, "source": str(path), "format": "canonical"}
    sidecar = path.with_name(path.name + ".meta.yaml")
    extra = yaml.safe_load(sidecar.read_text()) if sidecar.exists() else {}
    meta.update(extra.get("meta", {}) if isinstance(extra, dict) else {})
    rec = Recording.from_dataframe(df, meta=meta, **options)
    if rec.truth is not None and isinstance(extra, dict):
        rec.truth.closed_loop = bool(extra.get("closed_loop", False))
        steps = path.with_name(path.name + ".steps.csv")
        if steps.exists():
            rec.truth.steps = pd.read_csv(steps)
            rec.truth.stride_count = len(rec.truth.steps)  # the sidecar lists every true stride
        if meta.get("source") == "footzoo.sim":
            rec.truth.source = "simulator"
    return rec


def write(rec: Recording, path: str | Path, closed_loop: bool = False) -> Path:
    """Write a recording (with truth columns) as canonical CSV or Parquet plus a sidecar."""
    p = Path(path)
    df = rec.to_dataframe()
    if p.suffix.lower() in (".parquet", ".pq"):
        df.to_parquet(p, index=False)
    else:
        df.to_csv(p, index=False, float_format="%.9g")
    meta = {k: v for k, v in rec.meta.items() if isinstance(v, (str, int, float, bool))}
    side = {"meta": meta, "closed_loop": bool(closed_loop or (rec.truth is not None and rec.truth.closed_loop))}
    p.with_name(p.name + ".meta.yaml").write_text(yaml.safe_dump(side))
    if rec.truth is not None and rec.truth.steps is not None:
        rec.truth.steps.to_csv(p.with_name(p.name + ".steps.csv"), index=False, float_format="%.9g")
    return p
