"""Property-based fuzzing: readers, YAML, configs, studies and live samples raise only footzoo's documented errors.

The plug-ins' parameters and the settings blocks are fuzzed with values derived from their declarations
(:mod:`footzoo.core.params`: the values each declaration refuses, its edges, numbers in and around its
range), so a plug-in registered tomorrow is fuzzed without a line here.

Documented errors: :class:`~footzoo.core.errors.FootzooError` and its subclasses
(``ConfigError``, ``RecordingError``, ``FormatError``). Anything else escaping
is a bug. Parsing is bounded by the loader's limits (size, depth, aliases), so
every example finishes quickly with bounded memory.

Each property runs twice: a small CI profile (the whole file in well under a
minute) and a ``nightly`` profile with many more examples, skipped unless
``-m nightly`` is given or ``FOOTZOO_NIGHTLY=1`` is set.
"""

from __future__ import annotations

import math
import os
import tempfile
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from footzoo import Pipeline
from footzoo.config import TOP_LEVEL_KEYS
from footzoo.core.checks import validate_sample
from footzoo.core.errors import ConfigError, FootzooError
from footzoo.core.yamlsafe import load_text
from footzoo.io import READERS, load
from footzoo.plugins.registry import KINDS, available, build
from footzoo.runtime.validate import settings_declarations
from footzoo.studies.study import STUDY_KEYS, Study

CI_EXAMPLES = int(os.environ.get("FOOTZOO_FUZZ_EXAMPLES", "25"))
NIGHTLY_EXAMPLES = 2000


def _settings(examples: int, ci: bool = True) -> settings:
    return settings(max_examples=examples, deadline=None, database=None, derandomize=ci,
                    suppress_health_check=list(HealthCheck))


def _only_footzoo_errors(action: Callable[[], object]) -> object:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return action()
        except FootzooError:
            return None


# --------------------------------------------------------------------------- strategies
CELL = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-10**6, 10**6).map(str),
    st.sampled_from(["", "nan", "inf", "-inf", "1e400", "1e30", "-0", "abc", '"', "1,2", "0x10", "\t", "é"]),
    st.text(alphabet="0123456789.-+eE ", max_size=8),
)
HEADERS = [
    "t,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z",
    "t,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z,dist_a,true_pos_n,true_pos_e,true_pos_d,true_stance",
    "Time (s),Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),Accelerometer X (g),"
    "Accelerometer Y (g),Accelerometer Z (g)",
    "Time,d:scaledAccelX,d:scaledAccelY,d:scaledAccelZ,d:scaledGyroX,d:scaledGyroY,d:scaledGyroZ",
    "sensor,left_sensor,left_sensor,left_sensor,left_sensor,left_sensor,left_sensor\n"
    "axis,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z",
    "\nInertial data.\n\nHeader: a_x [g]: a_y [g]: a_z [g]: ar_x [rad/s]: ar_y [rad/s]: ar_z [rad/s]: Counter: "
    "Checksum: Nr: Filtered ts[s]: Unfiltered ts[s]: Pred. ts[s]: Freq. [Hz]: m_x [G]: m_y [G]: m_z [G]:",
    "dummy_header " * 32,
]
HEADER = st.one_of(st.sampled_from(HEADERS), st.text(max_size=60).filter(lambda s: "\n" not in s and "\r" not in s))
ROWS = st.lists(st.one_of(st.lists(CELL, min_size=0, max_size=17).map(",".join),
                          st.lists(CELL, min_size=0, max_size=17).map("   ".join)), max_size=40)
SCALAR = st.one_of(
    st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(allow_nan=True, allow_infinity=True),
    st.floats(0.0, 2.0), st.text(max_size=8), st.sampled_from(["no", "yes", "half", ".inf", "1:30", "0.5", "off"]),
)
VALUE = st.recursive(SCALAR, lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=6), c, max_size=3),
                     max_leaves=8)
YAMLISH = st.lists(st.sampled_from(list(":-[]{}&*!|>'\"#,?% \n\t<=@`~abcxyz019.") + ["<<", "!!", "&a", "*a", "\u00e9",
                                                                                  "\n  ", ": ", "- "]),
                   max_size=120).map("".join)


def _yamlable(value) -> bool:
    try:
        yaml.safe_dump(value)
        return True
    except yaml.YAMLError:
        return False


