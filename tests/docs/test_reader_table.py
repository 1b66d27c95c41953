"""The readers' table of docs/readers/index.md says what the readers declare: every format, its options, defaults."""

from __future__ import annotations

import re
from pathlib import Path

from footzoo.io import READERS
from footzoo.io.base import RECORDING_OPTIONS
from footzoo.io.registry import BUILTIN

PAGE = Path(__file__).resolve().parents[2] / "docs" / "readers" / "index.md"
FRAME = ("axes", "acc_unit", "gyr_unit")


def table_rows() -> dict[str, list[str]]:
    """``format -> cells`` of the table whose header starts with ``| format | reads |``."""
    lines = PAGE.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("| format | reads |"))
    rows = {}
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip("|").split("|")]
        rows[cells[0].strip("`")] = cells
    return rows


def test_the_table_lists_every_builtin_reader_in_detection_order():
    assert list(table_rows()) == list(BUILTIN)


def test_the_table_gives_each_reader_s_frame_defaults_and_other_options():
    for fmt, cells in table_rows().items():
        options = READERS[fmt].options
        for option, cell in zip(FRAME, cells[2:5], strict=True):
            default = options[option].default
            if default is None:  # from the file: the header, the description
                assert not cell.startswith("`"), (fmt, option, cell)
            else:
                assert cell == f"`{default}`", (fmt, option, cell, default)
        others = [o for o in options if o not in FRAME and o not in RECORDING_OPTIONS]
        named = re.findall(r"`(\w+)` \(", cells[5])
        assert sorted(named) == sorted(others + [o for o in RECORDING_OPTIONS if o in named]), (fmt, named, others)
        for o in RECORDING_OPTIONS:  # the common options are described under the table, unless a default differs
            assert o in options, (fmt, o)
            if options[o].default != RECORDING_OPTIONS[o].default:
                assert f"`{o}` (`{options[o].default}`)" in cells[5], (fmt, o)
