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


def test_validate_checks_a_study_or_tune_file_without_running_it(tmp_path, capsys):
    sim = "recordings: [{simulate: {path: straight, n_strides: 4, rate: 50, noise: {scale: 1}}, seeds: [0, 1]}]\n"
    study = tmp_path / "study.yaml"
    study.write_text("name: s\nbase: yun2012\nfactors: {detector.threshold: [0.4, 0.6, 0.8]}\n" + sim)
    assert main(["validate", str(study)]) == 0
    out = capsys.readouterr().out
    assert "valid study: 3 config(s) x 2 recording(s) = 6 runs" in out
    assert not (tmp_path / "ablation_study").exists()  # nothing ran, nothing written
    study.write_text("name: s\nbase: yun2012\nfactors: {detector.treshold: [0.4, 0.6]}\n" + sim)
    assert main(["validate", str(study)]) == 2
    err = capsys.readouterr().err
    assert "nothing was run" in err and "'treshold'" in err and "Traceback" not in err
    tune = tmp_path / "tune.yaml"
    tune.write_text("name: t\nbase: yun2012\nfactors: {detector.threshold: [0.4, 0.6]}\n" + sim
                    + "tune: {objective: armse_3d_m}\n")
    assert main(["validate", str(tune)]) == 2  # recordings without a group: tune would refuse them
    assert "has no group" in capsys.readouterr().err
    walk = "{path: straight, n_strides: 4, rate: 50, noise: {scale: 1}}"
    tune.write_text("name: t\nbase: yun2012\nfactors: {detector.threshold: [0.4, 0.6]}\n"
                    f"recordings: [{{simulate: {walk}, seeds: [0], group: a}}, "
                    f"{{simulate: {walk}, seeds: [1], group: b, label: other}}]\ntune: {{objective: armse_3d_m}}\n")
    assert main(["validate", str(tune)]) == 0
    out = capsys.readouterr().out
    assert "valid tune file: grid search, objective armse_3d_m (minimize); 2 recording(s) in 2 groups" in out


def test_list_shows_a_plug_in_file_given_with_plugins(tmp_path, capsys):
    from footzoo.plugins import registry

    mine = tmp_path / "listed_detector.py"
    mine.write_text(
        '"""A listed detector."""\nimport numpy as np\nimport footzoo\nfrom footzoo.plugins.base import Detector\n\n\n'
        "@footzoo.register\nclass Listed(Detector):\n"
        '    """Stance when the rate is small.\n\n    Parameters\n    ----------\n    limit : float\n'
        '        Largest rate in stance (rad/s).\n    """\n\n'
        '    name = "listed_detector"\n    paper = "none"\n    units = {"limit": "rad/s"}\n\n'
        "    def __init__(self, limit: float = 0.5):\n        self.limit = limit\n\n"
        "    def fit_predict(self, samples):\n"
        "        self.stance_ = np.linalg.norm(samples.gyr, axis=1) < self.limit\n        return self.stance_\n")
    try:
        assert main(["list", "listed_detector"]) == 2
        assert "no plug-in named 'listed_detector'" in capsys.readouterr().err
        assert main(["list", "listed_detector", "--plugins", str(mine)]) == 0
        out = capsys.readouterr().out
        assert "listed_detector — Stance when the rate is small." in out and "limit = 0.5 [rad/s]" in out
        # without a name: the file's plug-ins alone, not buried among footzoo's own (360 lines)
        assert main(["list", "--plugins", str(mine)]) == 0
        out = capsys.readouterr().out
        assert out.startswith("detector:\n  listed_detector — Stance when the rate is small.")
        assert "angular_rate_fsm" not in out and "footzoo list without it lists footzoo's own" in out
    finally:
        registry._REGISTRY["detector"].pop("listed_detector", None)
