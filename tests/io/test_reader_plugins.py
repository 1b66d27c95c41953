"""Readers are plug-ins of the entry-point group footzoo.readers: built-ins, installed packages, the documented example.

Discovery is tested without installing anything, by putting a package folder with a ``.dist-info``
(``METADATA`` and ``entry_points.txt``) on ``sys.path``, which is what an installed wheel is to
:mod:`importlib.metadata`. The example package ``examples/readers/imulog`` is tested the same way
here, and once more as really installed when it is (CI installs it; the test skips otherwise).
"""

from __future__ import annotations

import configparser
import importlib
import re
import sys
import warnings
from importlib.metadata import PackageNotFoundError, distribution, entry_points
from pathlib import Path

import numpy as np
import pytest

import footzoo
from footzoo import FormatError
from footzoo.core.conventions import GRAVITY
from footzoo.core.errors import FootzooWarning
from footzoo.io import READERS, load, registry
from footzoo.io.canonical import write
from footzoo.sim import NoiseModel, simulate

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "readers" / "imulog"

FAKE_READERS = '''
from pathlib import Path

import numpy as np
import pandas as pd

from footzoo import Recording
from footzoo.io import Option, Reader


class TsvReader(Reader):
    """Tab-separated t, acc (m/s^2), gyr (rad/s), already FRD; first line '#tsv'."""

    description = "tab-separated test format"
    extensions = (".tsv",)
    options = {"scale": Option(1.0, "1", "factor on the accelerometer")}

    def guess_can_open(self, path):
        return Path(path).suffix == ".tsv" and Path(path).read_text().startswith("#tsv")

    def open(self, path, scale=1.0):
        d = pd.read_csv(path, sep="\\t", comment="#", header=None).to_numpy(float)
        return Recording(t=d[:, 0], acc=d[:, 1:4] * scale, gyr=d[:, 4:7], meta={"name": "tsv"})


class NamelessReader(Reader):
    """The same files, read without naming the recording."""

    description = "sets no name"

    def guess_can_open(self, path):
        return False

    def open(self, path):
        d = pd.read_csv(path, sep="\\t", comment="#", header=None).to_numpy(float)
        return Recording(t=d[:, 0], acc=d[:, 1:4], gyr=d[:, 4:7])


class GreedyReader(Reader):
    """Claims every .csv file (a badly written reader)."""

    description = "claims every csv"

    def guess_can_open(self, path):
        return str(path).endswith(".csv")

    def open(self, path):
        raise RuntimeError("never used in the tests")


class RaisingReader(Reader):
    description = "its guess raises"

    def guess_can_open(self, path):
        raise ZeroDivisionError("bug in the reader")

    def open(self, path):
        return None


class NotARecording(Reader):
    def guess_can_open(self, path):
        return False

    def open(self, path):
        return {"t": []}
'''


def install_fake(folder: Path, dist: str, module: str | None, source: str | None, entries: dict[str, str]) -> None:
    """A package as an installed wheel would leave it: the module and ``<dist>-0.1.dist-info``."""
    if module is not None:
        (folder / f"{module}.py").write_text(source or "")
    info = folder / f"{dist.replace('-', '_')}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[footzoo.readers]\n" + "".join(f"{k} = {v}\n" for k, v in entries.items()))


@pytest.fixture
def on_path(tmp_path, monkeypatch):
    """A folder on sys.path for fake installed packages; the readers are discovered again afterwards."""
    folder = tmp_path / "site"
    folder.mkdir()
    monkeypatch.syspath_prepend(str(folder))
    yield folder
    monkeypatch.undo()
    for name in [m for m in sys.modules if m.startswith(("fake_readers", "footzoo_imulog"))]:
        del sys.modules[name]
    importlib.invalidate_caches()
    registry.refresh()


def rediscover() -> registry.Readers:
    importlib.invalidate_caches()
    return registry.refresh()


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=3, rate=100.0, noise=NoiseModel(seed=3))


def test_setup_cfg_registers_every_builtin_reader_in_detection_order():
    cfg = configparser.ConfigParser()
    cfg.read(ROOT / "setup.cfg")
    lines = [ln.strip() for ln in cfg["options.entry_points"]["footzoo.readers"].strip().splitlines() if ln.strip()]
    table = dict(tuple(part.strip() for part in ln.split("=", 1)) for ln in lines)
    assert list(table.items()) == list(registry.BUILTIN.items())
    for target in table.values():  # each target is a reader class
        reader = registry._load_target(target)()
        assert callable(reader.guess_can_open) and callable(reader.open) and reader.description


