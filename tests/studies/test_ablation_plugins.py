"""External plug-ins: loading (files, modules, entry points), errors, pipelines and studies in every back end."""

import hashlib
import re
import sys

import numpy as np
import pytest
import yaml

from footzoo import ConfigError, Pipeline
from footzoo.plugins import extensions as ext
from footzoo.plugins.registry import available
from footzoo.sim import NoiseModel, simulate
from footzoo.studies import Study, run_study

from ..conftest import HARD_IRON_NOT_FITTED, ON_PROCESS_CLUSTER, STANCES_GUARDED

# A detector defined outside the package: Yun's angular-rate FSM under a new name, so its results must
# equal the built-in's exactly; THRESHOLD is what the "edit" tests change.
PLUGIN = '''
from footzoo.detectors import AngularRateFSM
from footzoo.plugins.registry import register

THRESHOLD = {threshold}


@register
class MyDetector(AngularRateFSM):
    """Yun's angular-rate FSM under another name (a test plug-in)."""

    name = "{name}"

    def __init__(self, threshold: float = THRESHOLD, min_duration: float = 0.1):
        super().__init__(threshold, min_duration)
'''


def det_name(folder):
    """A detector name unique to the test (registrations and worker processes outlive a test)."""
    return "det_" + "".join(c if c.isalnum() else "_" for c in folder.name)


def write_plugin(folder, threshold=0.6, file="my_detector.py", name=None):
    path = folder / file
    path.write_text(PLUGIN.format(threshold=threshold, name=name or det_name(folder)))
    return path


def study_dict(plugin_spec, name):
    return {
        "name": "plugins",
        "plugins": [plugin_spec],
        "base": {"name": "yun", "orientation": {"type": "fqa_complementary"}, "detector": {"type": "angular_rate_fsm"},
                 "corrections": [{"type": "zvu_dedrift"}]},
        "factors": {"detector.type": ["angular_rate_fsm", name]},
        "recordings": [{"simulate": {"path": "straight", "n_strides": 4, "rate": 50, "noise": {"scale": 1}},
                        "seeds": [0, 1]}],
        "metrics": ["path_length_m", "armse_3d_m", "strides", "stance_f1"],
    }


def by_detector(table):
    ok = table[table["metric"].notna()].sort_values(["recording", "metric"])
    return {("builtin" if d == "angular_rate_fsm" else "mine"): g["value"].to_numpy()
            for d, g in ok.groupby("detector.type")}


# --------------------------------------------------------------------------- loading


