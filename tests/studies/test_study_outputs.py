"""A study's output files without pyarrow: a warning names what was not written, the CSV is written."""

from __future__ import annotations

import pandas as pd
import pytest

from footzoo.core.errors import FootzooWarning


def test_missing_pyarrow_warns_instead_of_silently_skipping_parquet(tmp_path, monkeypatch):
    from footzoo.studies.report import write_outputs

    def no_pyarrow(*args, **kwargs):
        raise ImportError("Unable to find a usable engine; tried using: 'pyarrow'")

    monkeypatch.setattr(pd.DataFrame, "to_parquet", no_pyarrow)
    table = pd.DataFrame({"run": ["a"], "base": ["yun2012"], "recording": ["r"], "metric": ["m"], "value": [1.0],
                          "error": [None]})
    with pytest.warns(FootzooWarning) as caught:
        write_outputs(table, [], [], tmp_path)
    for name in ("results", "trajectories", "roc"):
        assert any(f"pyarrow is not installed: {name}.parquet was not written" in str(w.message) for w in caught)
    assert (tmp_path / "results.csv").exists() and not (tmp_path / "results.parquet").exists()