def test_the_installed_distribution_lists_the_builtin_readers():
    try:
        dist = distribution("footzoo")
    except PackageNotFoundError:
        pytest.skip("footzoo is not installed (pip install . registers its readers)")
    eps = {ep.name: ep.value for ep in dist.entry_points if ep.group == registry.GROUP}
    if not eps:
        pytest.skip("the installed footzoo predates the footzoo.readers entry points: pip install . again")
    assert eps == registry.BUILTIN
    assert set(registry.BUILTIN) <= {ep.name for ep in entry_points(group=registry.GROUP)}


def test_a_reader_from_an_installed_package_loads_a_file_by_footzoo_load(on_path, tmp_path, walk):
    install_fake(on_path, "fake-readers", "fake_readers", FAKE_READERS, {"faketsv": "fake_readers:TsvReader"})
    readers = rediscover()
    assert "faketsv" in READERS and readers.origins["faketsv"] == "fake-readers"
    assert list(readers)[:len(registry.BUILTIN)] == list(registry.BUILTIN)  # built-ins first, in order
    data = tmp_path / "walk.tsv"
    rows = np.column_stack([walk.t, walk.acc, walk.gyr])
    data.write_text("#tsv\n" + "\n".join("\t".join(repr(float(v)) for v in r) for r in rows) + "\n")
    rec = footzoo.load(data)
    np.testing.assert_array_equal(rec.acc, walk.acc)
    assert rec.meta["format"] == "faketsv" and str(data) in rec.meta["input_files"]
    assert footzoo.load(data, scale=1.01).acc[0, 2] == 1.01 * walk.acc[0, 2]  # the option reaches open()
    with pytest.raises(FormatError, match=r"faketsv reader: unknown option 'scal' \(did you mean 'scale'\?\)"):
        footzoo.load(data, scal=2.0)
    # a reader without an axes option of its own gets one: applied to what it returns, named in meta
    turned = footzoo.load(data, axes="[x, -y, -z]")
    np.testing.assert_array_equal(turned.acc, walk.acc * [1.0, -1.0, -1.0])
    np.testing.assert_array_equal(turned.gyr, walk.gyr * [1.0, -1.0, -1.0])
    assert turned.meta["axes"] == "[x, -y, -z]" and "axes" not in rec.meta
    with pytest.raises(FormatError, match=r"axes: the axis map \[x, y, -z\] is left-handed"):
        footzoo.load(data, axes="[x, y, -z]")


def test_a_recording_its_reader_does_not_name_is_named_after_its_file(on_path, tmp_path, walk):
    install_fake(on_path, "fake-readers", "fake_readers", FAKE_READERS,
                 {"faketsv": "fake_readers:TsvReader", "nameless": "fake_readers:NamelessReader"})
    rediscover()
    data = tmp_path / "walk_07.tsv"
    rows = np.column_stack([walk.t, walk.acc, walk.gyr])
    data.write_text("#tsv\n" + "\n".join("\t".join(repr(float(v)) for v in r) for r in rows) + "\n")
    assert footzoo.load(data, format="nameless").name == "walk_07"  # not the default "recording"
    assert footzoo.load(data, format="faketsv").name == "tsv"  # a name the reader gives is kept


def test_broken_or_clashing_readers_are_skipped_with_the_reason_and_builtins_keep_working(on_path, walk, tmp_path):
    install_fake(on_path, "fake-readers", "fake_readers", FAKE_READERS,
                 {"broken": "no_such_module:Reader", "xio": "fake_readers:TsvReader", "Bad-Name": "fake_readers:X",
                  "raising": "fake_readers:RaisingReader", "dict": "fake_readers:NotARecording"})
    with pytest.warns(FootzooWarning) as caught:
        readers = rediscover()
    text = " | ".join(str(w.message) for w in caught)
    assert "the reader 'broken' of fake-readers (no_such_module:Reader) cannot be loaded: ModuleNotFoundError" in text
    assert "registers a reader named 'xio', which is a built-in format's name" in text
    assert "the reader name 'Bad-Name' must be lower case" in text
    assert readers["xio"].__class__.__module__ == "footzoo.io.xio"
    with pytest.raises(FormatError, match="format 'broken' is not available: the reader 'broken' of fake-readers"):
        footzoo.load(write(walk, tmp_path / "w.csv"), format="broken")
    with pytest.warns(FootzooWarning, match=r"reader 'raising' \(fake-readers\): guess_can_open raised "
                                            "ZeroDivisionError: bug in the reader; it was skipped"):
        assert footzoo.io.detect_format(tmp_path / "w.csv") == "canonical"  # the built-in still takes the file
    with pytest.raises(FormatError, match="the dict reader .* returned dict, not a footzoo Recording"):
        footzoo.load(tmp_path / "w.csv", format="dict")


