"""Study files: base configs × factors (dotted-path overrides, grids) × recordings × metrics."""

from __future__ import annotations

import collections
import copy
import functools
import glob
import hashlib
import inspect
import itertools
import json
import math
import os
import stat
import sys
import types
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .. import _version
from ..config.library import BUILTIN, is_name, resolve
from ..config.library import path as library_path
from ..config.schema import load_yaml
from ..core.errors import ConfigError, FootzooError, RecordingError, did_you_mean, prefixed
from ..core.files import why_missing
from ..core.yamlsafe import load_file
from ..evaluation.metrics import FIGURE_METRICS, METRICS
from ..io import _options_for, companion_files, detect_format
from ..io import available as available_readers
from ..io import load as load_recording
from ..plugins.base import Plugin
from ..plugins.extensions import load_plugins, resolve_specs, source_hash
from ..plugins.registry import KINDS, available
from ..runtime.pipeline import Pipeline
from ..runtime.validate import config_errors
from ..sim import NoiseModel, simulate
from ..sim.scenarios import check_spec, seed_matters

#: Largest grid (bases × factor levels × recordings) a study runs unless its ``max_cells`` says more.
MAX_CELLS = 10_000

STUDY_KEYS = {
    "name": "study name",
    "description": "free text",
    "base": "a config path, an inline config, or a list of them",
    "factors": "mapping of dotted paths to lists of values (all combinations are run)",
    "recordings": "list of {path: glob, format: ..., group: ..., label: ...} or {simulate: {...}, seeds: [...], "
                  "group: ..., label: ...}",
    "metrics": "list of metric names to keep (default: all)",
    "figures": "metrics drawn as a box plot per factor: a list of names, all or none (default: those listed under "
               "metrics, else the headline errors of footzoo.evaluation.metrics.FIGURE_METRICS)",
    "sweep": "threshold sweep of the detectors: {points: 25}",
    "plugins": "external plug-ins to load in every worker: module names or .py paths (relative to the study file)",
    "jobs": "local worker processes (1 = serial, -1 = every core); the command line's --jobs overrides it",
    "max_cells": f"largest number of runs (bases x factor levels x recordings) allowed, default {MAX_CELLS}",
}

_FILE_DIGESTS: dict[tuple[str, int, int], str] = {}  # (path, size, mtime_ns) -> sha256 of the content



