"""benchmarks/hdr_recommended.py: its candidates are recommended as shipped, and with HDR after its zupt."""

import yaml

from footzoo import Pipeline
from footzoo.config.library import path as config_path

from ..conftest import load_benchmark


def test_the_candidates_are_the_shipped_setting_and_it_with_hdr_after_its_zupt():
    hr = load_benchmark("hdr_recommended")
    shipped = yaml.safe_load(config_path("recommended").read_text())
    cands = hr.candidates()
    assert {k: v for k, v in cands[0].items() if k != "name"} == {k: v for k, v in shipped.items() if k != "name"}
    for cfg, (th, sd) in zip(cands[1:], hr.SETTINGS, strict=True):
        assert [c["type"] for c in cfg["corrections"]] == ["zupt", "hdr", "height_level"]
        assert cfg["corrections"][1] == {"type": "hdr", "threshold": th, "yaw_std": sd}
        Pipeline.from_dict({k: v for k, v in cfg.items() if k != "name"})  # a valid config