def test_a_file_two_readers_claim_is_ambiguous_and_names_both(on_path, walk, tmp_path):
    install_fake(on_path, "fake-readers", "fake_readers", FAKE_READERS, {"greedy": "fake_readers:GreedyReader"})
    rediscover()
    data = write(walk, tmp_path / "w.csv")
    with pytest.raises(FormatError, match=r"more than one reader recognises this file \(canonical, greedy\).*"
                                          r"format='canonical' or format='greedy'"):
        footzoo.load(data)
    assert footzoo.load(data, format="canonical").n == walk.n  # an explicit format wins


def test_an_unknown_file_lists_every_format_and_how_to_choose_one(tmp_path):
    odd = tmp_path / "odd.csv"
    odd.write_text("time;ax;ay;az\n0;0;0;1\n")
    with pytest.raises(FormatError) as err:
        load(odd)
    text = str(err.value)
    for fmt in registry.BUILTIN:
        assert f"{fmt} (" in text
    assert "format= one of" in text and "--format NAME" in text and "odd.csv.footzoo.yaml" in text


# --------------------------------------------------------------------------- the documented example package

def imulog_text(rec, mounting="instep") -> str:
    """The recording written as the example's imulog format (µs, milli-g, milli-deg/s, logger axes)."""
    flip = np.array([1.0, -1.0, -1.0]) if mounting == "instep" else np.ones(3)
    rows = np.column_stack([np.round(rec.t * 1e6), rec.acc * flip / GRAVITY * 1000.0,
                            np.degrees(rec.gyr * flip) * 1000.0])
    body = "\n".join(" ".join(repr(float(v)) for v in r) for r in rows)
    return f"# imulog 1.0\n# device: FootLogger-3 serial 0042\n# columns: time_us ax_mg ...\n{body}\n"


def check_example_reads(path: Path, walk) -> None:
    rec = footzoo.load(path)
    assert rec.meta["format"] == "imulog"
    np.testing.assert_allclose(rec.acc, walk.acc, rtol=0, atol=1e-9)  # milli-g and z up converted back to FRD, SI
    np.testing.assert_allclose(rec.gyr, walk.gyr, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rec.t, np.round(walk.t * 1e6) * 1e-6)


def test_the_example_reader_works_from_its_folder(on_path, tmp_path, walk):
    """The example's module and entry point, made visible to importlib.metadata without pip."""
    install_fake(on_path, "footzoo-imulog", None, None, {"imulog": "footzoo_imulog:ImuLogReader"})
    on_path.joinpath("footzoo_imulog.py").write_text((EXAMPLE / "footzoo_imulog.py").read_text())
    rediscover()
    data = tmp_path / "walk.imulog"
    data.write_text(imulog_text(walk))
    check_example_reads(data, walk)
    sole = tmp_path / "sole.txt"
    sole.write_text(imulog_text(walk, "sole"))
    rec = footzoo.load(sole, mounting="sole")
    np.testing.assert_allclose(rec.acc, walk.acc, rtol=0, atol=1e-9)
    with pytest.raises(FormatError, match="mounting='heel': use one of"):
        footzoo.load(sole, mounting="heel")


def test_the_installed_example_package_loads_a_file_by_footzoo_load(tmp_path, walk):
    names = {ep.name: ep for ep in entry_points(group=registry.GROUP)}
    if "imulog" not in names:
        pytest.skip("the example reader is not installed: pip install ./examples/readers/imulog (CI does)")
    assert names["imulog"].dist.name == "footzoo-imulog"
    rediscover()
    data = tmp_path / "walk.imulog"
    data.write_text(imulog_text(walk))
    with warnings.catch_warnings():
        warnings.simplefilter("error", FootzooWarning)  # no reader skipped
        check_example_reads(data, walk)


@pytest.mark.parametrize("first, found", [("# imulog 2.0", "'2.0'"), ("# imulog", "'(none given)'")])
def test_the_example_reader_names_a_version_it_does_not_read_and_the_ones_it_reads(on_path, tmp_path, walk, first,
                                                                                     found):
    install_fake(on_path, "footzoo-imulog", None, None, {"imulog": "footzoo_imulog:ImuLogReader"})
    on_path.joinpath("footzoo_imulog.py").write_text((EXAMPLE / "footzoo_imulog.py").read_text())
    rediscover()
    data = tmp_path / "walk.imulog"
    data.write_text(imulog_text(walk).replace("# imulog 1.0", first, 1))
    with pytest.raises(FormatError, match=rf"an imulog file of version {re.escape(found)}; this reader "
                                          r"\(footzoo-imulog\) reads version\(s\) 1.0: update footzoo-imulog"):
        footzoo.load(data)
