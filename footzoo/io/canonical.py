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

from ..core.checks import check_bool
from ..core.data import Recording
from ..core.errors import FormatError
from ..core.yamlsafe import load_file

#: Float format of every CSV footzoo writes: 17 significant digits reload to the same double.
FLOAT_FORMAT = "%.17g"
#: ``pd.read_csv`` options that parse those digits back exactly (pandas 3 does by default).
EXACT_CSV: dict[str, Any] = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}


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
            df = pd.read_csv(path, comment="#", **EXACT_CSV)
    except UnicodeDecodeError as err:
        raise FormatError(f"{path}: not UTF-8 text (byte offset {err.start}); is it a CSV file?") from None
    except (ValueError, OSError, pd.errors.ParserError) as err:
        raise FormatError(f"{path}: cannot read as canonical CSV/Parquet: {err}") from None
    meta: dict[str, Any] = {"name": path.stem, "source": str(path), "format": "canonical"}
    sidecar = path.with_name(path.name + ".meta.yaml")
    extra = load_file(sidecar, FormatError, "metadata sidecar") if sidecar.exists() else {}
    extra = {} if extra is None else extra
    fix = f"fix or delete {sidecar.name} (footzoo simulate writes it: meta: {{...}}, closed_loop: true|false)"
    if not isinstance(extra, dict):
        raise FormatError(f"{sidecar}: expected a mapping with 'meta' and 'closed_loop', got {extra!r:.80}; {fix}")
    if not isinstance(extra.get("meta", {}) or {}, dict):
        raise FormatError(f"{sidecar}: 'meta' must be a mapping, got {extra['meta']!r:.80}; {fix}")
    closed_loop = extra.get("closed_loop", False)
    if not isinstance(closed_loop, bool):
        raise FormatError(f"{sidecar}: closed_loop must be true or false, got {closed_loop!r}; {fix}")
    meta.update(extra.get("meta") or {})
    rec = Recording.from_dataframe(df, meta=meta, **options)
    if rec.truth is not None:
        rec.truth.closed_loop = closed_loop
        steps = path.with_name(path.name + ".steps.csv")
        if steps.exists():
            try:
                rec.truth.steps = pd.read_csv(steps, **EXACT_CSV)
            except (UnicodeDecodeError, ValueError, pd.errors.ParserError) as err:
                raise FormatError(f"{steps}: cannot read the true steps: {err}; fix or delete the file") from None
            rec.truth.stride_count = len(rec.truth.steps)  # the sidecar lists every true stride
        if meta.get("source") == "footzoo.sim":
            rec.truth.source = "simulator"
    return rec


def write(rec: Recording, path: str | Path, closed_loop: bool = False) -> Path:
    """Write a recording (with truth columns) as canonical CSV or Parquet plus a sidecar."""
    p = Path(path)
    closed_loop = check_bool("closed_loop", closed_loop)
    df = rec.to_dataframe()
    if p.suffix.lower() in (".parquet", ".pq"):
        df.to_parquet(p, index=False)
    else:
        df.to_csv(p, index=False, float_format=FLOAT_FORMAT)
    meta = {k: v for k, v in rec.meta.items() if isinstance(v, (str, int, float, bool))}
    side = {"meta": meta, "closed_loop": bool(closed_loop or (rec.truth is not None and rec.truth.closed_loop))}
    p.with_name(p.name + ".meta.yaml").write_text(yaml.safe_dump(side))
    if rec.truth is not None and rec.truth.steps is not None:
        rec.truth.steps.to_csv(p.with_name(p.name + ".steps.csv"), index=False, float_format=FLOAT_FORMAT)
    return p