def declared_values(param, default, yaml_only: bool = False) -> st.SearchStrategy:
    """Values for one declared parameter: the ones its declaration refuses or accepts at the edges, numbers inside
    and around its range, and anything (derived from the declaration, so a new plug-in is fuzzed too)."""
    edge = param.edge_values(default)
    invalid = [v for v in param.invalid_values() if not yaml_only or _yamlable(v)]
    options = [st.sampled_from(invalid), VALUE]
    if edge:
        options.append(st.sampled_from(edge))
    interval = getattr(param, "interval", None)
    if interval is not None:
        lo = interval.lo if math.isfinite(interval.lo) else -1e6
        hi = interval.hi if math.isfinite(interval.hi) else 1e6
        inside = st.floats(lo, hi, exclude_min=interval.lo_open, exclude_max=interval.hi_open) if lo < hi else None
        around = st.floats(lo - (hi - lo) - 1.0, hi + (hi - lo) + 1.0)
        options += [around] + ([inside] if inside is not None else [])
        size = getattr(param, "size", None)
        if size is not None:  # a vector: rows of such numbers
            row = st.lists(inside if inside is not None else around, min_size=size, max_size=size)
            options += [row, st.lists(row, min_size=1, max_size=3)]
    return st.one_of(options)


def _spec(kind: str) -> st.SearchStrategy:
    plugins = available(kind)

    @st.composite
    def spec(draw):
        name = draw(st.sampled_from(sorted(plugins)))
        params = plugins[name].param_names()
        declaration = plugins[name].declaration()
        keys = draw(st.lists(st.sampled_from(params), unique=True, max_size=len(params))) if params else []
        out = {"type": name, **{k: draw(declared_values(declaration[k].param, declaration[k].default, True)
                                        if k in declaration and draw(st.booleans()) else VALUE) for k in keys}}
        if draw(st.booleans()):
            out[draw(st.text(max_size=6))] = draw(VALUE)
        return out

    return spec()


@st.composite
def configs(draw):
    cfg = {"orientation": draw(_spec("orientation")), "detector": draw(_spec("detector"))}
    if draw(st.booleans()):
        cfg["corrections"] = draw(st.lists(_spec("correction"), max_size=3))
    if draw(st.booleans()):
        cfg["analysis"] = draw(st.lists(_spec("analysis"), max_size=1))
    if draw(st.booleans()):
        cfg["gravity"] = draw(st.one_of(VALUE, st.floats(9.6, 10.0)))
    if draw(st.booleans()):
        cfg["init"] = draw(st.one_of(VALUE, st.fixed_dictionaries({}, optional={"duration": VALUE, "max_gyr": VALUE})))
    for key in draw(st.lists(st.sampled_from([*TOP_LEVEL_KEYS, "gravty", "extra"]), max_size=2)):
        cfg[key] = draw(VALUE)
    return cfg


@st.composite
def studies(draw):
    rec = st.one_of(
        st.fixed_dictionaries({"simulate": VALUE}, optional={"seeds": VALUE, "repeats": VALUE, "label": VALUE}),
        st.fixed_dictionaries({"path": st.one_of(VALUE, st.text(alphabet="abc_", max_size=5))},
                              optional={"format": VALUE}),
        VALUE,
    )
    d = {"base": draw(st.one_of(VALUE, configs(), st.lists(configs(), max_size=2))),
         "recordings": draw(st.one_of(VALUE, st.lists(rec, max_size=3)))}
    for key in draw(st.lists(st.sampled_from([*STUDY_KEYS, "factor"]), max_size=3)):
        d[key] = draw(VALUE)
    return d


@st.composite
def near_valid_recordings(draw):
    """A still-then-moving 2 s canonical recording at 100 Hz with a few cells damaged."""
    n = 200
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    t = np.arange(n) / 100.0
    acc = np.tile([0.0, 0.0, -9.81], (n, 1)) + rng.normal(0, 0.05, (n, 3))
    gyr = rng.normal(0, 0.01, (n, 3))
    gyr[100:] += np.sin(np.arange(n - 100) / 10.0)[:, None]
    df = pd.DataFrame(np.column_stack([t, acc, gyr]), columns=HEADERS[0].split(",")).astype(object)
    for _ in range(draw(st.integers(0, 4))):
        row, col = draw(st.integers(0, n - 1)), draw(st.integers(0, 6))
        df.iat[row, col] = draw(st.one_of(st.floats(allow_nan=True, allow_infinity=True), CELL))
    return df.to_csv(index=False)