@functools.lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """SHA-256 over footzoo's own source files (part of every cache key)."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()

def _builtin_plugin_files() -> set[Path]:
    """The files of footzoo that define a registered plug-in (each has its own cache identity)."""

    root = Path(__file__).resolve().parents[1]
    out = set()
    for kind in KINDS:
        for cls in available(kind).values():
            f = _source_file(cls)
            if f is not None and root in f.parents:
                out.add(f)
    return out


@functools.lru_cache(maxsize=1)
def engine_fingerprint() -> str:
    """SHA-256 over footzoo's source files but those that define plug-ins: the engine every cell uses."""
    root = Path(__file__).resolve().parents[1]
    plugin_files = _builtin_plugin_files()
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        if f.resolve() not in plugin_files:
            h.update(str(f.relative_to(root)).encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def _source_file(obj: Any) -> Path | None:
    try:
        f = inspect.getsourcefile(obj)
    except (TypeError, OSError):
        return None
    return Path(f).resolve() if f else None


def plugin_sources(config: dict[str, Any]) -> list[Path]:
    """The plug-in source files a config actually uses: the modules of each plug-in's class and base
    classes (and of the plug-ins inside it), and the plug-in modules those import from, transitively.
    footzoo's engine (:func:`engine_fingerprint`), installed libraries and the plug-ins the config does
    not name are not among them."""


    pipeline = Pipeline.from_dict(copy.deepcopy(config))
    instances = [*pipeline.calibration, pipeline.orientation, pipeline.detector, *pipeline.corrections,
                 *pipeline.analysis]
    modules: list[str] = []
    seen: set[int] = set()
    while instances:
        obj = instances.pop()
        if obj is None or id(obj) in seen:
            continue
        seen.add(id(obj))
        modules += [c.__module__ for c in type(obj).__mro__]
        instances += [v for v in vars(obj).values() if isinstance(v, Plugin)]
    root = Path(__file__).resolve().parents[1]
    plugin_files = _builtin_plugin_files()
    libraries = {Path(sys.prefix).resolve(), Path(sys.base_prefix).resolve()}
    files: set[Path] = set()
    done: set[str] = set()
    while modules:
        name = modules.pop()
        module = sys.modules.get(name)
        if name in done or module is None:
            continue
        done.add(name)
        f = _source_file(module)
        if f is None or (root in f.parents and f not in plugin_files) or any(p in f.parents for p in libraries):
            continue  # the engine (in engine_fingerprint), the standard library, installed packages
        files.add(f)
        for v in vars(module).values():
            modules.append(v.__name__ if isinstance(v, types.ModuleType) else str(getattr(v, "__module__", "")))
    return sorted(files)


def config_code(config: dict[str, Any]) -> str:
    """A cell's code identity: footzoo's version, its engine and the source of the plug-ins the config uses.

    Editing a plug-in's file changes the identity of the cells whose config uses it, and only theirs.
    """

    h = hashlib.sha256()
    for f in plugin_sources(config):
        h.update(str(f).encode())
        h.update(hashlib.sha256(f.read_bytes()).digest())
    return json.dumps({"footzoo": _version.__version__, "engine": engine_fingerprint(), "plugins": h.hexdigest()},
                      sort_keys=True)


@dataclass
class RecordingSpec:
    """One recording of a study: a file or a simulator scenario with a seed."""

    label: str
    path: str | None = None
    format: str | None = None
    options: dict[str, Any] = field(default_factory=dict)
    simulate: dict[str, Any] | None = None
    seed: int | None = None
    group: str | None = None  # cross-validation group (subject, day, motion class): footzoo.studies.tune

    def identity(self) -> str:
        """What the cache key depends on: the file's content hash and its companions' (a reference, a description,
        a metadata sidecar: :func:`footzoo.io.companion_files`, absent ones as absent), or the simulator spec and seed.

        A path that is not a readable file (a dangling link, a directory, a vanished or unreadable
        file) gets an identity describing the problem, so its cells fail on their own and are run
        again once the file changes.
        """
        if self.path is not None:
            problem = self.problem()
            data = ({"problem": problem, "path": self.path} if problem else
                    {"file": _file_digest(self.path), "companions": _companion_digests(self.path, self.format,
                                                                                        self.options)})
            return json.dumps({**data, "format": self.format, "options": self.options}, sort_keys=True, default=str)

        return json.dumps({"simulate": self.simulate, "seed": self.seed, "footzoo": _version.__version__},
                          sort_keys=True, default=str)

    def problem(self) -> str | None:
        """Why the recording's file cannot be read (None for a simulated recording or a readable file)."""
        if self.path is None:
            return None
        p = Path(self.path)
        try:
            st = p.stat()
        except FileNotFoundError:
            if p.is_symlink():
                return f"{self.path!r} is a dangling link (its target {os.readlink(p)!r} does not exist)"
            return f"{self.path!r} does not exist (any more)"
        except OSError as err:
            if p.is_symlink():  # a loop of links (ELOOP): named as footzoo run names it, with the fix
                return f"{self.path!r} {why_missing(p)}"
            return f"{self.path!r} cannot be accessed: {err.strerror or err}"
        if stat.S_ISDIR(st.st_mode):
            return (f"{self.path!r} is a directory, not a recording file; give its recordings with a glob such as "
                    f"{str(Path(self.path) / '*.csv')!r}, or narrow the study's glob")
        if not stat.S_ISREG(st.st_mode):
            return f"{self.path!r} is not a regular file"
        if not os.access(p, os.R_OK):
            return f"{self.path!r} is not readable (permission denied)"
        return None

    def load(self):
        """The recording."""
        if self.path is not None:
            problem = self.problem()
            if problem:
                raise RecordingError(f"recording {problem}")

            return load_recording(self.path, format=self.format, **self.options)

        spec = copy.deepcopy(self.simulate)
        noise = spec.pop("noise", None)
        if isinstance(noise, dict):
            noise = NoiseModel(**{**noise, "seed": self.seed or 0})
        return simulate(**spec, noise=noise, seed=self.seed or 0)


@dataclass
class Cell:
    """One run: a resolved config on one recording."""

    config: dict[str, Any]
    recording: RecordingSpec
    levels: dict[str, Any]
    base: str
    code: str = ""  # footzoo's version, engine and the used plug-ins' source (config_code)

    def key(self, data: str | None = None) -> str:
        """Cache key: hash of the resolved config, the code identity and the data's identity."""
        data = self.recording.identity() if data is None else data
        payload = json.dumps({"config": self.config, "data": data, "code": self.code}, sort_keys=True, default=str)
        return hashlib.sha256(payload.encode()).hexdigest()[:24]


def _metric_names(value: Any, key: str, also: str = "") -> list[str] | None:
    """The metric names a study lists under ``key`` (a name or a list), or None if absent."""
    if value is None:
        return None
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(m, str) for m in value):
        raise ConfigError(f"{key} must be a list of metric names{', ' + also if also else ''}, got {value!r}; "
                          f"valid: {list(METRICS)}")
    for m in value:
        if m not in METRICS:
            where = "" if key == "metrics" else f" in {key}"
            raise ConfigError(f"unknown metric {m!r}{did_you_mean(str(m), list(METRICS))}{where}; "
                              f"valid metrics: {list(METRICS)}")
    return list(dict.fromkeys(value))


