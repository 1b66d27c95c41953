"""Bad input in memory: complex samples, a path given for a recording, a result folder named like a file or '-', a
session run without a pipeline."""

from __future__ import annotations

import re

import numpy as np
import pytest

import footzoo
from footzoo.core.errors import RecordingError
from footzoo.sim import simulate

from ..conftest import HARD_IRON_NOT_FITTED


@pytest.fixture(scope="module")
def sim_walk():
    from footzoo.sim import NoiseModel

    return simulate(n_strides=10, rate=100.0, noise=NoiseModel(seed=1))


def test_complex_samples_are_refused_not_cast():
    t = np.arange(300) / 100.0
    acc = np.tile([0.0, 0.0, -9.81], (300, 1)) + 1j
    with pytest.raises(RecordingError, match=r"acc holds complex numbers.*acc\.real"):
        footzoo.Recording(t=t, acc=acc, gyr=np.zeros((300, 3)))


def test_running_a_path_instead_of_a_recording_says_how_to_load_it():
    with pytest.raises(TypeError, match=r"load it first, Pipeline\.run\(footzoo\.load\('walk\.csv'\)\)"):
        footzoo.Pipeline.from_yaml("yun2012").run("walk.csv")


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_a_result_folder_named_like_a_file_is_refused(sim_walk, tmp_path):
    from footzoo.core.errors import OutputError

    res = footzoo.Pipeline.from_yaml("yun2012").run(sim_walk)
    with pytest.raises(OutputError, match=r"looks like a file name \(\.xlsx\).*saved as a folder"):
        res.save(tmp_path / "result.xlsx")
    assert not (tmp_path / "result.xlsx").exists()
    assert res.save(tmp_path / "result.v2").is_dir()  # a dotted folder name that is no file type is fine


@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_a_result_saved_to_dash_is_refused_as_on_the_command_line(sim_walk, tmp_path, monkeypatch):
    """'-' (standard output to most tools) used to create a folder named '-'; './-' still names such a folder."""
    from footzoo.core.errors import OutputError

    monkeypatch.chdir(tmp_path)
    res = footzoo.Pipeline.from_yaml("yun2012").run(sim_walk)
    with pytest.raises(OutputError, match=r"Result.save: '-' means standard output.*give a folder name.*'\./-'"):
        res.save("-")
    assert not (tmp_path / "-").exists()
    assert res.save("./-").is_dir() and footzoo.Result.load("./-").steps.shape == res.steps.shape


def test_a_session_run_without_a_pipeline_says_how_to_build_one(sim_walk):
    """Before: AttributeError ('NoneType' object has no attribute 'run') from inside the session."""
    session = footzoo.Session({"left": sim_walk})
    with pytest.raises(footzoo.ConfigError, match="Session.run needs a footzoo Pipeline, got NoneType None"):
        session.run(None)
    with pytest.raises(footzoo.ConfigError, match=r"\(Session.run\(Pipeline.from_yaml\('yun2012'\)\) builds it"):
        session.run("yun2012")


def test_an_argument_of_the_wrong_kind_is_both_the_subjects_error_and_a_type_error(sim_walk):
    """One convention for every entry point: the footzoo error of the subject, and Python's TypeError."""
    from footzoo.core.errors import NotAPipelineError, NotARecordingError

    pipe = footzoo.Pipeline.from_yaml("yun2012")
    for call, subject in [(lambda: pipe.run("walk.csv"), footzoo.RecordingError),
                          (lambda: footzoo.Session({"left": "walk.csv"}), footzoo.RecordingError),
                          (lambda: footzoo.Session({"left": sim_walk}).run("yun2012"), footzoo.ConfigError),
                          (lambda: footzoo.Stream(None, rate=100.0), footzoo.ConfigError),
                          (lambda: footzoo.Pipeline.run(sim_walk, pipe), footzoo.ConfigError)]:  # swapped
        with pytest.raises((NotARecordingError, NotAPipelineError)) as info:
            call()
        assert isinstance(info.value, subject) and isinstance(info.value, TypeError)
        assert "footzoo." in str(info.value) or "Pipeline.from_yaml" in str(info.value)


def test_a_pipeline_built_from_a_config_name_says_how_to_read_one():
    for given, how in (("yun2012", "Pipeline.from_yaml('yun2012')"), ({"orientation": {}}, "Pipeline.from_dict")):
        with pytest.raises(footzoo.ConfigError, match=re.escape(f"builds a pipeline from plug-in objects; a config is "
                                                                f"read with {how}")):
            footzoo.Pipeline(given)


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_a_path_with_a_nul_character_is_named_not_a_crash(sim_walk, tmp_path):
    """Before: ValueError (embedded null byte) from pathlib, for a result folder; for a recording: 'no such file'."""
    from footzoo.core.errors import OutputError

    res = footzoo.Pipeline.from_yaml("yun2012").run(sim_walk)
    with pytest.raises(OutputError, match=r"Result.save '.*r\\x00es' holds a NUL character \(\\x00\) at position"):
        res.save(str(tmp_path / "r\x00es"))
    with pytest.raises(footzoo.FormatError, match=r"recording 'walk\\x00.csv' holds a NUL character"):
        footzoo.load("walk\x00.csv")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("call, message", [
    (lambda: footzoo.Pipeline.from_yaml(None), r"a config is a shipped config's name or the path of a YAML file, got "
                                               r"NoneType None; a mapping goes to Pipeline.from_dict"),
    (lambda: footzoo.Pipeline.from_yaml({"detector": {"type": "shoe"}}), r"got dict .*Pipeline.from_dict"),
    (lambda: footzoo.Pipeline.from_dict("yun2012"), r"a config must be a mapping, got str: a shipped config's name or "
                                                   r"a YAML file goes to Pipeline.from_yaml\('yun2012'\)"),
])
def test_a_config_of_the_wrong_kind_says_which_constructor_takes_it(call, message):
    """Before: TypeError from pathlib for from_yaml(None)."""
    with pytest.raises(footzoo.ConfigError, match=message):
        call()