# --------------------------------------------------------------------------- properties
def _load_every_way(path: Path) -> None:
    _only_footzoo_errors(lambda: load(path))
    for fmt in READERS:
        options = {"foot": "left"} if fmt == "gaitmap" else {}
        _only_footzoo_errors(lambda fmt=fmt, options=options: load(path, format=fmt, **options))


def readers_on_random_bytes(data: bytes, suffix: str) -> None:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / f"r{suffix}"
        p.write_bytes(data)
        _load_every_way(p)


def readers_on_csvish_text(header: str, rows: list[str], encoding: str) -> None:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "r.csv"
        p.write_bytes(("\n".join([header, *rows]) + "\n").encode(encoding, errors="replace"))
        _load_every_way(p)


def readers_on_damaged_text(text: str, encoding: str, at: float, nuls: int) -> None:
    """A recording in a foreign encoding, or with a run of NUL bytes (a damaged or padded file): a footzoo error,
    or (a UTF-8 byte-order mark, NUL padding after the last line) the same recording as the clean file."""
    data = text.encode(encoding)
    k = int(at * len(data))
    damaged = data[:k] + b"\0" * nuls + data[k:]
    with tempfile.TemporaryDirectory() as d:
        clean, p = Path(d) / "clean.csv", Path(d) / "r.csv"
        clean.write_text(text)
        p.write_bytes(damaged)
        ref = _only_footzoo_errors(lambda: load(clean))
        rec = _only_footzoo_errors(lambda: load(p))
        _load_every_way(p)
    if rec is not None:  # read: then it is the clean recording, never a shifted or partial one
        assert ref is not None and np.array_equal(rec.t, ref.t) and np.array_equal(rec.acc, ref.acc)


def reader_on_near_valid_recording(text: str) -> None:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "r.csv"
        p.write_text(text)
        rec = _only_footzoo_errors(lambda: load(p))
        if rec is not None:  # accepted: then it is finite and plausible
            assert np.isfinite(rec.t).all() and np.isfinite(rec.acc).all() and np.isfinite(rec.gyr).all()
            assert np.all(np.diff(rec.t) > 0)


def generic_descriptions(description: dict, text: str) -> None:
    """A data file with a random description sidecar: a footzoo error, or a valid recording."""
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "r.csv"
        p.write_text(text)
        p.with_name("r.csv.footzoo.yaml").write_text(yaml.safe_dump(description, allow_unicode=True))
        rec = _only_footzoo_errors(lambda: load(p))
        if rec is not None:
            assert np.isfinite(rec.acc).all() and np.all(np.diff(rec.t) > 0)


_META_WALK: list = []


def _meta_walk():
    if not _META_WALK:
        from footzoo.sim import simulate

        _META_WALK.append(simulate(n_strides=2, rate=50.0))
    return _META_WALK[0]


def metadata_round_trip(meta: dict) -> None:
    """Metadata written with a recording comes back with the same values and types (text stays text)."""
    from footzoo.io.canonical import write

    rec = _meta_walk()
    saved = dict(rec.meta)
    rec.meta.update(meta)
    try:
        with tempfile.TemporaryDirectory() as d:
            back = load(write(rec, Path(d) / "w.csv"))
    finally:
        rec.meta.clear()
        rec.meta.update(saved)
    for key, value in meta.items():
        got = back.meta[key]
        assert type(got) is type(value) and (got == value or (value != value and got != got)), (key, value, got)


def archive_tables(frame: pd.DataFrame) -> None:
    """A table written in a result archive's CSV form reads back equal, dtypes and NaN included."""
    from footzoo.core.archive import _read_table, _write_table
    from footzoo.core.atomic import FileGroup

    with tempfile.TemporaryDirectory() as d:
        with FileGroup(fsync=False) as group:
            name, info = _write_table(frame, group, Path(d), "t", "csv")
        pd.testing.assert_frame_equal(_read_table(Path(d), name, info), frame, check_exact=True)


