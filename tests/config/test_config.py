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


def test_bad_value_names_the_parameter_the_range_and_the_fix():
    with pytest.raises(ConfigError, match=r"detector \(angular_rate_fsm\): threshold = -1 rad/s is out of range: "
                                          r"it must lie in \(0, 10\] rad/s \(.*\); e.g. the default 0.6 rad/s"):
        Pipeline.from_dict(with_(detector={"type": "angular_rate_fsm", "threshold": -1}))


@pytest.mark.parametrize("section, value, hint", [
    # issue 24: a deg/s value given as rad/s passed validation silently
    ({"detector": {"type": "angular_rate_fsm", "threshold": 35}},
     "detector (angular_rate_fsm): threshold = 35 rad/s is out of range", "35 rad/s is 2005 °/s: threshold is in rad/s "
     "(the default 0.6 rad/s is 34.4 °/s); for 35 °/s write 0.611"),
    ({"gravity": 1.0}, "gravity = 1.0 m/s^2 is out of range: it must lie in [9.7, 9.9] m/s^2",
     "1 m/s^2 is 0.102 g: gravity is in m/s^2 (the default 9.81 m/s^2 is 1 g); for 1 g write 9.81"),
    ({"init": {"duration": 500}}, "init.duration = 500 s is out of range", "for 500 ms write 0.5"),
    ({"corrections": [{"type": "hdr", "threshold": 30}], "orientation": {"type": "madgwick"}},
     "corrections[0] (hdr): threshold = 30 rad is out of range", "for 30 ° write 0.524"),
    ({"guards": {"still_rate": 57}}, "guards.still_rate = 57 rad/s is out of range", "for 57 °/s write 0.995"),
])
def test_values_in_the_wrong_unit_are_refused_with_the_conversion(section, value, hint):
    with pytest.raises(ConfigError) as err:
        Pipeline.from_dict(with_(**section))
    assert value in str(err.value) and hint in str(err.value)


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


def test_cli_list_shows_every_kind_the_settings_and_one_plugin(capsys):
    assert main(["list", "--kind", "calibration"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("calibration:\n") and "\n  hard_iron — " in out  # (other tests may register more)
    assert "min_spread = 0.01 [1]  [0, 1/3]" in out and "\ndetector:" not in out
    assert main(["list", "--kind", "settings"]) == 0
    out = capsys.readouterr().out
    assert "gravity = 9.81 [m/s^2]  [9.7, 9.9]" in out and "guards.max_swing = 1.5 [s]  [0, 10]" in out
    assert main(["list", "angular_rate_fsm"]) == 0
    out = capsys.readouterr().out
    assert "threshold = 0.6 [rad/s]  (0, 10]  Ω_th" in out and "default: footzoo's design notes" in out
    assert "shoe" not in out
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert all(f"\n{kind}:\n" in f"\n{out}" for kind in ("calibration", "orientation", "detector", "correction",
                                                          "analysis"))
    assert "settings (top-level blocks of a pipeline config):" in out
    assert main(["list", "sheo"]) == 2
    assert "no plug-in named 'sheo' (did you mean 'shoe'?)" in capsys.readouterr().err


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


PLUGIN = '''
import footzoo
from footzoo.plugins.base import Detector, Real


@footzoo.register
class MyDetector(Detector):
    """Stance while |ω| is small (a user's plug-in)."""

    name = "{name}"
    paper = "none (test)"
    parameters = {{"gyro_max": Real("rad/s", "(0, 10]", "bound on |ω|", source="test")}}

    def __init__(self, gyro_max: float = 0.8):
        self.gyro_max = gyro_max

    def detect(self, t, acc, gyr):
        import numpy as np

        self.statistic_ = np.linalg.norm(gyr, axis=1)
        self.stance_ = self.statistic_ < self.gyro_max
        return self
'''


def _user_config(folder, name, detector_line):
    (folder / "my_detector.py").write_text(PLUGIN.format(name=name))
    config = folder / "mine.yaml"
    config.write_text("plugins: [my_detector.py]\norientation: {type: madgwick}\n"
                      f"detector: {detector_line}\ncorrections: [{{type: zvu_dedrift}}]\n")
    return config


def test_validate_loads_plugins_as_run_does(tmp_path, monkeypatch, capsys):
    """Issue 24: validate refused `plugins: [my_detector.py]` as 'unknown detector type' while run accepted it."""
    folder = tmp_path / "study"
    folder.mkdir()
    config = _user_config(folder, "test_config_validate_mine", "{type: test_config_validate_mine, gyro_max: 0.7}")
    monkeypatch.chdir(tmp_path)  # elsewhere: the plug-in path is relative to the config file's folder
    assert main(["validate", str(config)]) == 0
    assert "valid" in capsys.readouterr().out
    assert main(["run", str(config)]) == 0
    assert "strides" in capsys.readouterr().out


def test_validate_lists_a_plugins_problems_with_the_others(tmp_path, capsys):
    config = _user_config(tmp_path, "test_config_validate_bad", "{type: test_config_validate_bad, gyro_max: 35}")
    config.write_text(config.read_text() + "gravity: 1.0\nguards: {max_swing: -1}\ninit: {duration: 0}\n")
    assert main(["validate", str(config)]) == 2
    err = capsys.readouterr().err
    assert "4 problem(s)" in err
    for what in ("detector (test_config_validate_bad): gyro_max = 35 rad/s is out of range", "for 35 °/s write 0.611",
                 "gravity = 1.0 m/s^2", "guards.max_swing = -1", "init.duration = 0 s"):
        assert what in err


def test_validate_reports_a_missing_plugin_file_and_the_types_it_would_have_registered(tmp_path, capsys):
    config = tmp_path / "c.yaml"
    config.write_text("plugins: [nowhere.py]\norientation: {type: madgwick}\ndetector: {type: mine}\n")
    assert main(["validate", str(config)]) == 2
    err = capsys.readouterr().err
    assert "plugins[0]: plug-in file" in err and "nowhere.py' does not exist" in err
    assert "unknown detector type 'mine'" in err


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


def test_validate_prints_the_resolved_config_on_request_and_it_runs_as_the_original(capsys):
    import yaml

    assert main(["validate", "recommended"]) == 0
    assert "every default filled in" not in capsys.readouterr().out  # short by default
    assert main(["validate", "recommended", "--resolved"]) == 0
    text = capsys.readouterr().out.split("# the config with every default filled in (what footzoo run runs):\n")[1]
    resolved = Pipeline.from_dict(yaml.safe_load(text))
    assert resolved.to_dict() == Pipeline.from_yaml("recommended").to_dict()


def test_kalman_noises_on_a_pipeline_without_a_kalman_filter_are_refused_not_ignored():
    import yaml

    from footzoo.config.library import path as config_path

    cfg = yaml.safe_load(config_path("yun2012").read_text())
    with pytest.raises(ConfigError, match=r"navigation: velocity_noise set\(s\) the Kalman filter's noises, and this "
                                          r"pipeline has none, so it would change nothing"):
        Pipeline.from_dict({**cfg, "navigation": {"velocity_noise": 5.0}})


def test_a_calibration_listed_twice_is_refused():
    import yaml

    from footzoo.config.library import path as config_path

    cfg = yaml.safe_load(config_path("yun2012").read_text())
    with pytest.raises(ConfigError, match=r"calibration: \['hard_iron'\] listed more than once; keep one of each"):
        Pipeline.from_dict({**cfg, "calibration": [{"type": "hard_iron"}, {"type": "hard_iron"}]})
