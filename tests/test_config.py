"""Config errors name the problem, list the valid choices and suggest the closest one."""

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.apps.cli import main

GOOD = {
    "name": "t",
    "orientation": {"type": "fqa_complementary", "static_gain": 1.05, "dynamic_gain": 0.0},
    "detector": {"type": "angular_rate_fsm", "threshold": 0.6, "min_duration": 0.1},
    "corrections": [{"type": "zvu_dedrift"}],
}


def with_(**changes):
    d = {k: (dict(v) if isinstance(v, dict) else v) for k, v in GOOD.items()}
    d.update(changes)
    return d


def test_good_config_resolves_every_parameter():
    p = Pipeline.from_dict(GOOD)
    assert p.to_dict()["orientation"] == {"type": "fqa_complementary", "static_gain": 1.05, "dynamic_gain": 0.0,
                                          "use_magnetometer": True, "mag_rejection": True,
                                          "mag_norm_tolerance": 0.1, "mag_dip_tolerance": float(np.radians(5.0))}


def test_unknown_top_level_key_suggests_the_closest():
    with pytest.raises(ConfigError, match=r"unknown config key 'detecter' \(did you mean 'detector'\?\); valid keys"):
        Pipeline.from_dict(with_(detecter={}))


def test_unknown_type_lists_valid_types():
    with pytest.raises(ConfigError, match=r"unknown detector type 'angular_rate' \(did you mean 'angular_rate_fsm'\?\)"
                                          r"; valid types: \['adaptive_shoe', 'amvd', 'angular_rate_fsm'"):
        Pipeline.from_dict(with_(detector={"type": "angular_rate"}))


def test_unknown_parameter_lists_valid_parameters():
    with pytest.raises(ConfigError, match=r"unknown parameter 'static_gian'.*did you mean 'static_gain'.*"
                                          r"valid parameters: \['static_gain', 'dynamic_gain', 'use_magnetometer', "
                                          r"'mag_rejection'"):
        Pipeline.from_dict(with_(orientation={"type": "fqa_complementary", "static_gian": 1}))


def test_bad_value_names_the_parameter():
    with pytest.raises(ConfigError, match=r"detector \(angular_rate_fsm\): threshold = -1 rad/s is out of range: "
                                          r"it must lie in \(0, 50\] rad/s"):
        Pipeline.from_dict(with_(detector={"type": "angular_rate_fsm", "threshold": -1}))


def test_missing_section_and_missing_type():
    d = dict(GOOD)
    del d["detector"]
    with pytest.raises(ConfigError, match="config is missing 'detector'"):
        Pipeline.from_dict(d)
    with pytest.raises(ConfigError, match="orientation: missing 'type'; valid types"):
        Pipeline.from_dict(with_(orientation={"static_gain": 1}))


def test_unknown_correction_is_placed_in_the_list():
    with pytest.raises(ConfigError, match=r"corrections\[0\]: unknown correction type 'zvu'"):
        Pipeline.from_dict(with_(corrections=[{"type": "zvu"}]))


def test_unknown_init_key():
    with pytest.raises(ConfigError, match=r"unknown init key 'durration' \(did you mean 'duration'\?\)"):
        Pipeline.from_dict(with_(init={"durration": 1}))


def test_yaml_files_missing_empty_and_not_a_mapping(tmp_path):
    with pytest.raises(ConfigError, match="does not exist"):
        Pipeline.from_yaml(tmp_path / "nope.yaml")
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(ConfigError, match="the file is empty"):
        Pipeline.from_yaml(empty)
    listy = tmp_path / "list.yaml"
    listy.write_text("- a\n- b\n")
    with pytest.raises(ConfigError, match="top level must be a mapping"):
        Pipeline.from_yaml(listy)


def test_cli_validate_reports_errors_with_exit_code_2(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("orientation: {type: fqa_complementary}\ndetector: {type: shoe_detector}\n")
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "unknown detector type 'shoe_detector'" in err and "valid types" in err
    good = tmp_path / "good.yaml"
    good.write_text("orientation: {type: fqa_complementary}\ndetector: {type: angular_rate_fsm}\n")
    assert main(["validate", str(good)]) == 0
    assert "valid" in capsys.readouterr().out


@pytest.mark.parametrize("key, value, message", [
    ("navigation", {"velocity_nosie": 0.1}, "unknown navigation key 'velocity_nosie' (did you mean 'velocity_noise'?)"),
    ("navigation", "0.1", "navigation must be a mapping like"),
    ("guards", {"max_swnig": 1.0}, "unknown guards key 'max_swnig' (did you mean 'max_swing'?)"),
    ("guards", [1.5], "guards must be a mapping like"),
])
def test_settings_blocks_refuse_unknown_keys_and_non_mappings_alike(key, value, message):
    cfg = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"}, "corrections": [{"type": "zupt"}], key: value}
    with pytest.raises(ConfigError) as err:
        Pipeline.from_dict(cfg)
    assert message in str(err.value)