@dataclass
class Study:
    """A parsed study file."""

    name: str
    bases: list[tuple[str, dict[str, Any]]]
    factors: dict[str, list[Any]]
    recordings: list[RecordingSpec]
    metrics: list[str] | None = None
    sweep_points: int = 0
    plugins: list[str] = field(default_factory=list)
    jobs: int | None = None
    max_cells: int = MAX_CELLS
    figures: list[str] | str | None = None

    def figure_metrics(self) -> list[str] | None:
        """The metrics to draw a box plot per factor of (those the table holds), None for every one.

        ``figures:`` when the study names them (``all``: every one, ``none``: none), else every metric
        the study keeps under ``metrics:``, else those of :data:`~footzoo.evaluation.metrics.FIGURE_METRICS`.
        """
        if self.figures == "all" or (self.figures is None and self.metrics is not None):
            return None
        return [] if self.figures == "none" else list(FIGURE_METRICS if self.figures is None else self.figures)

    @classmethod
    def from_yaml(cls, path: str | Path, max_cells: int | None = None) -> Study:
        """Read and check a study file; paths in it are relative to the file."""
        p = resolve(path)
        data = load_file(p, ConfigError, "study file")
        if not isinstance(data, dict):
            raise ConfigError(f"{p}: a study must be a mapping with base, factors, recordings")
        try:
            return cls.from_dict(data, root=p.parent, max_cells=max_cells)
        except ConfigError as err:
            raise prefixed(err, p) from err.__cause__

    def code_identity(self) -> str:
        """footzoo's version and source, and every plug-in's source (SHA-256): part of every cache key.

        With footzoo's own source in the key, a result computed before an edit of a built-in
        plug-in (an editable install, a benchmark) is never read back as if it were current.
        """

        return json.dumps({"footzoo": _version.__version__, "source": code_fingerprint(),
                           "plugins": source_hash(self.plugins)}, sort_keys=True)

    @classmethod
    def from_dict(cls, d: dict[str, Any], root: str | Path = ".", max_cells: int | None = None) -> Study:
        """Build from a mapping (see :data:`STUDY_KEYS`); ``max_cells`` overrides the study's grid limit."""
        root = Path(root)
        if "base" not in d and {"orientation", "detector"} & set(d):
            raise ConfigError("this is a pipeline config (orientation, detector, ...), not a study: run it with "
                              "footzoo run FILE, or write a study whose base: names it (see footzoo configs: "
                              "study_quick)")
        if "tune" in d:
            raise ConfigError("this is a tune file (a study with a tune: block): run it with footzoo tune FILE")
        for key in d:
            if key not in STUDY_KEYS:
                raise ConfigError(f"unknown study key {key!r}{did_you_mean(key, list(STUDY_KEYS))}; "
                                  f"valid keys: {list(STUDY_KEYS)}")
        if "base" not in d or "recordings" not in d:
            raise ConfigError("a study needs 'base' (config path(s)) and 'recordings'")
        plugins = resolve_specs(d.get("plugins"), root, "plugins")
        bases, unnamed = [], []
        for b in d["base"] if isinstance(d["base"], list) else [d["base"]]:
            if isinstance(b, str):
                path = _resolve(root, b)
                cfg, folder = load_yaml(path), Path(path).parent
                name = Path(path).stem
            elif isinstance(b, dict):
                cfg, folder = copy.deepcopy(b), root
                name = str(b.get("name", f"base{len(bases)}"))
                if "name" not in b:
                    unnamed.append(len(bases))
            else:
                raise ConfigError(f"base entries must be config paths or mappings, got {b!r}")
            if cfg.get("plugins"):  # the base's own plug-ins, made absolute so any worker finds them
                cfg["plugins"] = resolve_specs(cfg["plugins"], folder, f"base {name}: plugins")
                plugins += [p for p in cfg["plugins"] if p not in plugins]
            bases.append((name, cfg))
        bases = _named_by_difference(bases, unnamed)
        _refuse_duplicate_bases(bases)
        load_plugins(plugins)  # here too: errors surface before any run, and factors may name the plug-ins
        factors = d.get("factors") or {}
        if not isinstance(factors, dict):
            raise ConfigError("factors must map dotted paths to lists of values, e.g. {detector.type: [dgp, shoe]}")
        for k in factors:
            if not isinstance(k, str) or not k:
                raise ConfigError(f"factor names must be dotted paths like detector.threshold, got {k!r}")
        factors = {k: (v if isinstance(v, list) else [v]) for k, v in factors.items()}
        for k, v in factors.items():
            if not v:
                raise ConfigError(f"factor {k!r} has no levels: give it a list of values, e.g. {k}: [a, b], "
                                  "or remove it")
            keys = [json.dumps(_numbers_as_float(level), sort_keys=True, default=str) for level in v]  # 1 == 1.0
            counts = collections.Counter(keys)
            twice = next((level for level, key in zip(v, keys, strict=True) if counts[key] > 1), None)
            if twice is not None:  # it would run every cell of that level twice under one name
                raise ConfigError(f"factor {k!r} lists the level {twice!r} more than once; list each level once")
        recordings = []
        if not isinstance(d["recordings"] or [], list):
            raise ConfigError("recordings must be a list, e.g. [{path: data/*.csv}, {simulate: {path: straight}}]")
        max_cells = d.get("max_cells", MAX_CELLS) if max_cells is None else max_cells
        if isinstance(max_cells, bool) or not isinstance(max_cells, int) or max_cells < 1:
            raise ConfigError(f"max_cells must be a whole number >= 1, got {max_cells!r}")
        _refuse_large(len(bases), factors, [_count_recording(r, i) for i, r in enumerate(d["recordings"] or [])],
                      max_cells)  # before any list is expanded: a pasted repeats: 10000000 must not fill the memory
        for i, r in enumerate(d["recordings"] or []):
            recordings += _expand_recording(r, root, i)
        if not recordings:
            raise ConfigError("the study has no recordings (check the globs)")
        _name_feet(recordings)
        _refuse_identical_simulations(recordings)
        seen: dict[str, RecordingSpec] = {}
        for rec in recordings:
            other = seen.setdefault(rec.label, rec)
            if other is not rec:  # two recordings under one name would share their rows and cache entries
                where = " and ".join(str(x.path) if x.path else f"simulate seed {x.seed}" for x in (other, rec))
                raise ConfigError(f"two recordings of the study are both called {rec.label!r} ({where}); give each "
                                  "entry its own label: (e.g. {path: subject2/walk.csv, label: subject2_walk})")
        metrics = _metric_names(d.get("metrics"), "metrics")
        figures = d.get("figures")
        if figures not in ("all", "none"):
            figures = _metric_names(figures, "figures", also="or the word all or none")
        if isinstance(figures, list) and metrics is not None and set(figures) - set(metrics):
            missing = [m for m in figures if m not in metrics]
            raise ConfigError(f"figures names {missing} but metrics does not keep them: add them to metrics, "
                              "or leave them out of figures")
        sweep = d.get("sweep") or {}
        if not isinstance(sweep, dict) or set(sweep) - {"points"}:
            raise ConfigError(f"sweep must be a mapping like {{points: 25}}, got {sweep!r}")
        points = sweep.get("points", 0)
        if isinstance(points, bool) or not isinstance(points, int) or points < 0:
            raise ConfigError(f"sweep.points must be a whole number >= 0, got {points!r}")
        jobs = d.get("jobs")
        if jobs is not None:
            check_jobs(jobs)
        study = cls(str(d.get("name", "study")), bases, factors, recordings, metrics, points, plugins, jobs,
                    max_cells, figures)
        study.check_size()
        return study

    @property
    def size(self) -> int:
        """Number of runs: bases × the product of the factors' level counts × recordings (no cell is built)."""
        n = len(self.bases) * len(self.recordings)
        for levels in self.factors.values():
            n *= len(levels)
        return n

    def check_size(self, max_cells: int | None = None) -> None:
        """A ConfigError when the grid has more runs than ``max_cells`` (default: the study's own limit)."""
        _refuse_large(len(self.bases), self.factors, [len(self.recordings)],
                      self.max_cells if max_cells is None else max_cells)

    def configs(self) -> list[tuple[dict[str, Any], dict[str, Any]]]:
        """Every distinct ``(config, levels)`` of the grid, without the recordings.

        Type changes are set first: they reset the plug-in's parameters, which other factors may then set.
        A level that cannot be set gives ``{"__invalid__": reason}`` as its config.
        """
        names = sorted(self.factors, key=lambda n: not n.endswith(".type"))
        out = []
        for base_name, base in self.bases:
            for values in itertools.product(*(self.factors[n] for n in names)):
                cfg = copy.deepcopy(base)
                levels = {"base": base_name, **dict(zip(names, values, strict=True))}
                try:
                    for n, v in zip(names, values, strict=True):
                        set_dotted(cfg, n, v)
                except (ConfigError, TypeError, ValueError, IndexError) as err:
                    cfg = {"__invalid__": str(err)}
                out.append((cfg, levels))
        return out

    def check(self, max_cells: int | None = None) -> None:
        """Validate everything before a run: the grid's size, every config of the grid, the reader options.

        Raises
        ------
        ConfigError
            Listing the first distinct problems, each with the factor levels that lead to it.
        """

        self.check_size(max_cells)
        problems: dict[str, list[dict[str, Any]]] = {}
        configs = self.configs()
        bad = 0
        for cfg, levels in configs:
            errors = [cfg["__invalid__"]] if "__invalid__" in cfg else config_errors(cfg)
            bad += bool(errors)
            for e in errors:
                problems.setdefault(e, []).append(levels)
        for rec in self.recordings:
            problem = _reader_problem(rec)
            if problem:
                problems.setdefault(problem, []).append({"recording": rec.label})
        if problems:
            lines = [f"- {e} ({len(where)} case(s), the first: {_levels_text(where[0])})"
                     for e, where in list(problems.items())[:5]]
            more = f"\n... and {len(problems) - 5} more distinct problem(s)" if len(problems) > 5 else ""
            raise ConfigError(f"study {self.name!r}: {bad} of {len(configs)} config(s) invalid or recordings "
                              f"unreadable, nothing was run; the first distinct causes:\n" + "\n".join(lines) + more)

    def cells(self) -> list[Cell]:
        """Every base × factor combination × recording."""
        # type changes first: they reset the plug-in's parameters, which other factors may then set
        self.check_size()
        out = []
        for cfg, levels in self.configs():
            if "__invalid__" in cfg:
                raise ConfigError(f"factor levels {_levels_text(levels)}: {cfg['__invalid__']}")
            try:
                code = config_code(cfg)
            except (ConfigError, ValueError, TypeError):  # an invalid config's cells fail on their own
                code = self.code_identity()
            for rec in self.recordings:
                out.append(Cell(cfg, rec, levels, levels["base"], code))
        return out


