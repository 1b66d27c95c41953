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
    # one warning for the one missing package, naming every file it costs
    missing = [str(w.message) for w in caught if "pyarrow is not installed" in str(w.message)]
    assert missing == ["pyarrow is not installed: results.parquet, trajectories.parquet, roc.parquet not written "
                       "(results.csv has the table; pip install 'footzoo[parquet]' or pyarrow to get them)"]
    assert (tmp_path / "results.csv").exists() and not (tmp_path / "results.parquet").exists()