TEXTS = st.one_of(st.none(), st.text(max_size=12), st.sampled_from(["1e3", "007", "true", "", "nan", ".inf", "0x1F",
                                                                     "1:30", "null", "~", "- a", "a: b", "\n"]))


@st.composite
def tables(draw):
    n = draw(st.integers(0, 6))
    floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
    columns = {
        "f": st.lists(floats, min_size=n, max_size=n).map(lambda v: np.array(v, dtype=float)),
        "i": st.lists(st.integers(-2**62, 2**62), min_size=n, max_size=n).map(lambda v: np.array(v, dtype=np.int64)),
        "b": st.lists(st.booleans(), min_size=n, max_size=n).map(lambda v: np.array(v, dtype=bool)),
        "s": st.lists(TEXTS, min_size=n, max_size=n).map(lambda v: pd.Series(v, dtype=object)),
    }
    chosen = draw(st.lists(st.sampled_from(sorted(columns)), unique=True, min_size=1))
    return pd.DataFrame({c: draw(columns[c]) for c in chosen})


def yaml_text(text: str) -> None:
    _only_footzoo_errors(lambda: load_text(text, "fuzz.yaml"))


def config_files(cfg: dict) -> None:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "c.yaml"
        p.write_text(yaml.safe_dump(cfg, allow_unicode=True))
        pipeline = _only_footzoo_errors(lambda: Pipeline.from_yaml(p))
    if pipeline is not None:  # accepted: every number in the resolved config is finite
        def numbers(x):
            if isinstance(x, dict):
                return [v for y in x.values() for v in numbers(y)]
            if isinstance(x, (list, tuple)):
                return [v for y in x for v in numbers(y)]
            return [x] if isinstance(x, float) else []

        assert all(math.isfinite(v) for v in numbers(pipeline.to_dict()))
        assert 9.7 <= pipeline.gravity <= 9.9


DECLARED = [(kind, name, p, d) for kind in KINDS for name, cls in sorted(available(kind).items())
            if not name.startswith("test_") for p, d in cls.declaration().items()]


@st.composite
def declared_parameter_values(draw):
    kind, name, p, d = draw(st.sampled_from(DECLARED))
    return kind, name, p, d, draw(declared_values(d.param, d.default))


def declared_parameters(case) -> None:
    """A plug-in accepts a value only if its declaration does, and then stores the declaration's conversion of it."""
    kind, name, p, d, value = case
    try:
        expected = d.validate(value)
    except ConfigError:
        expected = REFUSED
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            plugin = build(kind, {"type": name, p: value}, kind)
        except ConfigError:  # refused, by the declaration or a rule between parameters (e.g. a window's order)
            return
    assert expected is not REFUSED, f"{name}.{p} = {value!r} was accepted, but its declaration refuses it"
    assert _same(plugin.get_params()[p], expected), (name, p, value, plugin.get_params()[p], expected)


REFUSED = object()


def _same(a, b) -> bool:
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b and type(a) is type(b)


SETTINGS = list(settings_declarations().items())


@st.composite
def setting_values(draw):
    key, d = draw(st.sampled_from(SETTINGS))
    return key, d, draw(declared_values(d.param, d.default))


def settings_blocks(case) -> None:
    """The settings blocks follow their declarations as plug-ins do: accepted iff declared valid."""
    key, d, value = case
    block, _, field = key.partition(".")
    cfg = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"}, "corrections": [{"type": "zupt"}],
           block: {field: value} if field else value}
    try:
        expected = d.validate(value)
    except ConfigError:
        expected = REFUSED
    try:
        pipeline = Pipeline.from_dict(cfg)
    except ConfigError as err:
        assert expected is REFUSED and key in str(err), (key, value, err)
        return
    assert expected is not REFUSED, f"{key} = {value!r} was accepted, but its declaration refuses it"
    got = pipeline.to_dict()[block][field] if field else pipeline.to_dict()[block]
    assert _same(got, expected), (key, value, got, expected)


def study_mappings(d: dict) -> None:
    with tempfile.TemporaryDirectory() as root:
        _only_footzoo_errors(lambda: Study.from_dict(d, root=root))


def live_samples(t, acc, gyr, previous) -> None:
    _only_footzoo_errors(lambda: validate_sample(t, acc, gyr, None, None, previous, None))


