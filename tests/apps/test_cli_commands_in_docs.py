"""Every ``footzoo ...`` command quoted in the shipped configs, the README and the command-line page parses."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from footzoo.apps.cli import build_parser
from footzoo.config import library


def test_config_comments_show_commands_that_parse():
    """Every `footzoo ...` command quoted in a config comment is accepted by the parser."""
    parser = build_parser()
    found = 0
    for cfg in library.BUILTIN.glob("*.yaml"):
        for line in cfg.read_text().splitlines():
            m = re.search(r"#.*?footzoo ((?:run|calibrate|simulate|validate|list|ablate)\b[^,;]*)", line)
            if m:
                args = ["x.csv" if a.isupper() else a for a in m.group(1).split()]
                parser.parse_args(args)
                found += 1
    assert found >= 1


@pytest.mark.parametrize("page, at_least", [("README.md", 5), ("docs/command-line.md", 15)])
def test_every_command_in_the_readme_parses(page, at_least):
    """The `footzoo ...` lines of the README and of the command-line page (continuations joined, comments cut)
    are accepted by the parser."""
    import shlex

    parser = build_parser()
    text = (Path(__file__).resolve().parents[2] / page).read_text().replace("\\\n", " ")
    commands = [line.split("#", 1)[0] for line in text.splitlines() if line.startswith("footzoo ")]
    assert len(commands) >= at_least
    for cmd in commands:
        parser.parse_args(shlex.split(cmd)[1:])
