"""Bad input: files cut short, foreign delimiters, damaged MATLAB files, YAML and CLI oddities, study names.

Each case is a clear error naming the file, the problem and the fix (never a raw traceback, never a silently
wrong recording).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import footzoo
from footzoo.core.errors import FormatError, RecordingError
from footzoo.io.canonical import write
from footzoo.sim import simulate


@pytest.fixture(scope="module")
def walk_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("walk") / "walk.csv"
    write(simulate(n_strides=4, rate=50.0), path)
    return path


def _lines(path):
    return path.read_text().splitlines()


def test_a_file_cut_short_in_its_last_row_is_named_not_read(walk_csv, tmp_path):
    lines = _lines(walk_csv)
    cut = tmp_path / "cut.csv"
    cut.write_text("\n".join(lines[:-1] + [lines[-1][: len(lines[-1]) // 3]]) + "\n")  # cut mid-row
    with pytest.raises(RecordingError, match=r"cut\.csv.*row \d+ \(t = [\d.]+ s\) has values in only its first \d+ "
                                             r"of \d+ columns: the file is cut short"):
        footzoo.load(cut)


def test_a_non_finite_value_names_its_time_in_seconds(walk_csv, tmp_path):
    lines = _lines(walk_csv)
    fields = lines[10].split(",")
    fields[3] = "nan"
    lines[10] = ",".join(fields)
    bad = tmp_path / "nan.csv"
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(RecordingError, match=r"column 'acc_z' has 1 non-finite value\(s\), first at row 9 "
                                             r"\(t = 0\.180000 s\)") as info:
        footzoo.load(bad)
    assert "np.float64" not in str(info.value)


def test_a_semicolon_separated_file_says_so(walk_csv, tmp_path):
    semi = tmp_path / "semi.csv"
    semi.write_text(walk_csv.read_text().replace(",", ";"))
    with pytest.raises(FormatError, match=r"separated by semicolons, not commas"):
        footzoo.load(semi)


def test_a_truncated_matlab_file_is_called_damaged(tmp_path):
    from scipy.io import savemat

    whole = tmp_path / "whole.mat"
    savemat(whole, {"imu": np.random.default_rng(0).normal(size=(2000, 6)), "ts": np.arange(2000) / 200.0})
    cut = tmp_path / "cut.mat"
    cut.write_bytes(whole.read_bytes()[:3000])
    with pytest.raises(FormatError, match=r"cut\.mat.*(damaged or truncated|cannot)"):
        footzoo.load(cut)
    other = tmp_path / "other.mat"
    savemat(other, {"x": np.zeros(3)})
    with pytest.raises(FormatError, match=r"variables \['x'\]; PyShoe's trials have imu and ts"):
        footzoo.load(other)


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


# --------------------------------------------------------------------------- live and in memory


@pytest.fixture(scope="module")
def sim_walk():
    from footzoo.sim import NoiseModel

    return simulate(n_strides=10, rate=100.0, noise=NoiseModel(seed=1))


def test_a_stream_made_with_the_wrong_rate_refuses_at_its_start(sim_walk):
    from footzoo import Pipeline, Stream

    stream = Stream(Pipeline.from_yaml("nguyen2016"), rate=2 * sim_walk.rate)
    with pytest.raises(RecordingError, match=r"come at 100 Hz, but the stream was made with rate=200 Hz.*rate=100"):
        stream.run(sim_walk)
    near = Stream(Pipeline.from_yaml("nguyen2016"), rate=sim_walk.rate * 1.05)  # a nominal rate, 5 % off: fine
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert np.isfinite(near.run(sim_walk)["pos"]).all()


def test_an_accelerometer_unit_that_changes_mid_stream_is_warned_where_it_changes(sim_walk):
    from footzoo import Pipeline, Stream
    from footzoo.core.errors import SensorWarning

    half = sim_walk.n // 2
    stream = Stream(Pipeline.from_yaml("nguyen2016"), rate=sim_walk.rate)
    with pytest.warns(SensorWarning, match=r"accelerometer reads 0\.99\d? \(≈ 1: in g\?"):
        for i in range(sim_walk.n):
            stream.push(sim_walk.t[i], sim_walk.acc[i] / (9.81 if i >= half else 1.0), sim_walk.gyr[i])
        stream.close()
    finding = stream.sensor["acc_scale"]
    assert finding["first"] >= half and finding["magnitude"] == pytest.approx(1.0, abs=0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SensorWarning)  # the same walk in m/s² throughout: no finding
        res = footzoo.Pipeline.from_yaml("nguyen2016").run(sim_walk)
    assert "acc_scale" not in res.diagnostics["sensor"]


def test_complex_samples_are_refused_not_cast():
    t = np.arange(300) / 100.0
    acc = np.tile([0.0, 0.0, -9.81], (300, 1)) + 1j
    with pytest.raises(RecordingError, match=r"acc holds complex numbers.*acc\.real"):
        footzoo.Recording(t=t, acc=acc, gyr=np.zeros((300, 3)))


def test_a_result_folder_named_like_a_file_is_refused(sim_walk, tmp_path):
    from footzoo.core.errors import OutputError

    res = footzoo.Pipeline.from_yaml("yun2012").run(sim_walk)
    with pytest.raises(OutputError, match=r"looks like a file name \(\.xlsx\).*saved as a folder"):
        res.save(tmp_path / "result.xlsx")
    assert not (tmp_path / "result.xlsx").exists()
    assert res.save(tmp_path / "result.v2").is_dir()  # a dotted folder name that is no file type is fine


def test_running_a_path_instead_of_a_recording_says_how_to_load_it():
    with pytest.raises(TypeError, match=r"load it first, Pipeline\.run\(footzoo\.load\('walk\.csv'\)\)"):
        footzoo.Pipeline.from_yaml("yun2012").run("walk.csv")


# --------------------------------------------------------------------------- studies


@pytest.mark.parametrize("simulate_spec, message", [
    ({"path": "straigt"}, r"recordings\[0\]\.simulate: unknown path 'straigt'"),
    ({"path": "straight", "n_strides": -4}, r"n_strides must be a whole number in \[0, 100000\].*got -4"),
    ({"path": "straight", "n_stride": 4}, r"unknown option 'n_stride' \(did you mean 'n_strides'\?\)"),
    ({"path": "straight", "rate": 0}, r"rate must be a number in \(0, 20000\] Hz, got 0"),
])
def test_a_study_refuses_a_bad_simulate_entry_before_running(simulate_spec, message):
    from footzoo.studies import Study

    with pytest.raises(footzoo.ConfigError, match=message):
        Study.from_dict({"base": "yun2012", "recordings": [{"simulate": simulate_spec}]})


def test_two_recordings_with_one_name_are_refused_and_labels_tell_them_apart(walk_csv, tmp_path):
    import shutil

    from footzoo.studies import Study

    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        shutil.copy(walk_csv, tmp_path / d / "walk.csv")
    same = [{"path": str(tmp_path / d / "walk.csv")} for d in ("a", "b")]
    with pytest.raises(footzoo.ConfigError, match=r"both called 'walk'.*give each entry its own label"):
        Study.from_dict({"base": "yun2012", "recordings": same})
    labelled = [{**r, "label": d} for r, d in zip(same, ("a", "b"), strict=True)]
    study = Study.from_dict({"base": "yun2012", "recordings": labelled})
    assert [r.label for r in study.recordings] == ["a", "b"]


@pytest.mark.parametrize("factors, message", [
    ({"detector.threshold.x": [1, 2]}, r"'detector\.threshold' is a value .* one level too deep"),
    ({"detector.threshold": [0.5, 0.5]}, r"lists the level 0\.5 more than once"),
])
def test_a_factor_that_cannot_be_set_or_repeats_a_level_is_refused(factors, message, tmp_path):
    from footzoo.studies import Study, run_study

    with pytest.raises(footzoo.ConfigError, match=message):
        study = Study.from_dict({"base": "yun2012", "factors": factors,
                                 "recordings": [{"simulate": {"path": "straight", "n_strides": 4}}]})
        run_study(study, out=tmp_path / "out", quiet=True)
