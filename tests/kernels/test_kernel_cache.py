"""Shipped kernels: ``footzoo compile --ship`` writes machine code a new process loads instead of compiling.

Each case runs in new processes with their own empty numba cache, and counts the footzoo kernels
numba compiles there (numba's compile events).
"""

import json
import os
import pickle
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from footzoo.apps.cli import main as cli_main
from footzoo.kernels import jit as _jit

from ..conftest import made_once

ROOT = Path(__file__).resolve().parents[2]
CONFIG = str(ROOT / "configs" / "yun2012.yaml")
pytestmark = pytest.mark.skipif(not _jit.HAVE_NUMBA, reason="needs numba")

# run the config on a simulated walk; print the footzoo kernels numba compiled and the end position
RUN = f"""
import json, warnings
warnings.simplefilter("ignore")
from numba.core import event
import footzoo
from footzoo.sim import simulate
compiled = []
class Listener(event.Listener):
    def on_start(self, ev):
        d = ev.data.get("dispatcher")
        if d is not None and getattr(d.py_func, "__module__", "").startswith("footzoo"):
            compiled.append(d.py_func.__qualname__)
    def on_end(self, ev):
        pass
rec = RECORDING
with event.install_listener("numba:compile", Listener()):
    result = footzoo.Pipeline.from_yaml({CONFIG!r}).run(rec)
print(json.dumps({{"compiled": compiled, "pos": result.pos[-1].tolist()}}))
""".replace("RECORDING", 'simulate(n_strides=6, rate=100.0, profile="physical")')


@pytest.fixture(autouse=True)
def no_inherited_shipped_kernels(monkeypatch):
    """These tests choose the shipped folder of each process themselves: not the installed wheel's (conftest.py)."""
    monkeypatch.delenv("FOOTZOO_SHIPPED_KERNELS", raising=False)


