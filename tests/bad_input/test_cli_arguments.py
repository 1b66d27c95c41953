"""Command-line arguments out of range, malformed or in the wrong place: a usage error naming the fix, before any work.

Table-driven: each case is an argument list (built in a temporary folder), the exit code and a fragment
of the message; none may print a traceback or take the internal-error exit code.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from footzoo.apps.cli import EXIT_DATA, EXIT_USAGE, build_parser, main
from footzoo.core.errors import ConfigError
from footzoo.io.canonical import write
from footzoo.sim import simulate
from footzoo.studies.runner import check_scheduler
from footzoo.studies.study import max_jobs

ROOT = Path(__file__).resolve().parents[2]
YUN = ROOT / "configs" / "yun2012.yaml"
QUICK = ROOT / "configs" / "study_quick.yaml"


@pytest.fixture(scope="module")
def walk(tmp_path_factory) -> Path:
    return write(simulate(n_strides=2, rate=50.0), tmp_path_factory.mktemp("walk") / "walk.csv")


@pytest.fixture(scope="module")
def walk_text(walk) -> bytes:
    return walk.read_bytes()


def _tune_file(d: Path) -> Path:
    text = QUICK.read_text().replace("base: yun2012.yaml", f"base: {YUN}")
    (d / "tune.yaml").write_text(text + "tune: {objective: armse_3d_m, group_by: '(s[0-9])$'}\n")
    return d / "tune.yaml"


def _sim(d: Path, *option: str) -> list[str]:
    return ["simulate", "straight", *option, "--out", str(d / "s.csv")]


CASES = [
    # every numeric option with its range
    ("seed-negative", lambda d, w: _sim(d, "--seed", "-1"), EXIT_USAGE, "argument --seed: -1 is out of range: it must "
                                                                         "be a whole number >= 0"),
    ("seed-fraction", lambda d, w: _sim(d, "--seed", "1.5"), EXIT_USAGE, "argument --seed: '1.5' is not a whole"),
    ("strides-zero", lambda d, w: _sim(d, "--strides", "0"), EXIT_USAGE, "argument --strides: 0 is out of range"),
    ("stride-length-zero", lambda d, w: _sim(d, "--stride-length", "0"), EXIT_USAGE, "--stride-length: 0 m is out"),
    ("rate-huge", lambda d, w: _sim(d, "--rate", "1e9"), EXIT_USAGE, "argument --rate: 1e9 Hz is out of range"),
    ("noise-negative", lambda d, w: _sim(d, "--noise-scale", "-1"), EXIT_USAGE, "argument --noise-scale: -1"),
    ("fpa-beyond-90", lambda d, w: _sim(d, "--fpa", "200"), EXIT_USAGE, "argument --fpa: 200 deg is out of range"),
    ("mount-yaw-beyond-180", lambda d, w: _sim(d, "--mount-yaw", "400"), EXIT_USAGE, "--mount-yaw: 400 deg is out"),
    ("biases-unknown", lambda d, w: _sim(d, "--biases", "acc,foo"), EXIT_USAGE,
     "argument --biases: 'foo': unknown bias; give a comma-separated list of acc, gyr, mag"),
    ("jobs-zero", lambda d, w: ["ablate", str(QUICK), "--jobs", "0"], EXIT_USAGE,
     "argument --jobs: 0 must be a number of worker processes"),
    ("jobs-minus-five", lambda d, w: ["ablate", str(QUICK), "--jobs", "-5"], EXIT_USAGE, "or -1 for one per core"),
    ("jobs-huge", lambda d, w: ["tune", str(QUICK), "--jobs", "100000"], EXIT_USAGE,
     f"1 (serial) to {max_jobs()}"),
    ("max-cells-zero", lambda d, w: ["ablate", str(QUICK), "--max-cells", "0"], EXIT_USAGE,
     "argument --max-cells: 0 is out of range"),
    ("cache-age-negative", lambda d, w: ["ablate", str(QUICK), "--cache-max-age", "-1"], EXIT_USAGE,
     "argument --cache-max-age: -1 days is out of range"),
    ("cache-size-nan", lambda d, w: ["ablate", str(QUICK), "--cache-max-size", "nan"], EXIT_USAGE,
     "argument --cache-max-size: nan MB is out of range"),
    ("calibrate-out-not-yaml", lambda d, w: ["calibrate", "--data", str(w), "--out", str(d / "fv.csv")], EXIT_USAGE,
     "the foot-vector calibration is a YAML file, which huang_fpa's calibration: reads; name it 'fv.yaml'"),
    ("still-text", lambda d, w: ["calibrate", "--data", str(w), "--still", "a", "b", "--out", str(d / "f.yaml")],
     EXIT_USAGE, "argument --still: 'a' is not a number"),
    ("ablate-out-empty", lambda d, w: ["ablate", str(QUICK), "--out", ""], EXIT_USAGE, "argument --out: an empty path"),
    # a NUL character no file name can hold (was: internal error, ValueError: embedded null byte)
    ("run-out-nul", lambda d, w: ["run", "yun2012", "--data", str(w), "--out", "o\x00ut"], EXIT_USAGE,
     "argument --out: the path 'o\\x00ut' holds a NUL character (\\x00) at position 1, which no file name can"),
    ("run-data-nul", lambda d, w: ["run", "yun2012", "--data", "wa\x00lk.csv"], EXIT_DATA,
     "recording 'wa\\x00lk.csv' holds a NUL character"),
    ("configs-to-nul", lambda d, w: ["configs", "--copy", "yun2012", "--to", "a\x00.yaml"], EXIT_USAGE,
     "argument --to: the path 'a\\x00.yaml' holds a NUL character"),
    # a malformed scheduler address, before any work (Dask's own parser would fail late, with a bare ValueError)
    *[(f"scheduler-{i}", lambda d, w, a=a: ["ablate", str(QUICK), "--scheduler", a], EXIT_USAGE, fragment)
      for i, (a, fragment) in enumerate([
          ("garbage", "is not HOST:PORT with a port in 1-65535"), ("tcp://", "is not HOST:PORT"),
          ("tcp://host:99999", "is not HOST:PORT with a port in 1-65535"),
          ("http://host:8786", "unknown protocol 'http'"), ("inproc://x", "is not an in-process address (inproc://HOST/PID/N"),
          ("", "is not HOST:PORT"), ("tcp://[::1:8786", "the IPv6 host must be in brackets")])],
    # a reader's option given twice: the last one would silently win
    ("option-given-twice", lambda d, w: ["run", "yun2012", "--data", str(w), "--option", "max_gap=1", "--option",
                                         "max_gap=2"], EXIT_USAGE,
     "the reader's option 'max_gap' is given twice (--option max_gap=1 and --option max_gap=2); give it once"),
    ("unit-given-twice", lambda d, w: ["run", "yun2012", "--data", str(w), "--acc-unit", "g", "--option",
                                       "acc_unit=m/s^2"], EXIT_USAGE, "(--option acc_unit=m/s^2 and --acc-unit g)"),
    ("option-nan", lambda d, w: ["run", "yun2012", "--data", str(w), "--option", "max_gap=nan"], EXIT_USAGE,
     "max_gap must be a finite number, got 'nan'"),
    # a name, a metric or a destination that cannot be what was meant
    ("list-kind-of-another", lambda d, w: ["list", "shoe", "--kind", "orientation"], EXIT_USAGE,
     "no orientation plug-in named 'shoe': 'shoe' is a detector plug-in; leave out --kind orientation"),
    ("show-unknown-metric", lambda d, w: ["ablate", str(QUICK), "--show", "strides,armse_3d"], EXIT_USAGE,
     "argument --show: 'armse_3d' is not a metric (did you mean 'armse_3d_m'?)"),
    ("compile-ship-a-file", lambda d, w: [(d / "k.txt").write_text("x"), "compile"][1:] + [
        "yun2012", "--ship", "k.txt"], EXIT_USAGE,
     "argument --ship: 'k.txt' is a file, not a folder; give a folder name"),
    ("configs-copy-empty", lambda d, w: ["configs", "--copy", ""], EXIT_USAGE, "argument --copy: an empty name"),
    ("simulate-biases-empty", lambda d, w: ["simulate", "straight", "--out", "s.csv", "--biases", ""], EXIT_USAGE,
     "argument --biases: an empty list; give a comma-separated list of acc, gyr, mag"),
    ("run-data-from-stdin", lambda d, w: ["run", "yun2012", "--data", "-"], EXIT_USAGE,
     "argument --data: '-' (standard input): footzoo reads a recording from a file"),
    ("run-out-to-stdout", lambda d, w: ["run", "yun2012", "--data", str(w), "--out", "-"], EXIT_USAGE,
     "argument --out: '-' (standard output): footzoo writes its outputs to files"),
    ("simulate-out-to-stdout", lambda d, w: ["simulate", "straight", "--out", "-"], EXIT_USAGE,
     "argument --out: '-' (standard output)"),
    ("configs-to-without-copy", lambda d, w: ["configs", "--to", str(d / "mine")], EXIT_USAGE,
     "--to goes with --copy NAME"),
    ("configs-to-not-yaml", lambda d, w: ["configs", "--copy", "yun2012", "--to", str(d / "mine.txt")], EXIT_USAGE,
     "a config is a YAML file; name the copy 'mine.yaml', or give a folder"),
    ("simulate-out-a-folder", lambda d, w: [(d / "o").mkdir(), "simulate"][1:] + ["straight", "--out", "o"], EXIT_DATA,
     "error: --out 'o' is a directory; give a file name"),
    ("run-config-link-loop", lambda d, w: [(d / "loop.yaml").symlink_to("loop.yaml"), "run"][1:] + [
        "loop.yaml", "--data", str(w)], EXIT_USAGE, "config file 'loop.yaml' is a symbolic link in a loop"),
    ("tune-config-over-a-recording", lambda d, w: ["tune", str(_tune_file(d)), "--out", str(d / "o"), "--config",
                                                   str(w)], EXIT_USAGE,
     "the chosen setting is written as a YAML config; name the file 'walk.yaml'"),
    # arguments in the wrong place
    ("run-swapped", lambda d, w: ["run", str(w), str(YUN)], EXIT_USAGE,
     f"the config comes first and the recording after --data (swapped?): footzoo run {YUN} --data "),
    ("run-swapped-shipped-name", lambda d, w: ["run", str(w), "yun2012"], EXIT_USAGE,
     "the config comes first and the recording after --data (swapped?): footzoo run yun2012 --data "),
    ("run-swapped-with-data", lambda d, w: ["run", str(w), "--data", str(YUN)], EXIT_USAGE,
     f"a config file: the config comes first and the recording after --data (swapped?): footzoo run {YUN} --data "),
    ("run-recording-as-extra", lambda d, w: ["run", "yun2012", str(w)], EXIT_USAGE,
     "a recording goes after --data: footzoo run yun2012 --data "),
    ("run-recording-as-config", lambda d, w: ["run", str(w)], EXIT_USAGE,
     "is a recording (.csv file), not a config file (YAML): a recording goes to --data"),
    ("validate-recording", lambda d, w: ["validate", str(w)], EXIT_USAGE, "is a recording (.csv file)"),
    ("run-config-as-data", lambda d, w: ["run", "yun2012", "--data", str(YUN)], EXIT_DATA,
     "a YAML file (a config or study?), not a recording"),
    ("run-a-study", lambda d, w: ["run", str(QUICK)], EXIT_USAGE,
     "this is a study file (base, recordings), not a pipeline config: run it with footzoo ablate FILE "
     "(footzoo validate FILE checks it)"),
    ("ablate-a-config", lambda d, w: ["ablate", str(YUN)], EXIT_USAGE,
     "this is a pipeline config (orientation, detector, ...), not a study: run it with footzoo run FILE"),
]


@pytest.mark.parametrize("argv, code, fragment", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_arguments_are_a_usage_error_before_any_work(argv, code, fragment, tmp_path, walk, walk_text, capsys,
                                                        monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv(tmp_path, walk)) == code
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err
    assert not (tmp_path / "s.csv").exists()
    assert walk.read_bytes() == walk_text  # never replaced by an output


def test_case_ids_are_unique():
    assert len({c[0] for c in CASES}) == len(CASES)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.sampled_from(["--seed", "--strides", "--stride-length", "--rate", "--noise-scale", "--fpa", "--mount-yaw"]),
       st.one_of(st.integers(-10**12, 10**12).map(str), st.floats(allow_nan=True, allow_infinity=True).map(repr),
                 st.text(max_size=6)))
def test_property_a_numeric_option_is_parsed_in_range_or_refused_as_usage(option, value):
    """Any text for a numeric option: argparse's usage error (exit 2), or a value inside the option's range."""
    ranges = {"--seed": (0, 2**63 - 1), "--strides": (1, 100_000), "--stride-length": (0.05, 5.0),
              "--rate": (10.0, 20_000.0), "--noise-scale": (0.0, 1000.0), "--fpa": (-90.0, 90.0),
              "--mount-yaw": (-180.0, 180.0)}
    if value.startswith("-"):
        try:
            float(value)
        except ValueError:
            return  # an option's name (-h, --x), not a value
    try:
        args = build_parser().parse_args(["simulate", "straight", "--out", "x.csv", option, value])
    except SystemExit as stop:
        assert stop.code == 2
        return
    got = getattr(args, option.lstrip("-").replace("-", "_"))
    lo, hi = ranges[option]
    assert lo <= got <= hi


@settings(max_examples=80, deadline=None, derandomize=True)
@given(st.one_of(st.text(max_size=30), st.builds(lambda s, h, p: f"{s}://{h}:{p}",
                                                 st.sampled_from(["tcp", "tls", "http", "", "ws"]),
                                                 st.text(alphabet="abc.019:[]", max_size=8),
                                                 st.integers(-5, 70000))))
def test_property_a_scheduler_address_is_normalised_or_refused(address):
    try:
        out = check_scheduler(address)
    except ConfigError:
        return
    scheme, _, rest = out.partition("://")
    host, _, port = rest.rpartition(":")
    assert scheme in ("tcp", "tls", "ws", "wss", "ucx") and host and 1 <= int(port) <= 65535


def test_a_name_the_terminal_cannot_show_is_escaped_not_a_crash(tmp_path, monkeypatch):
    """With an ASCII-only terminal (LC_ALL=C, PYTHONIOENCODING=ascii) a non-ASCII name is printed escaped."""
    import io
    import sys

    monkeypatch.chdir(tmp_path)
    err = io.TextIOWrapper(io.BytesIO(), encoding="ascii")
    monkeypatch.setattr(sys, "stderr", err)
    assert main(["validate", "gång.yaml"]) == EXIT_USAGE
    err.flush()
    assert "g\\xe5ng.yaml" in err.buffer.getvalue().decode("ascii")


@pytest.mark.parametrize("scenario", ["run", "stairs"])
def test_every_simulator_path_is_a_simulate_scenario(scenario, tmp_path):
    """The command line offers what footzoo.sim.simulate offers (run and stairs were missing)."""
    from footzoo.io import load

    assert main(["simulate", scenario, "--strides", "4", "--rate", "50", "--out", str(tmp_path / "w.csv"),
                 "--quiet"]) == 0
    assert load(tmp_path / "w.csv").truth.pos is not None
