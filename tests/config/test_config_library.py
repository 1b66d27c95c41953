"""Shipped configs by name, from any folder; modules import under their own names only."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

from footzoo import ConfigError, Pipeline
from footzoo.apps.cli import main
from footzoo.config import library


def test_every_shipped_config_builds_by_name_from_another_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    names = library.names("pipeline")
    assert {"recommended", "yun2012", "nguyen2016", "duong2015", "huang2016"} <= set(names)
    for name in names:
        assert Pipeline.from_yaml(name).name == name
        assert Pipeline.from_yaml(f"{name}.yaml").name == name


def test_a_file_next_to_the_data_wins_over_the_shipped_config_of_that_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    copy = library.copy("yun2012", tmp_path)
    copy.write_text(copy.read_text().replace("name: yun2012", "name: mine"))
    assert Pipeline.from_yaml("yun2012.yaml").name == "mine"  # the file here
    assert Pipeline.from_yaml("yun2012").name == "yun2012"  # a bare name is the shipped config


def test_an_unknown_name_lists_the_shipped_configs_with_a_suggestion():
    with pytest.raises(ConfigError, match=r"no shipped config named 'recomended'.*did you mean 'recommended'"):
        Pipeline.from_yaml("recomended")


def test_the_configs_command_lists_and_copies(tmp_path, capsys):
    assert main(["configs"]) == 0
    out = capsys.readouterr().out
    assert "recommended" in out and "study_quick" in out
    assert main(["configs", "--copy", "recommended", "--to", str(tmp_path)]) == 0
    assert (tmp_path / "recommended.yaml").read_text() == library.path("recommended").read_text()
    assert main(["configs", "--copy", "recommended", "--to", str(tmp_path)]) == 2  # exists: refused
    assert "--force" in capsys.readouterr().err
    assert main(["configs", "--copy", "recommended", "--to", str(tmp_path), "--force"]) == 0


def test_the_configs_command_gives_each_description_s_first_whole_sentence(tmp_path, capsys):
    from footzoo.apps.cli import _first_sentence

    f = tmp_path / "c.yaml"
    f.write_text("# Smith et al. 2020 (Fig. 3, eqs. 1-4): the \"K.F.\" method,\n# on two lines. A second sentence.\n"
                 "# More.\nname: c\n# not the description\n")
    assert _first_sentence(f) == 'Smith et al. 2020 (Fig. 3, eqs. 1-4): the "K.F." method, on two lines.'
    assert main(["configs"]) == 0
    out = " ".join(capsys.readouterr().out.split())  # the lines as wrapped, joined
    assert "the 9-state filter without distance sensors." in out and "(eqs. 15-16)." in out


def test_a_study_names_its_base_config_by_name(tmp_path):
    from footzoo.studies import Study

    study = Study.from_dict({"base": "yun2012", "recordings": [{"simulate": {"n_strides": 3}, "seeds": [0]}]},
                            root=tmp_path)
    assert study.bases[0][0] == "yun2012"


@pytest.mark.parametrize("old", ["footzoo.pipeline", "footzoo.plugin", "footzoo.metrics", "footzoo.ablation"])
def test_a_module_is_found_under_its_own_name_only(old):
    """The package installs no import hook: a module name of footzoo 0.2 is not found (CHANGELOG.md maps them)."""
    with pytest.raises(ModuleNotFoundError, match=old):
        importlib.import_module(old)


def test_the_live_twin_of_recommended_differs_only_in_its_smoother():
    """recommended_live is recommended with the step-wise smoother, which streams; the two cannot drift apart."""
    from footzoo import Pipeline, Stream

    offline, live = Pipeline.from_yaml("recommended").to_dict(), Pipeline.from_yaml("recommended_live").to_dict()
    assert (offline.pop("smoother"), live.pop("smoother")) == ("rts", "stepwise")
    assert (offline.pop("name"), live.pop("name")) == ("recommended", "recommended_live")
    assert offline == live
    assert Stream(Pipeline.from_yaml("recommended_live"), rate=100.0).latency.live


def test_a_built_package_carries_its_data_files(tmp_path):
    """What `pip install .` installs: the configs, the built-in sample and the learned detector's weights.

    setup.py's build (kernels not precompiled, a second) from a clean copy of the sources (a checkout's
    own egg-info would list the data files whatever setup.py says); every data file is in the build.
    """
    import os
    import shutil
    import subprocess
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    src = tmp_path / "src"
    src.mkdir()
    for name in ("setup.py", "setup.cfg", "pyproject.toml", "README.md"):
        shutil.copy(root / name, src / name)
    ignore = shutil.ignore_patterns("__pycache__", "_compiled", "*.egg-info")
    for folder in ("footzoo", "configs"):
        shutil.copytree(root / folder, src / folder, ignore=ignore)
    env = {**os.environ, "FOOTZOO_NO_PRECOMPILE": "1"}
    run = subprocess.run([sys.executable, "setup.py", "-q", "build_py", "--build-lib", str(tmp_path / "lib")],
                         cwd=src, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    built = tmp_path / "lib" / "footzoo"
    for source in [*(root / "footzoo" / "samples").glob("*.csv.gz"), *(root / "footzoo").rglob("*.npz")]:
        rel = source.relative_to(root / "footzoo")
        assert (built / rel).is_file(), f"{rel} is not in the built package"
    assert {p.name for p in (built / "configs").glob("*.yaml")} == {p.name for p in (root / "configs").glob("*.yaml")}


def test_a_copy_goes_into_a_folder_named_with_a_slash_or_without_an_extension(tmp_path):
    """``--to new/`` (or ``new``) is a folder to create and copy into, not a file named ``new`` (before: a file)."""
    for dest in (f"{tmp_path / 'with_slash'}/", str(tmp_path / "no_extension")):
        target = library.copy("yun2012", dest)
        assert target == Path(dest.rstrip("/")) / "yun2012.yaml"
        assert target.read_text() == library.path("yun2012").read_text()
    assert library.copy("yun2012", tmp_path / "mine.yml").name == "mine.yml"
    with pytest.raises(ConfigError, match="a config is a YAML file; name the copy 'mine.yaml'"):
        library.copy("yun2012", tmp_path / "mine.txt")