def _run(code_or_args: str | list[str], cache: Path, shipped: Path | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    env.pop("FOOTZOO_SHIPPED_KERNELS", None)
    if shipped is not None:
        env["FOOTZOO_SHIPPED_KERNELS"] = str(shipped)
    args = ["-c", code_or_args] if isinstance(code_or_args, str) else ["-m", "footzoo", *code_or_args]
    proc = subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc


def _cached_files(folder: Path) -> list[Path]:
    return sorted(folder.rglob("*.nbi"))


@pytest.fixture(scope="module")
def shipped(tmp_path_factory):
    """A folder of shipped kernels for yun2012, written by ``footzoo compile --ship`` (once for all workers)."""

    def make(tmp: Path) -> None:
        proc = _run(["compile", "--ship", str(tmp / "shipped"), CONFIG], cache=tmp / "cache")
        assert "yun2012.yaml" in proc.stdout

    return made_once(tmp_path_factory, "shipped-yun2012", make)


@pytest.mark.slow
def test_shipping_writes_the_kernels_into_the_folder_and_not_into_numbas_cache(shipped):
    names = [p.name for p in _cached_files(shipped / "shipped")]
    # the folders mirror the package's modules (orientation/fqa.py -> orientation/)
    assert any(p.parent.name == "orientation" and p.name.startswith("fqa.") for p in _cached_files(shipped / "shipped"))
    assert any(n.startswith("fsm.") or n.startswith("angular_rate_fsm.") for n in names) or len(names) >= 5
    assert _cached_files(shipped / "cache") == []


def _kernel_names(folder: Path) -> list[str]:
    """The footzoo kernels with machine code in a numba cache folder (index files ``module.qualname-line.pyXY.nbi``)."""
    return sorted({p.name.split(".", 1)[1].rsplit("-", 1)[0] for p in _cached_files(folder)})


@pytest.fixture(scope="module")
def cold(tmp_path_factory):
    """``footzoo compile`` of the config into an empty numba cache, nothing shipped, then :data:`RUN` in a new
    process with that cache: the kernels a new process compiles, what the run compiled and where it ends (once
    for all workers)."""

    def make(tmp: Path) -> None:
        _run(["compile", CONFIG], cache=tmp / "cache")
        after = json.loads(_run(RUN, cache=tmp / "cache").stdout)
        (tmp / "run.json").write_text(json.dumps({"cached": _kernel_names(tmp / "cache"), **after}))

    return json.loads((made_once(tmp_path_factory, "cold-yun2012", make) / "run.json").read_text())


@pytest.mark.slow
def test_a_new_process_loads_the_shipped_kernels_instead_of_compiling(shipped, cold, tmp_path):
    warm = json.loads(_run(RUN, cache=tmp_path / "b", shipped=shipped / "shipped").stdout)
    assert len(cold["cached"]) >= 5  # without the folder: compiled
    assert warm["compiled"] == []
    assert warm["pos"] == cold["pos"]  # the same machine code
    assert _cached_files(tmp_path / "b") == []  # nothing had to be compiled and cached


@pytest.mark.slow  # its fixture compiles a config from nothing (about 12 s), as the other shipping tests
def test_a_recording_read_from_a_file_without_magnetometer_needs_no_compilation_either(shipped, tmp_path):
    """The shipped code covers what readers give (pandas' read-only columns, no magnetometer), not only simulations."""
    from footzoo.io.canonical import write
    from footzoo.sim import simulate

    path = tmp_path / "walk.csv"
    write(simulate(n_strides=6, rate=100.0, profile="physical", magnetometer=False), path)
    run = RUN.replace('simulate(n_strides=6, rate=100.0, profile="physical")', f"footzoo.load({str(path)!r})")
    warm = json.loads(_run(run, cache=tmp_path / "b", shipped=shipped / "shipped").stdout)
    assert warm["compiled"] == []
    assert np.all(np.isfinite(warm["pos"]))


#: The shipped kernel the damaged-folder tests change (a leaf: no other kernel calls it), and its files' stem.
CHANGED_KERNEL, CHANGED_FILES = "_dedrift_kernel", "zvu_dedrift._dedrift_kernel-"


def _copy_with_one_kernel(shipped: Path, to: Path) -> list[Path]:
    """A copy of the shipped folder and the files of :data:`CHANGED_KERNEL` in it."""
    shutil.copytree(shipped, to)
    files = sorted(to.rglob(f"{CHANGED_FILES}*"))
    assert {f.suffix for f in files} == {".nbi", ".nbc"}, files
    return files


@pytest.mark.slow
def test_shipped_code_of_a_changed_source_file_is_ignored_not_used(shipped, cold, tmp_path):
    """Only the kernel whose source changed is compiled again; the others still load."""
    files = _copy_with_one_kernel(shipped / "shipped", tmp_path / "shipped")
    for index in (f for f in files if f.suffix == ".nbi"):  # as if its source had changed since: another hash
        with open(index, "rb") as f:
            version = pickle.load(f)
            stamp, overloads = pickle.loads(f.read())
        with open(index, "wb") as f:
            pickle.dump(version, f)
            f.write(pickle.dumps(("0" * 64, overloads)))
    stale = json.loads(_run(RUN, cache=tmp_path / "b", shipped=tmp_path / "shipped").stdout)
    assert CHANGED_KERNEL in cold["cached"]
    assert stale["compiled"] == [CHANGED_KERNEL]
    assert stale["pos"] == cold["pos"]


@pytest.mark.slow
def test_compile_without_ship_fills_numbas_cache(cold):
    assert len(cold["cached"]) >= 5
    assert cold["compiled"] == []  # the next process compiled nothing: every kernel came from the cache
    assert np.all(np.isfinite(cold["pos"]))


def test_ship_refuses_a_process_that_already_compiled(monkeypatch, tmp_path):
    from footzoo.apps.compile import compile_kernels

    monkeypatch.setattr(_jit, "_materialised", True)
    with pytest.raises(RuntimeError, match="new process"):
        compile_kernels([CONFIG], ship=tmp_path)


def test_compile_takes_a_study_file_for_every_config_of_its_grid(capsys):
    assert cli_main(["compile", str(ROOT / "configs" / "study_quick.yaml")]) == 0
    lines = capsys.readouterr().out.splitlines()
    # 2 detectors x 2 corrections on one base: four distinct pipelines, whatever the recordings
    assert len(lines) == 4
    assert sum("detector.type=shoe" in line for line in lines) == 2


def test_compile_names_a_file_that_is_not_a_config(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("orientation: {type: no_such_filter}\n")
    assert cli_main(["compile", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.yaml" in err or "no_such_filter" in err


@pytest.mark.slow
def test_a_damaged_shipped_file_is_compiled_instead_with_a_warning(shipped, cold, tmp_path):
    """Only the kernel whose machine code cannot be read is compiled; the others still load."""
    for data in (f for f in _copy_with_one_kernel(shipped / "shipped", tmp_path / "shipped") if f.suffix == ".nbc"):
        data.write_bytes(b"not a pickle")
    proc = _run(RUN.replace('warnings.simplefilter("ignore")', 'warnings.simplefilter("default")'),
                cache=tmp_path / "b", shipped=tmp_path / "shipped")
    result = json.loads(proc.stdout)
    assert result["compiled"] == [CHANGED_KERNEL]
    assert result["pos"] == cold["pos"]
    assert "could not be loaded" in proc.stderr


@pytest.mark.slow
def test_compile_loads_a_configs_own_plug_in_and_a_new_process_then_compiles_none_of_it(tmp_path):
    """A user's Kalman correction (the plug-in guide's example, beside its YAML) is compiled and cached like a
    built-in one, whichever folder the command runs from. The built-in kernels come from the installed wheel
    when there is one (conftest.py), so both processes compile only what the plug-in adds."""
    from footzoo.kernels.installed import installed_kernels

    plugin = ROOT / "examples" / "plugins" / "magnetometer_heading_update.py"
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / plugin.name).write_text(plugin.read_text())
    config = folder / "magu.yaml"
    config.write_text(f"plugins: [{plugin.name}]\norientation: {{type: ins}}\ndetector: {{type: shoe}}\n"
                      "corrections: [{type: ekf_zupt}, {type: magnetometer_heading}]\n")
    env_run = dict(cache=tmp_path / "cache", shipped=installed_kernels())
    shipped_env = {} if env_run["shipped"] is None else {"FOOTZOO_SHIPPED_KERNELS": str(env_run["shipped"])}
    # the footzoo the other processes here run (the checkout, not an installed copy: another source, another cache)
    path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    proc = subprocess.run([sys.executable, "-m", "footzoo", "compile", str(config)], capture_output=True, text=True,
                          cwd=tmp_path, timeout=600,
                          env={**os.environ, "NUMBA_CACHE_DIR": str(env_run["cache"]), "PYTHONPATH": path,
                               **shipped_env})
    assert proc.returncode == 0, proc.stderr[-3000:]
    run = RUN.replace(f"footzoo.Pipeline.from_yaml({CONFIG!r})", f"footzoo.Pipeline.from_yaml({str(config)!r})")
    after = json.loads(_run(run, **env_run).stdout)
    assert after["compiled"] == []  # the plug-in's measure function too: it is in numba's cache
    assert np.all(np.isfinite(after["pos"]))


@pytest.mark.skipif(not _jit.HAVE_NUMBA, reason="numba not installed")
def test_a_read_only_recording_runs_the_same_compiled_loop():
    """A study freezes its shared recordings; their read-only arrays must not type (and compile) a second loop."""
    from footzoo import Pipeline
    from footzoo.filters import forward
    from footzoo.sim import simulate
    from footzoo.studies.runner import _read_only

    pipe = Pipeline.from_yaml("nguyen2016")
    writable = pipe.run(simulate("rectangle", rate=100, seed=1))
    n = len(forward.run.signatures)
    frozen = _read_only(simulate("rectangle", rate=100, seed=1))
    assert not frozen.acc.flags.writeable
    again = pipe.run(frozen)
    assert len(forward.run.signatures) == n
    np.testing.assert_array_equal(again.pos, writable.pos)
    assert not frozen.acc.flags.writeable  # the recording itself stays frozen




@pytest.mark.slow
def test_kernels_shipped_in_parts_are_all_read(shipped, tmp_path):
    """A wheel's build compiles groups of configs side by side, each into its own part of the folder
    (``part-0``, ``part-1``...): a new process looks a kernel up in every part."""
    folders = sorted(p for p in (shipped / "shipped").iterdir() if p.is_dir())
    assert len(folders) >= 2
    for k, part in enumerate((folders[:1], folders[1:])):  # one subpackage's kernels in part-0, the rest in part-1
        for folder in part:
            shutil.copytree(folder, tmp_path / "parts" / f"part-{k}" / folder.name)
    warm = json.loads(_run(RUN, cache=tmp_path / "b", shipped=tmp_path / "parts").stdout)
    assert warm["compiled"] == []  # each kernel found in whichever part holds it
    assert _cached_files(tmp_path / "b") == []