def _levels_text(levels: dict[str, Any]) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in levels.items())


def _reader_problem(rec: RecordingSpec) -> str | None:
    """Why a recording's reader cannot take its options (an unknown format or option), or None.

    A file that cannot be read (vanished, a directory, not recognised) is not a problem of the
    study: its cells fail on their own, the other recordings run.
    """
    if rec.path is None or rec.problem():
        return None

    readers = available_readers()
    try:
        fmt = rec.format or detect_format(Path(rec.path), rec.options)
    except FootzooError:
        return None
    try:
        _options_for(readers.get_reader(fmt), fmt, Path(rec.path), dict(rec.options))
    except FootzooError as err:
        return str(err)
    return None


def _named_by_difference(bases: list[tuple[str, dict[str, Any]]], unnamed: list[int]) -> list[tuple[str, dict]]:
    """Inline base configs without a ``name`` named by what differs between the bases (``detector: shoe``), as the
    summaries label a factor's levels; ``base<i>`` stays where that gives no name or two bases the same one."""
    if len(bases) < 2 or not unnamed:
        return bases
    from .report import level_labels

    texts = [json.dumps({k: v for k, v in cfg.items() if k != "name"}, sort_keys=True, default=str) for _, cfg in bases]
    labels = level_labels("base", texts)
    out = list(bases)
    for i in unnamed:
        label = labels[texts[i]]
        taken = [n for j, (n, _) in enumerate(out) if j != i]
        if label and label not in taken and texts.count(texts[i]) == 1:
            out[i] = (label, bases[i][1])
    return out