_STREAM_PIPELINE = Path(__file__).resolve().parents[2] / "configs" / "nguyen2016.yaml"
SAMPLE = st.tuples(st.floats(0.002, 0.05), st.lists(st.floats(-60.0, 60.0), min_size=3, max_size=3),
                   st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3))


def stream_pushes(samples: list, use_mag: bool, offset: float) -> None:
    """A live stream fed odd but well-formed samples: only footzoo errors, finite estimates."""
    from footzoo.runtime.stream import Stream

    stream = Stream(Pipeline.from_yaml(_STREAM_PIPELINE))
    t = offset
    for k, (dt, acc, gyr) in enumerate(samples):
        t += dt
        acc = [acc[0] * 0.01, acc[1] * 0.01, -9.81 + acc[2] * 0.01] if k < 60 else acc  # a still start
        gyr = [g * 0.001 for g in gyr] if k < 60 else gyr
        est = _only_footzoo_errors(lambda t=t, acc=acc, gyr=gyr: stream.push(t, acc, gyr, [0.2, 0.0, 0.4] if use_mag
                                                                             else None))
        if est is not None:
            assert np.isfinite(est["pos"]).all() and np.isfinite(est["quat"]).all()


NUM = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(), st.text(max_size=3), st.none())
PROPERTIES = {
    "readers_on_random_bytes": (readers_on_random_bytes, (st.binary(max_size=2048),
                                                          st.sampled_from([".csv", ".txt", ".mat", ".parquet"]))),
    "readers_on_csvish_text": (readers_on_csvish_text, (HEADER, ROWS, st.sampled_from(["utf-8", "latin-1"]))),
    "reader_on_near_valid_recording": (reader_on_near_valid_recording, (near_valid_recordings(),)),
    "readers_on_damaged_text": (readers_on_damaged_text, (
        near_valid_recordings(), st.sampled_from(["utf-8", "utf-8-sig", "utf-16", "utf-16-le", "utf-32"]),
        st.floats(0.0, 1.0), st.sampled_from([0, 1, 7, 300]))),
    "yaml_text": (yaml_text, (st.one_of(YAMLISH, st.text(max_size=200)),)),
    "generic_descriptions": (generic_descriptions, (
        st.fixed_dictionaries({}, optional={k: VALUE for k in ("time", "acc", "gyr", "mag", "axes", "delimiter",
                                                                "decimal", "skip_rows", "header", "meta")}),
        st.one_of(near_valid_recordings(), st.text(max_size=200)))),
    "metadata_round_trip": (metadata_round_trip, (st.dictionaries(
        st.text(alphabet="abcdefgh_", min_size=1, max_size=6).map(lambda k: f"x_{k}"),
        st.one_of(TEXTS.filter(lambda v: v is not None), st.booleans(), st.integers(-10**9, 10**9),
                  st.floats(allow_nan=True, allow_infinity=True)), max_size=5),)),
    "archive_tables": (archive_tables, (tables(),)),
    "config_files": (config_files, (configs(),)),
    "declared_parameters": (declared_parameters, (declared_parameter_values(),)),
    "settings_blocks": (settings_blocks, (setting_values(),)),
    "study_mappings": (study_mappings, (studies(),)),
    "stream_pushes": (stream_pushes, (st.lists(SAMPLE, min_size=0, max_size=120), st.booleans(),
                                      st.sampled_from([0.0, 1.7e9]))),
    "live_samples": (live_samples, (NUM, st.one_of(NUM, st.lists(NUM, max_size=4), st.lists(st.lists(NUM))),
                                    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4),
                                    st.one_of(st.none(), st.floats(allow_nan=False)))),
}


#: Properties whose examples take microseconds: more of them in the CI profile.
CI_MORE = {"declared_parameters": 4 * CI_EXAMPLES, "settings_blocks": 2 * CI_EXAMPLES}


def _make(name: str, examples: int, ci: bool = True):
    body, strategies = PROPERTIES[name]
    test = _settings(examples, ci)(given(*strategies)(body))
    test.__name__ = f"test_{name}"
    return test


for _name in PROPERTIES:
    globals()[f"test_{_name}"] = _make(_name, CI_MORE.get(_name, CI_EXAMPLES))
    globals()[f"test_{_name}_nightly"] = pytest.mark.nightly(_make(_name, NIGHTLY_EXAMPLES, ci=False))
