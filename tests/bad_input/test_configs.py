"""Bad configs: a plug-in type that is not a name, a config file that does not exist (run and validate alike)."""

from __future__ import annotations

import pytest

import footzoo

NOT_A_NAME = r"the {} type must be a plug-in's name \(text\), got {}"


@pytest.mark.parametrize("part, value, message", [
    ("orientation", {"type": {"type": "ins"}}, "orientation: " + NOT_A_NAME.format("orientation", "dict")),
    ("detector", {"type": ["shoe"]}, "detector: " + NOT_A_NAME.format("detector", "list")),
    ("detector", {"type": 3}, "detector: " + NOT_A_NAME.format("detector", "int")),
])
def test_a_type_that_is_not_a_name_is_a_config_error_in_run_and_validate(part, value, message, tmp_path):
    from footzoo.apps.cli import main

    cfg = {"name": "odd", "orientation": {"type": "ins"}, "detector": {"type": "shoe"},
           "corrections": [{"type": "ekf_zupt"}], part: value}
    with pytest.raises(footzoo.ConfigError, match=message):
        footzoo.Pipeline.from_dict(cfg)
    import yaml

    (tmp_path / "odd.yaml").write_text(yaml.safe_dump(cfg))
    assert main(["validate", str(tmp_path / "odd.yaml")]) == 2  # a config error, not "internal error"


def test_a_missing_yaml_file_is_called_missing_not_an_unknown_shipped_name(tmp_path, monkeypatch):
    from footzoo.config.library import resolve

    monkeypatch.chdir(tmp_path)
    missing = r"'my_study\.yaml': no such file in .*no shipped config has that name"
    with pytest.raises(footzoo.ConfigError, match=missing):
        resolve("my_study.yaml")
    with pytest.raises(footzoo.ConfigError, match=r"no shipped config named 'recomended' \(did you mean 'recommended'"):
        resolve("recomended")


def test_a_shipped_configs_source_path_where_there_is_none_names_the_shipped_name(tmp_path, monkeypatch):
    """``configs/study_quick.yaml`` (a source checkout's path) run where footzoo is only installed."""
    from footzoo.apps.cli import main

    monkeypatch.chdir(tmp_path)
    for read in (footzoo.Pipeline.from_yaml, footzoo.run_study):
        with pytest.raises(footzoo.ConfigError, match=r"ships a config named 'study_quick': give its name alone"):
            read("configs/study_quick.yaml")
    assert main(["ablate", "configs/study_quick.yaml", "--out", str(tmp_path / "o")]) == 2


def test_yaml_text_given_as_a_configs_name_says_what_it_is(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for text in ("detector: {type: shoe}", "name: x\norientation: {type: ins}\n"):
        with pytest.raises(footzoo.ConfigError, match="looks like the text of a YAML config, not a file name"):
            footzoo.Pipeline.from_yaml(text)
    with pytest.raises(footzoo.ConfigError, match="no shipped config named 'yun'"):  # a name stays a name
        footzoo.Pipeline.from_yaml("yun")


def test_a_config_named_by_a_link_in_a_loop_is_called_a_loop_not_missing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "c.yaml").symlink_to("c.yaml")
    for read in (footzoo.Pipeline.from_yaml, footzoo.run_study):
        with pytest.raises(footzoo.ConfigError, match=r"'c\.yaml' is a symbolic link in a loop \(c\.yaml -> c\.yaml"):
            read("c.yaml")


@pytest.mark.parametrize("text, line, column", [("detector:\n\ttype: shoe\n", 2, 1), ("name: a\nx:\t1\n", 2, 3)])
def test_a_tab_in_a_yaml_file_is_named_with_its_place_and_the_fix(text, line, column):
    """PyYAML's own message ("found character '\\t' that cannot start any token") says what, not how to fix it."""
    from footzoo.core.yamlsafe import load_text

    fix = rf"YAML allows no tab there \(it indents with spaces only\): replace the tab at line {line}, column {column}"
    with pytest.raises(footzoo.ConfigError, match=rf"(?s)c.yaml: not valid YAML: .*{fix} by spaces"):
        load_text(text, "c.yaml")