def _refuse_duplicate_bases(bases: list[tuple[str, dict[str, Any]]]) -> None:
    """Two bases of one name, or of one config, would be counted twice in every summary (as a duplicate factor level
    or seed would): refused, naming them."""
    seen: dict[str, str] = {}
    for name, cfg in bases:
        text = json.dumps({k: v for k, v in cfg.items() if k != "name"}, sort_keys=True, default=str)
        if name in seen.values():
            raise ConfigError(f"base: {name!r} is given twice; its runs would be counted twice in every summary: give "
                              "each base once (or name two variants apart: name: in an inline config)")
        if text in seen:
            raise ConfigError(f"base: {seen[text]!r} and {name!r} are the same config; their runs would be counted "
                              "as two settings: keep one")
        seen[text] = name


def _resolve(root: Path, path: str) -> str:
    """A path of the study file: as written, relative to the study's folder, or a shipped config's name."""
    p = Path(path)
    if p.is_absolute() or p.exists():
        return str(p)
    if not (root / p).exists() and is_name(path):
        return str(library_path(path))
    return str(root / p)


#: Most local worker processes per core a study starts (more only share the cores and multiply the memory).
JOBS_PER_CORE = 4


def max_jobs() -> int:
    """The most local worker processes a study may start on this machine: :data:`JOBS_PER_CORE` per core."""
    return JOBS_PER_CORE * (os.cpu_count() or 1)