def test_a_plugin_file_registers_once_under_a_stable_module_name(tmp_path):
    path = write_plugin(tmp_path)
    first = ext.load_plugins([path.name], base_dir=tmp_path)
    again = ext.load_plugins([str(path)])  # same file, absolute: not executed again, no "already registered"
    assert first == again and first[0]["module"] == ext.module_name_for(path)
    assert sys.modules[first[0]["module"]].MyDetector is available("detector")[det_name(tmp_path)]
    assert first[0]["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()


def test_an_edited_plugin_file_replaces_its_plugins(tmp_path):
    path = write_plugin(tmp_path, threshold=0.6)
    ext.load_plugins([str(path)])
    h1 = ext.source_hash([str(path)])
    write_plugin(tmp_path, threshold=0.9)
    ext.load_plugins([str(path)])
    assert ext.source_hash([str(path)]) != h1
    assert available("detector")[det_name(tmp_path)]().threshold == 0.9


def test_a_builtin_name_cannot_be_taken(tmp_path):
    path = tmp_path / "clash.py"
    path.write_text(PLUGIN.format(threshold=0.6, name="shoe"))
    with pytest.raises(ConfigError, match=r"plugins\[0\]: importing plug-in file .*clash.py' failed at line \d+: "
                                          r"ValueError: a detector plug-in named 'shoe' is already registered"):
        ext.load_plugins([str(path)])


@pytest.mark.parametrize(("source", "message"), [
    (None, r"plugins\[0\]: plug-in file 'missing.py' does not exist: a relative path is read from the folder of the "
           r"file that lists it, '.*'; give the path from there, or an absolute one"),
    ("def broken(:\n    pass\n", r"plugins\[0\]: syntax error in plug-in file .*bad.py, line 1: .*; fix the file"),
    ("import numpy\nimport not_a_module_xyz\n",
     r"plugins\[0\]: importing plug-in file '.*bad.py' failed at line 2: ModuleNotFoundError: .*not_a_module_xyz"),
    ("x = 1 / 0\n", r"failed at line 1: ZeroDivisionError"),
])
def test_plugin_file_errors_name_file_line_and_fix(tmp_path, source, message):
    name = "missing.py" if source is None else "bad.py"
    if source is not None:
        (tmp_path / name).write_text(source)
    before = set(sys.modules)
    with pytest.raises(ConfigError, match=message):
        ext.load_plugins([name], base_dir=tmp_path)
    assert not {m for m in set(sys.modules) - before if m.startswith("footzoo_plugin_")}  # a failed import leaves none


def test_a_missing_plugin_file_says_where_its_relative_path_was_read_from(tmp_path, monkeypatch, capsys):
    """A YAML file's plug-in paths are read from its folder; ``--plugins`` and Python's from the current folder."""
    from footzoo.apps.cli import main

    monkeypatch.chdir(tmp_path)
    with pytest.raises(ConfigError, match=rf"--plugins\[0\]: plug-in file 'mine.py' does not exist: a relative path is "
                                          rf"read from the current folder, '{re.escape(str(tmp_path))}'"):
        ext.load_plugins(["mine.py"], where="--plugins")
    with pytest.raises(ConfigError, match=rf"read from the folder of the file that lists it, "
                                          rf"'{re.escape(str(tmp_path / 'configs'))}'"):
        ext.load_plugins(["mine.py"], base_dir=tmp_path / "configs")
    with pytest.raises(ConfigError, match=r"plug-in file '/nowhere/mine.py' does not exist; give the path to an "
                                          r"existing .py file"):
        ext.load_plugins(["/nowhere/mine.py"])  # absolute: read from nowhere else
    capsys.readouterr()
    assert main(["list", "--plugins", "mine.py"]) != 0
    assert "a relative path is read from the current folder" in capsys.readouterr().err


def test_plugin_module_names_and_bad_specs(tmp_path, monkeypatch):
    (tmp_path / "my_plugins_pkg.py").write_text(PLUGIN.format(threshold=0.6, name="my_module_det"))
    monkeypatch.syspath_prepend(str(tmp_path))
    info = ext.load_plugins(["my_plugins_pkg"])
    assert info[0]["module"] == "my_plugins_pkg" and "my_module_det" in available("detector")
    assert ext.source_hash(["my_plugins_pkg"]) != ext.source_hash([])
    with pytest.raises(ConfigError, match=r"no plug-in module named 'no_such_footzoo_plugin'; install it"):
        ext.load_plugins(["no_such_footzoo_plugin"])
    with pytest.raises(ConfigError, match=r"plugins\[0\] must be a module name or a path to a .py file, got 3"):
        ext.load_plugins([3])
    with pytest.raises(ConfigError, match="must be a list of module names or .py paths"):
        ext.load_plugins({"a": 1})
    with pytest.raises(ConfigError, match="is not a file"):
        ext.load_plugins([str(tmp_path) + "/"])


def _fake_distribution(site, dist, module, body):
    info = site / f"{dist}-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(f"[footzoo.plugins]\n{module} = {module}\n")
    (site / f"{module}.py").write_text(body)


def test_entry_points_are_loaded_once_and_failures_name_the_distribution(tmp_path, monkeypatch):
    site = tmp_path / "site"
    site.mkdir()
    _fake_distribution(site, "footzoo_extra", "footzoo_extra_plugins",
                       PLUGIN.format(threshold=0.6, name="entry_point_det"))
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setattr(ext, "_ENTRY_POINTS", None)
    loaded = ext.load_entry_points()
    mine = {"name": "footzoo_extra_plugins", "value": "footzoo_extra_plugins", "distribution": "footzoo_extra"}
    assert mine in loaded
    assert "entry_point_det" in available("detector")
    assert ext.load_entry_points() == loaded  # once per process
    _fake_distribution(site, "footzoo_broken", "footzoo_broken_plugins", "raise RuntimeError('boom')\n")
    monkeypatch.setattr(ext, "_ENTRY_POINTS", None)
    with pytest.raises(ConfigError, match=r"entry point 'footzoo_broken_plugins' .* of footzoo_broken failed to load: "
                                          r"RuntimeError: boom; fix or uninstall footzoo_broken"):
        ext.load_entry_points()


# --------------------------------------------------------------------------- pipelines


def test_a_pipeline_yaml_loads_its_plugins_and_keeps_them_in_to_dict(tmp_path, monkeypatch):
    folder = tmp_path / "configs"
    folder.mkdir()
    write_plugin(folder, name=det_name(tmp_path))
    cfg = {"plugins": ["my_detector.py"], "orientation": {"type": "fqa_complementary"},
           "detector": {"type": det_name(tmp_path)}, "corrections": [{"type": "zvu_dedrift"}]}
    (folder / "mine.yaml").write_text(yaml.safe_dump(cfg))
    monkeypatch.chdir(tmp_path)  # the path is relative to the YAML file, not to the working directory
    pipeline = Pipeline.from_yaml(folder / "mine.yaml")
    d = pipeline.to_dict()
    assert d["plugins"] == [str((folder / "my_detector.py").resolve())]
    rec = simulate(n_strides=3, rate=50.0, noise=NoiseModel(seed=0))
    builtin = Pipeline.from_dict({**cfg, "detector": {"type": "angular_rate_fsm"}, "plugins": []}).run(rec)
    np.testing.assert_array_equal(Pipeline.from_dict(d).run(rec).pos, builtin.pos)


# --------------------------------------------------------------------------- studies


# slow (7 s: two worker processes start): the fast suite runs plug-in files in workers with the tests below that
# take a config's plug-in and a calibration plug-in
@pytest.mark.slow
def test_a_study_with_a_plugin_file_runs_serially_and_with_two_jobs(tmp_path):
    write_plugin(tmp_path)
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(study_dict("my_detector.py", det_name(tmp_path))))
    serial = run_study(tmp_path / "study.yaml")
    parallel = run_study(Study.from_yaml(tmp_path / "study.yaml"), jobs=2)
    assert serial["error"].isna().all() and len(serial) == 2 * 2 * 4
    values = by_detector(serial)
    np.testing.assert_array_equal(values["mine"], values["builtin"])  # same algorithm, same numbers
    assert serial.equals(parallel)


