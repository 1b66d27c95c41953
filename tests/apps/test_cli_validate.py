"""``footzoo validate`` reports every problem of a config at once; ``footzoo list --compatibility`` keeps whole
reasons.
"""

from __future__ import annotations

from footzoo.apps.cli import main
from footzoo.apps.compat import check

YUN = "yun2012"


def test_validate_reports_every_problem_at_once(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("gravty: 9.8\norientation: {type: fqa_complementary, static_gane: 1.0}\n"
                   "detector: {type: angular_rate_fsm, threshold: -1}\ncorrections:\n  - {type: zvu_dedrif}\n")
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "4 problem(s)" in err
    for what in ("'gravty'", "'static_gane'", "threshold = -1 rad/s is out of range", "'zvu_dedrif'"):
        assert what in err
    assert main(["validate", YUN]) == 0


def test_compatibility_list_keeps_whole_reasons(capsys):
    assert main(["list", "--compatibility"]) == 0
    out = capsys.readouterr().out
    reason = check({"orientation": {"type": "madgwick"}, "detector": {"type": "angular_rate_fsm"},
                    "corrections": [{"type": "ekf_zupt"}, {"type": "zvu_dedrift"}]})
    assert reason is not None
    assert reason.split(":", 1)[-1].strip() in out
    longest = max((len(line) for line in out.splitlines() if line.startswith("- ")), default=0)
    assert longest > 162  # reasons used to be cut at 160 characters