def check_jobs(jobs: Any, what: str = "jobs") -> int:
    """``jobs`` when it is -1 (every core) or 1 to :func:`max_jobs`; a ConfigError naming the range otherwise."""
    if isinstance(jobs, bool) or not isinstance(jobs, int) or not (jobs == -1 or 1 <= jobs <= max_jobs()):
        raise ConfigError(f"{what} must be a number of worker processes on this machine: 1 (serial) to {max_jobs()} "
                          f"({JOBS_PER_CORE} per core of this machine's {os.cpu_count() or 1}; more only share the "
                          f"cores), or -1 for one per core; got {jobs!r}")
    return jobs


def _refuse_large(bases: int, factors: dict[str, list[Any]], recordings: list[int], limit: int) -> None:
    """A ConfigError naming the count when bases x factor levels x recordings exceeds ``limit`` (nothing expanded)."""
    size = bases * math.prod(len(v) for v in factors.values()) * sum(recordings)
    if size > limit:
        levels = " x ".join(f"{len(v)} {k}" for k, v in factors.items()) or "no factors"
        raise ConfigError(
            f"the study has {size:,} runs ({bases} base(s) x {levels} x {sum(recordings):,} recording(s)), more "
            f"than the limit of {limit:,}: shorten the factors' level lists or the recordings' seeds and repeats, or "
            "raise the limit (max_cells: N in the study file, --max-cells N on the command line) if you mean it")


#: The keys of a ``{simulate: {...}}`` entry of ``recordings:``.
SIMULATE_ENTRY_KEYS = ["simulate", "seeds", "repeats", "label", "group"]


def _seeds(r: dict[str, Any], i: int) -> list[int]:
    """The seeds of a ``simulate:`` entry, repeats included (``seeds`` and ``repeats`` checked)."""
    seeds = r.get("seeds", [0])
    if not isinstance(seeds, list) or not all(isinstance(s, int) and not isinstance(s, bool) and s >= 0
                                              for s in seeds):
        raise ConfigError(f"recordings[{i}].seeds must be a list of whole numbers >= 0, got {seeds!r:.120}")
    if not seeds:
        raise ConfigError(f"recordings[{i}].seeds is empty, so the entry gives no recording: list at least one seed "
                          "(seeds: [0]), or remove the entry")
    repeats = r.get("repeats", 1)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise ConfigError(f"recordings[{i}].repeats must be a whole number >= 1, got {repeats!r}")
    out = [s + 1000 * k for k in range(repeats if seeds else 0) for s in seeds]
    seen: set[int] = set()
    twice = sorted({s for s in out if s in seen or seen.add(s)})
    if twice:
        raise ConfigError(f"recordings[{i}].seeds gives seed(s) {twice} more than once (seeds {seeds!r:.80}, repeats "
                          f"{repeats}: seed s, then s + 1000, s + 2000, ...); one seed is one simulated recording, the "
                          "same twice would be averaged as two: list each seed once")
    return out


def _count_recording(r: Any, i: int) -> int:
    """How many recordings an entry of ``recordings:`` gives, without expanding it (a glob counts as 1 here)."""
    if isinstance(r, dict) and "simulate" in r and "path" not in r:
        seeds, repeats = r.get("seeds", [0]), r.get("repeats", 1)
        if isinstance(seeds, list) and isinstance(repeats, int) and not isinstance(repeats, bool) and repeats >= 1:
            return len(seeds) * repeats
    return 1