@pytest.mark.slow
@ON_PROCESS_CLUSTER
def test_a_study_with_a_plugin_file_runs_on_a_local_dask_cluster_of_processes(tmp_path, process_cluster):
    write_plugin(tmp_path)
    study = Study.from_dict(study_dict("my_detector.py", det_name(tmp_path)), root=tmp_path)
    serial = run_study(study)
    distributed = run_study(study, scheduler=process_cluster.scheduler_address)
    assert distributed["error"].isna().all()
    assert serial.equals(distributed)


# the edited threshold, below the gyroscope's noise, misses stances; the guard marks them (expected warning)
@pytest.mark.filterwarnings(STANCES_GUARDED)
@pytest.mark.slow
def test_editing_the_plugin_reruns_its_cells_only(tmp_path):
    write_plugin(tmp_path, threshold=0.6)
    out = tmp_path / "out"
    d = study_dict("my_detector.py", det_name(tmp_path))
    first = run_study(Study.from_dict(d, root=tmp_path), out=out, jobs=2)
    write_plugin(tmp_path, threshold=0.01)  # the edited plug-in file: a threshold below the gyro noise
    second = run_study(Study.from_dict(d, root=tmp_path), out=out, jobs=2)
    # only the cells whose config uses the edited plug-in run again; the built-in detector's stay cached
    assert first.attrs["computed"] == 4 and second.attrs["computed"] == 2 and second.attrs["cached"] == 2
    rerun = set(second.loc[second["run"].isin(set(second["run"]) - set(first["run"])), "detector.type"])
    assert rerun == {det_name(tmp_path)}
    values = by_detector(second)
    assert not np.array_equal(values["mine"], values["builtin"])  # the edit took effect
    third = run_study(Study.from_dict(d, root=tmp_path), out=out)
    assert third.attrs["computed"] == 0 and third.equals(second)


@pytest.mark.slow  # two worker processes (about 6 s)
def test_a_base_config_with_plugins_is_resolved_against_its_own_folder(tmp_path):
    configs = tmp_path / "configs"
    configs.mkdir()
    write_plugin(configs, name=det_name(tmp_path))
    base = {"plugins": ["my_detector.py"], "orientation": {"type": "fqa_complementary"},
            "detector": {"type": det_name(tmp_path)}, "corrections": [{"type": "zvu_dedrift"}]}
    (configs / "mine.yaml").write_text(yaml.safe_dump(base))
    d = study_dict("configs/my_detector.py", det_name(tmp_path))
    del d["plugins"]
    d["base"] = "configs/mine.yaml"
    d["factors"] = {"detector.threshold": [0.6, 0.7]}
    study = Study.from_dict(d, root=tmp_path)
    assert study.plugins == [str((configs / "my_detector.py").resolve())]
    table = run_study(study, jobs=2)
    assert table["error"].isna().all() and len(table) == 2 * 2 * 4


def test_a_study_names_a_missing_plugin_file(tmp_path):
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump(study_dict("nowhere/my_detector.py", det_name(tmp_path))))
    with pytest.raises(ConfigError, match=r"study.yaml: plugins\[0\]: plug-in file '.*nowhere/my_detector.py' "
                                          r"does not exist"):
        Study.from_yaml(study)


def test_the_version_is_part_of_the_code_identity(tmp_path, monkeypatch):
    from footzoo import _version

    write_plugin(tmp_path)
    study = Study.from_dict(study_dict("my_detector.py", det_name(tmp_path)), root=tmp_path)
    keys = [c.key() for c in study.cells()]
    monkeypatch.setattr(_version, "__version__", "99.0")
    assert not set(keys) & {c.key() for c in study.cells()}