def _expand_recording(r: Any, root: Path, i: int) -> list[RecordingSpec]:
    if isinstance(r, str):  # a file path or glob alone: {path: GLOB}, its format found as footzoo.load finds it
        r = {"path": r}
    if not isinstance(r, dict) or not ({"path", "simulate"} & set(r)):
        raise ConfigError(f"recordings[{i}] must be a file path or glob, {{path: GLOB}} with optional format:, label:, "
                          f"group: and reader options (foot:, axes:, sidecar: ...), or {{simulate: {{...}}, seeds: "
                          f"[...]}}; got {r!r:.80}")
    group = r.get("group")
    if group is not None and not isinstance(group, (str, int)):
        raise ConfigError(f"recordings[{i}].group must be a group name (text), got {group!r}")
    group = None if group is None else str(group)
    if "path" in r:
        pattern = r["path"]
        if not isinstance(pattern, str) or not pattern:
            raise ConfigError(f"recordings[{i}].path must be a file path or glob (text), got {pattern!r}")
        if r.get("format") is not None and not isinstance(r["format"], str):
            raise ConfigError(f"recordings[{i}].format must be a format name, got {r['format']!r}")
        matches = sorted(glob.glob(pattern)) or sorted(glob.glob(str(root / pattern)))
        if not matches:
            where = ("" if Path(pattern).is_absolute() else
                     f", neither from the working folder ({Path.cwd()}) nor from the study file's ({root})")
            fix = "fix the path or the working folder"
            if Path(root).resolve() == BUILTIN.resolve():  # a shipped study: its data paths are the repository's
                fix = ("a shipped study finds its data from the repository's root; copy it next to your data "
                       "(footzoo configs --copy <its name> --to my_study.yaml) and edit the path")
            raise ConfigError(f"recordings[{i}]: no file matches {pattern!r}{where}: {fix}")
        matches = _without_sidecars(matches)
        label = r.get("label")
        if label is not None and not isinstance(label, (str, int)):
            raise ConfigError(f"recordings[{i}].label must be a name (text), got {label!r}")
        opts = {k: v for k, v in r.items() if k not in ("path", "format", "group", "label")}

        def name(m: str) -> str:  # one file: the label itself; a glob: the label as a prefix of each stem
            return Path(m).stem if label is None else str(label) if len(matches) == 1 else f"{label}_{Path(m).stem}"

        return [RecordingSpec(name(m), path=m, format=r.get("format"), options=opts, group=group) for m in matches]
    if not isinstance(r["simulate"], dict):
        raise ConfigError(f"recordings[{i}].simulate must be a mapping of simulator options, got {r['simulate']!r}")
    unknown = [k for k in r if k not in SIMULATE_ENTRY_KEYS]
    if unknown:
        near = did_you_mean(str(unknown[0]), SIMULATE_ENTRY_KEYS)
        raise ConfigError(f"recordings[{i}]: unknown key {unknown[0]!r}{near} in a simulate: entry; its keys are "
                          f"{SIMULATE_ENTRY_KEYS} (the simulator's own options go inside simulate: {{...}})")
    sim = dict(r["simulate"])
    try:
        check_spec(sim)
    except ConfigError as err:
        raise ConfigError(f"recordings[{i}].{err}") from None
    seeds = _seeds(r, i)
    if len(set(seeds)) > 1 and not seed_matters(sim):
        raise ConfigError(
            f"recordings[{i}]: its {len(set(seeds))} seeds give {len(set(seeds))} identical recordings: the simulation "
            "has no random part (no noise, or noise: {scale: 0}), so the study would average identical runs as if "
            "they were independent; add the sensor noise (noise: {scale: 1}, Yun et al. 2012 Table II) or keep one "
            "seed (seeds: [0])")
    label = str(r.get("label", f"sim_{sim.get('path', 'straight')}"))
    return [RecordingSpec(f"{label}_s{s}", simulate=sim, seed=int(s), group=group) for s in seeds]


def _refuse_identical_simulations(recordings: list[RecordingSpec]) -> None:
    """Two simulated recordings of one scenario without a random part (no noise) are one recording whatever their
    seeds: across entries too, a study would average identical runs as if they were independent."""
    first: dict[str, RecordingSpec] = {}
    for rec in recordings:
        if rec.simulate is None or seed_matters(rec.simulate):
            continue
        other = first.setdefault(json.dumps(rec.simulate, sort_keys=True, default=str), rec)
        if other is not rec:
            raise ConfigError(
                f"recordings {other.label!r} and {rec.label!r} are identical: the same simulation (seeds {other.seed} "
                f"and {rec.seed}) without a random part (no noise, or noise: {{scale: 0}}), so the study would "
                "average identical runs as if they were independent; add the sensor noise (noise: {scale: 1}) or "
                "keep one of them")


def _name_feet(recordings: list[RecordingSpec]) -> None:
    """One file read once per foot (gaitmap's two sensors: ``{path: f.csv, foot: left}`` and ``foot: right``) under
    one default name: each entry is named after its foot (``f_left``, ``f_right``); a given label is kept."""
    counts = collections.Counter(rec.label for rec in recordings)
    for rec in recordings:
        foot = rec.options.get("foot")
        if (counts[rec.label] > 1 and foot in ("left", "right") and rec.path is not None
                and rec.label == Path(rec.path).stem):
            rec.label = f"{rec.label}_{foot}"


def _without_sidecars(paths: list[str]) -> list[str]:
    """The matches that are not another match's sidecar (``walk.csv.steps.csv`` next to ``walk.csv``)."""
    names = {Path(p).name for p in paths}
    return [p for p in paths if not any(Path(p).name.startswith(n + ".") for n in names if n != Path(p).name)]


def set_dotted(d: dict[str, Any], path: str, value: Any) -> None:
    """Set ``a.b.0.c`` in nested dicts/lists; setting ``X.type`` drops X's other parameters.

    Changing a plug-in's type keeps only the new type (its parameters take their
    defaults) unless other factors set them.
    """
    parts = path.split(".")
    node: Any = d
    for depth, part in enumerate(parts[:-1]):
        if not isinstance(node, (dict, list)):
            where = ".".join(parts[:depth])
            raise ConfigError(f"factor {path!r}: {where!r} is a value ({type(node).__name__} {node!r:.40}), not a "
                              f"section with parameters; the factor goes one level too deep (did you mean {where!r}?)")
        if isinstance(node, list) and not part.lstrip("-").isdigit():
            raise ConfigError(f"factor {path!r}: {'.'.join(parts[:depth])!r} is a list; index it by number "
                              f"(e.g. {'.'.join([*parts[:depth], '0'])})")
        key: Any = int(part) if isinstance(node, list) else part
        if isinstance(node, list):
            if key >= len(node):
                raise ConfigError(f"factor {path!r}: index {key} is out of range ({len(node)} entries)")
        elif key not in node or node[key] is None:
            node[key] = {}
        node = node[key]
    last = parts[-1]
    if not isinstance(node, (dict, list)):
        where = ".".join(parts[:-1])
        raise ConfigError(f"factor {path!r}: {where!r} is a value ({type(node).__name__} {node!r:.40}), not a "
                          f"section with parameters; the factor goes one level too deep (did you mean {where!r}?)")
    if isinstance(node, list):
        node[int(last)] = value
    elif last == "type" and isinstance(node, dict) and node.get("type") != value:
        node.clear()
        node["type"] = value
    else:
        node[last] = value


def _companion_digests(path: str, format: str | None, options: dict[str, Any]) -> list[str | None]:
    """The content hash of each file that reading ``path`` may use besides it, in the reader's order (None: absent)."""
    out: list[str | None] = []
    for f in companion_files(path, format, **options):
        try:
            out.append(_file_digest(str(f)) if f.is_file() else None)
        except OSError as err:  # unreadable: its runs fail when they read it, and run again once it changes
            out.append(f"unreadable: {err.strerror or err}")
    return out


def _file_digest(path: str) -> str:
    """SHA-256 of a file's content, remembered per (path, size, modification time) within the process."""
    st = os.stat(path)
    memo = (os.path.realpath(path), st.st_size, st.st_mtime_ns)
    if memo not in _FILE_DIGESTS:
        h = hashlib.sha256()
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        _FILE_DIGESTS[memo] = h.hexdigest()
    return _FILE_DIGESTS[memo]


def _numbers_as_float(value: Any) -> Any:
    """``value`` with every number (not a bool) as a float, in lists and mappings too: the levels 1 and 1.0 are one."""
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, list):
        return [_numbers_as_float(v) for v in value]
    if isinstance(value, dict):
        return {k: _numbers_as_float(v) for k, v in value.items()}
    return value