def test_a_plugin_that_writes_into_its_input_fails_its_cells_not_the_others(tmp_path):
    name = det_name(tmp_path)
    (tmp_path / "vandal.py").write_text(PLUGIN.format(threshold=0.6, name=name) + '''
    def detect(self, t, acc, gyr):
        acc *= 2.0  # a bug: changes the caller's recording
        return super().detect(t, acc, gyr)
''')
    d = study_dict("vandal.py", name)
    d["factors"] = {"detector.type": [name, "angular_rate_fsm"]}  # the vandal runs first on each recording
    table = run_study(Study.from_dict(d, root=tmp_path))
    mine = table[table["detector.type"] == name]
    expected = f"PluginError: detector '{name}'.*writes into an input array.*copy it first"
    assert mine["error"].str.contains(expected).all()
    clean = run_study(Study.from_dict({**d, "factors": {"detector.type": ["angular_rate_fsm"]}}, root=tmp_path))
    builtin = table[table["detector.type"] == "angular_rate_fsm"]
    np.testing.assert_array_equal(builtin["value"].to_numpy(), clean["value"].to_numpy())


@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)  # yun2012's calibration on a straight walk (expected)
def test_a_plugin_that_makes_its_input_writable_again_fails_its_cells_not_the_others(tmp_path):
    """The usual fix for "assignment destination is read-only" (setflags(write=True)) must not reach the shared
    recording: the frozen array is passed as a view, which cannot be made writable again."""
    name = det_name(tmp_path)
    (tmp_path / "unfreezer.py").write_text(PLUGIN.format(threshold=0.6, name=name) + '''
    def detect(self, t, acc, gyr):
        gyr.setflags(write=True)
        gyr[:, 2] += 0.05  # a bug: changes the caller's recording
        return super().detect(t, acc, gyr)
''')
    from footzoo.io.canonical import write

    write(simulate(path="straight", n_strides=4, rate=50), tmp_path / "walk.csv")  # a file's arrays own their data
    d = {**study_dict("unfreezer.py", name), "recordings": [str(tmp_path / "walk.csv")], "base": "yun2012"}
    d["factors"] = {"detector.type": [name, "angular_rate_fsm"]}
    # first the built-in alone (a process keeps the recordings it read: the clean values come first)
    clean = run_study(Study.from_dict({**d, "factors": {"detector.type": ["angular_rate_fsm"]}}, root=tmp_path))
    table = run_study(Study.from_dict(d, root=tmp_path))
    mine = table[table["detector.type"] == name]
    assert mine["error"].str.contains(f"PluginError: detector '{name}'.*makes it writable.*copy it first").all()
    builtin = table[table["detector.type"] == "angular_rate_fsm"]
    np.testing.assert_array_equal(builtin["value"].to_numpy(), clean["value"].to_numpy())


CALIBRATION = '''
from footzoo.calibration import HardIron
from footzoo.plugins.registry import register


@register
class MyHardIron(HardIron):
    """footzoo's hard_iron under another name (a test plug-in of the calibration kind)."""

    name = "{name}"
'''


@pytest.mark.slow  # two worker processes start and import the plug-in
def test_a_calibration_plugin_file_runs_in_a_parallel_study_like_the_builtin(tmp_path):
    name = "cal_" + "".join(c if c.isalnum() else "_" for c in tmp_path.name)
    (tmp_path / "my_calibration.py").write_text(CALIBRATION.format(name=name))
    study = {
        "name": "calibration_plugin",
        "plugins": ["my_calibration.py"],
        "base": {"name": "yun", "orientation": {"type": "fqa_complementary"}, "detector": {"type": "angular_rate_fsm"},
                 "corrections": [{"type": "zvu_dedrift"}]},
        "factors": {"calibration": [[{"type": "hard_iron"}], [{"type": name}]]},
        "recordings": [{"simulate": {"path": "rectangle", "length": 10.0, "width": 5.0, "rate": 50,
                                     "noise": {"scale": 1}}, "seeds": [0]}],
        "metrics": ["loop_closure_xy_m", "armse_3d_m"],
    }
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(study))
    serial = run_study(tmp_path / "study.yaml")
    parallel = run_study(Study.from_yaml(tmp_path / "study.yaml"), jobs=2)
    assert serial["error"].isna().all() and serial.equals(parallel)
    ok = serial[serial["metric"].notna()].sort_values("metric")
    mine = ok[ok["calibration"].str.contains(name)]["value"].to_numpy()
    builtin = ok[~ok["calibration"].str.contains(name)]["value"].to_numpy()
    np.testing.assert_array_equal(mine, builtin)  # same algorithm, same numbers, in the workers too
