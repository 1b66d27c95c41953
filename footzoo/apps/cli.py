"""Command line: ``footzoo run | simulate | calibrate | ablate (study) | tune | list | validate | formats``.

Every command takes ``--quiet``: no warnings (and no progress bar) on the terminal. The warnings
are kept all the same: in the result (``Result.diagnostics["warnings"]`` of ``footzoo run``, the
study table's ``attrs["warnings"]``) and, for a command that writes a folder (``run --out``,
``ablate``, ``tune``), in its ``footzoo.log``, which lists every warning of the command (or says
there was none); a command with no such place says how many it did not show.

Bad input never prints a Python traceback: the message names the input, the
problem and the fix, and the exit code says which kind of problem it was
(``--debug`` adds the traceback):

====  ==============================================================================
code  meaning
====  ==============================================================================
0     success
1     internal error: a bug in footzoo (rerun with ``--debug`` and report it)
2     usage or configuration error: bad arguments, config, study or calibration file
3     data error: unreadable, malformed or implausible recording; unwritable output
4     plug-in error: a plug-in (built-in or yours) raised, exited or broke its contract
      (a wrong shape, NaN, a non-unit quaternion, a forgotten ``return self``); the
      message names the plug-in, the method and the cause
130   interrupted (Ctrl-C)
====  ==============================================================================
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import sys
import textwrap
import traceback
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ..core.atomic import atomic_path, check_target, folder_lock, refuse_inputs
from ..core.context import RunContext
from ..core.conventions import ACC_UNITS, GYR_UNITS
from ..core.errors import (
    ConfigError,
    FootzooError,
    FootzooWarning,
    FormatError,
    OutputError,
    PluginError,
    ReaderOptionError,
    RecordingError,
    did_you_mean,
    user_stacklevel,
)
from ..core.files import nul_in_path, why_missing
from ..core.params import describe as describe_parameters
from ..core.usage import used_from
from ..core.warninglog import LOG, log_text, warning_texts
from ..io.registry import BUILTIN
from ..plugins.base import BASES
from ..plugins.registry import describe, registered_by


def _reader_options(args: argparse.Namespace) -> dict[str, Any]:
    """The reader's options of the command line; one given twice (two values, or --acc-unit and --option acc_unit=)
    is a ConfigError: the last one would silently win."""
    options: dict[str, Any] = {}
    given = [(name, value, f"--option {name}=") for name, value in getattr(args, "option", None) or []]
    if getattr(args, "foot", None) and args.foot != "both":
        given.append(("foot", args.foot, "--foot "))
    given += [(key, getattr(args, key), f"--{key.replace('_', '-')} ") for key in ("acc_unit", "gyr_unit")
              if getattr(args, key, None)]
    first: dict[str, str] = {}
    for name, value, how in given:
        if name in options and options[name] != value:
            raise ConfigError(f"the reader's option {name!r} is given twice ({first[name]}{options[name]} and "
                              f"{how}{value}); give it once")
        options[name], first[name] = value, first.get(name, how)
    return options


def _reader_option(text: str) -> tuple[str, Any]:
    """An argparse ``type``: ``NAME=VALUE`` (the value read as a YAML scalar: 820 is a number, true a boolean)."""
    # deferred: yaml, read only for an option given
    from ..core.yamlsafe import load_text

    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise argparse.ArgumentTypeError(f"{text!r} is not NAME=VALUE (e.g. --option rate=820)")
    try:
        parsed = load_text(value, "--option", ConfigError) if value.strip() else ""
    except ConfigError:
        parsed = value
    return name.strip(), parsed


def _named(text: str, empty: str, what: str = "path") -> str:
    """``text`` if it names something: not empty or blank (``empty`` says what to give instead) and without a NUL
    (``what`` it is, for the message); the checks every path or name argument shares."""
    if not text.strip():
        raise argparse.ArgumentTypeError(empty)
    if nul_in_path(text):
        raise argparse.ArgumentTypeError(f"the {what} {nul_in_path(text)}")
    return text


def _output(text: str) -> str:
    """An argparse ``type`` for ``--out``: a non-empty path (an empty one would write nothing, silently), not ``-``."""
    _named(text, "an empty path; give the output's name (or leave --out out)")
    if text.strip() == "-":
        raise argparse.ArgumentTypeError("'-' (standard output): footzoo writes its outputs to files, not to a "
                                         "stream; give a name")
    return text


def _recording_path(text: str) -> str:
    """An argparse ``type`` for ``--data``: a path, not ``-`` (a recording is not read from standard input)."""
    if text.strip() == "-":
        raise argparse.ArgumentTypeError("'-' (standard input): footzoo reads a recording from a file, not from a "
                                         "stream; save it to a file and give its path")
    return text


def _metric_names(text: str) -> list[str]:
    """An argparse ``type`` for ``--show``: comma-separated names of footzoo's metrics (a misspelt one would show
    an empty table)."""
    # deferred: the metrics (pandas), read only for --show given
    from ..evaluation.metrics import METRICS

    names = [n.strip() for n in text.split(",") if n.strip()]
    for name in names:
        if name not in METRICS:
            raise argparse.ArgumentTypeError(f"{name!r} is not a metric{did_you_mean(name, list(METRICS))}; "
                                             f"metrics: {', '.join(METRICS)}")
    if not names:
        raise argparse.ArgumentTypeError("no metric named; give metrics separated by commas, e.g. armse_3d_m,strides")
    return names


def _input_yaml(text: str) -> str:
    """An argparse ``type`` for a config or study argument: a shipped name or a path, never empty ('' is not '.')."""
    return _named(text, "an empty name; give a shipped config's name (footzoo configs lists them) or the path of a "
                  "YAML file", what="name")


def _destination(text: str) -> str:
    """An argparse ``type`` for ``--to``: a non-empty path (an empty one would silently mean here)."""
    return _named(text, "an empty path; give a folder or file name (or leave --to out: here)")


def _folder(text: str) -> str:
    """An argparse ``type`` for an output folder (``compile --ship``): non-empty, and not an existing file."""
    _named(text, "an empty path; give a folder name")
    if Path(text).exists() and not Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file, not a folder; give a folder name (it is created if "
                                         "missing)")
    return text


EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_USAGE = 2
EXIT_DATA = 3
EXIT_PLUGIN = 4
EXIT_INTERRUPTED = 130

EXIT_CODES_HELP = """exit codes:
  0    success
  1    internal error (a bug in footzoo: rerun with --debug and report it)
  2    usage or configuration error (arguments, config, study or calibration file)
  3    data error (unreadable, malformed or implausible recording; unwritable output)
  4    plug-in error (a plug-in raised or broke its contract: the message names it and the cause)
  130  interrupted
"""


def _number(lo: float, hi: float, unit: str = "", integer: bool = False):
    """An argparse ``type``: a finite number in [lo, hi] (a usage error, exit code 2, otherwise)."""

    def parse(text: str) -> float | int:
        try:
            value = int(text) if integer else float(text)
        except ValueError:
            kind = "a whole number" if integer else "a number"
            raise argparse.ArgumentTypeError(f"{text!r} is not {kind}") from None
        if not (lo <= value <= hi):  # also rejects nan
            u = f" {unit}" if unit else ""
            if integer and hi >= 2**31:  # no real upper bound
                raise argparse.ArgumentTypeError(f"{text}{u} is out of range: it must be a whole number >= {lo:g}{u}")
            raise argparse.ArgumentTypeError(f"{text}{u} is out of range: it must lie in [{lo:g}, {hi:g}]{u}")
        return value

    return parse


def _jobs(text: str) -> int:
    """An argparse ``type`` for ``--jobs``: -1 (every core) or 1 up to a few per core of this machine."""
    # deferred: pandas and the study runner, loaded only for --jobs
    from ..studies.study import check_jobs

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    try:
        return check_jobs(value, text)
    except ConfigError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _biases(text: str) -> tuple[str, ...]:
    """An argparse ``type`` for ``--biases``: ``none`` or a comma-separated subset of acc, gyr, mag."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty list; give a comma-separated list of acc, gyr, mag (e.g. acc,gyr), "
                                         "or none")
    if text.strip() == "none":
        return ()
    names = tuple(b.strip() for b in text.split(","))
    unknown = [b for b in names if b not in ("acc", "gyr", "mag")]
    if unknown:
        raise argparse.ArgumentTypeError(f"{', '.join(map(repr, unknown))}: unknown bias; give a comma-separated "
                                         "list of acc, gyr, mag (e.g. acc,gyr), or none")
    return names


def _scheduler(text: str) -> str:
    """An argparse ``type`` for ``--scheduler``: a Dask scheduler's address, checked before any work."""
    # deferred: pandas and the study runner, loaded only for --scheduler
    from ..studies.runner import check_scheduler

    try:
        return check_scheduler(text)
    except ConfigError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _writable_dir(path: str, option: str = "--out") -> Path:
    """Create ``path`` if needed and check it is a writable directory, before any work is done."""
    out = Path(path)
    if out.is_symlink() and not out.exists():
        raise OutputError(f"{option} {path!r} {why_missing(out)}")
    if out.exists() and not out.is_dir():
        raise OutputError(f"{option} {path!r} exists and is not a directory; choose a directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except PermissionError:
        raise OutputError(f"{option} {path!r} cannot be created (permission denied); choose a writable place") from None
    except OSError as err:
        raise OutputError(f"{option} {path!r} cannot be created: {err.strerror or err}") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise OutputError(f"{option} {path!r} is not writable (permission denied); choose a writable directory")
    return out


def _writable_file(path: str, option: str = "--out") -> Path:
    """Check that the file ``path`` can be written (its folder exists and is writable), before any work."""

    p = check_target(path, option)
    if p.exists() and not os.access(p, os.W_OK):
        raise OutputError(f"{option} {path!r} is not writable (permission denied); choose a writable place")
    return p


def _load_recording(args: argparse.Namespace):
    # deferred: pandas and the readers: the command line starts without them
    from ..io import builtin_sample, load

    if args.data is None:
        given = [o for o in ("option", "format") if getattr(args, o, None)]
        if given:  # they describe --data; the built-in walk is read as it is
            raise ConfigError(f"--{given[0]} describes the file given with --data; without --data footzoo runs its "
                              f"built-in walk, which takes no reader options: add --data FILE or drop --{given[0]}")
        rec = builtin_sample()
        if getattr(args, "foot", None) in ("left", "right"):
            rec.meta["foot"] = args.foot  # the sample does not say which foot it is from
        return rec
    return load(args.data, format=args.format, **_reader_options(args))


def _two_feet(args: argparse.Namespace) -> bool:
    """Run both feet: ``--foot both``, or a gaitmap file with both sensors and no ``--foot``."""
    if args.data is None:
        if args.foot == "both":
            raise FormatError("--foot both needs --data with a two-foot file (gaitmap)")
        return False
    if args.foot not in (None, "both"):
        return False
    # deferred: pandas and the readers: the command line starts without them
    from ..io import check_input_file, detect_format
    from ..io.gaitmap import feet

    fmt = args.format or detect_format(check_input_file(args.data), _reader_options(args))
    if fmt != "gaitmap":
        if args.foot == "both":
            how = (" (a file with both feet's columns: one description per foot, each run with --option sidecar=, or "
                   "both at once in Python as a footzoo.Session: docs/readers/generic.md, 'Both feet in one file')"
                   if fmt == "generic" else "")
            raise FormatError(f"{args.data}: a {fmt} file holds one foot; --foot both needs a gaitmap file{how}")
        return False
    return len(feet(Path(args.data))) == 2 or args.foot == "both"


def _print_metrics(title: str, metrics: dict[str, Any], notes: dict[str, str] | None = None) -> None:
    print(title)
    notes = notes or {}
    width = max([32, *(len(str(k)) for k in metrics)])  # one column of values, however long a name
    for key, value in metrics.items():
        why = f"   (refused: {notes[key]})" if key in notes else ""
        print(f"  {key:{width}s} {value:.4f}{why}" if isinstance(value, float) else f"  {key:{width}s} {value}{why}")


#: Files ``footzoo run --out DIR`` writes (a result archive with CSV tables, :mod:`footzoo.core.archive`).
RUN_OUTPUTS = ("samples.csv", "steps.csv", "metrics.json", "result.json", "arrays.npz", "manifest.json")
#: The figures ``--plot`` may add (:func:`footzoo.evaluation.plots.run_figures`).
RUN_FIGURES = ("trajectory.png", "states.png", "errors.png", "strides.png", "fpa.png")


def _inputs(args: argparse.Namespace, rec=None) -> list[str]:
    """Every file the command read: the recording and its sidecars, the config."""
    files = [str(f) for f in (rec.meta.get("input_files") or []) if f] if rec is not None else []
    for name in ("data", "config"):
        value = getattr(args, name, None)
        if value and Path(value).is_file():
            files.append(value)
    return files


def _locked(folder: Path, owner: str):
    """The output folder's lock for this command (another footzoo process writing into it is refused)."""
    return folder_lock(folder, "--out", owner)


def _check_outputs(folder: Path, names: tuple[str, ...], inputs: list[str], option: str = "--out") -> None:
    """Refuse, before the run, an output folder whose files would replace an input, or a file footzoo did not write."""
    # deferred: pandas (the result archive): the command line starts without it
    from ..core.archive import check_folder

    refuse_inputs([folder / n for n in names], inputs, option)
    check_folder(folder, names, option)


def _figures(result, rec) -> dict[str, bytes]:
    """The run's figures (``--plot``) as PNG files in memory: saved with the result, as one unit."""
    # deferred: matplotlib's figures, drawn only with --plot
    from ..evaluation.plots import png_bytes, run_figures

    return {name: png_bytes(fig) for name, fig in run_figures(result, rec).items()}


def _write_result(result, rec, out: Path, plot: bool, inputs: list[str]) -> list[str]:
    """The result archive (samples.csv, steps.csv, metrics.json, result.json, ...) with the figures (``--plot``)
    and the command's log.

    One commit: the manifest is written last, and the figures of an earlier run into the folder
    that this one does not draw are removed with it (they belong to the earlier result).
    """
    from ..core.archive import MANIFEST

    figures = _figures(result, rec) if plot else {}
    files = {**figures, LOG: log_text(result.diagnostics["warnings"])}
    # absolute: --out ./- (a folder named "-", which --out accepts) is Path("-") once made a Path, which save refuses
    folder = result.save(out.absolute(), backend="csv", inputs=inputs, files=files)
    saved = json.loads((folder / MANIFEST).read_text(encoding="utf-8")).get("files", [])
    return sorted({*(str(f) for f in saved if f not in files), MANIFEST}) + sorted(files)  # reference tables too


def _refuse_swapped(config: str, data: str | None) -> None:
    """A ConfigError naming both when the config is a recording and ``--data`` a YAML file: the two were swapped."""
    from ..core.yamlsafe import RECORDING_SUFFIXES

    if data is None or Path(data).suffix.lower() not in (".yaml", ".yml"):
        return
    if Path(config).suffix.lower() in RECORDING_SUFFIXES:
        raise ConfigError(f"{config!r} is a recording and --data {data!r} a config file: the config comes first and "
                          f"the recording after --data (swapped?): footzoo run {data} --data {config}")


def cmd_run(args: argparse.Namespace) -> int:
    """Run a pipeline on a recording (or both feet of a session); print metrics; optionally write outputs."""
    # deferred: pandas and the engine: the command line starts without them
    from ..runtime.pipeline import Pipeline

    _refuse_swapped(args.config, args.data)
    pipeline = Pipeline.from_yaml(args.config)
    out = _writable_dir(args.out) if args.out is not None else None
    if args.plot and out is None:
        raise ConfigError("--plot needs --out DIR (the folder the figures are written to): add --out DIR")
    if out is None:
        return _run(args, pipeline, None)
    data = Path(args.data).name if args.data else "the built-in sample"
    with _locked(out, f"footzoo run {Path(args.config).name} on {data}"):
        return _run(args, pipeline, out)


def _run(args: argparse.Namespace, pipeline, out: Path | None) -> int:
    """:func:`cmd_run` once its output folder (if any) is locked."""
    if _two_feet(args):
        return _run_session(args, pipeline)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec = _load_recording(args)
    if not args.quiet:
        for w in caught:
            print(f"note: {w.message}", file=sys.stderr)
    if out is not None:
        _check_outputs(out, (*RUN_OUTPUTS, LOG, *(RUN_FIGURES if args.plot else ())), _inputs(args, rec))
    with kept_warnings(args) as later:
        result = pipeline.run(rec)
        metrics = result.metrics
    result.diagnostics["warnings"] = warning_texts([*caught, *later])
    if "pyshoe_trial_error" in rec.meta:
        metrics["pyshoe_published_best_m"] = min(rec.meta["pyshoe_trial_error"].values())
    ref = f"; reference: {rec.truth.source}" if rec.truth is not None and rec.truth.source else ""
    _print_metrics(f"pipeline  {pipeline.name}  on  {rec.name}  ({rec.n} samples, {rec.rate:.1f} Hz{ref})", metrics,
                   result.metric_notes)
    if out is not None:
        written = _write_result(result, rec, out, args.plot, _inputs(args, rec))
        print(f"wrote {', '.join(written)} to {args.out} (footzoo.Result.load({args.out!r}) reads it back)")
    tell_unshown(args, result.diagnostics["warnings"], None if out is None else out / LOG)
    return 0


class kept_warnings:
    """Record the warnings of a block; shown as they come unless ``--quiet``, kept either way.

    ``with kept_warnings(args) as caught: ...`` gives the list of :class:`warnings.WarningMessage`.
    """

    def __init__(self, args: argparse.Namespace):
        self.quiet = bool(getattr(args, "quiet", False))
        self._ctx = warnings.catch_warnings(record=True)

    def __enter__(self) -> list[warnings.WarningMessage]:
        self.caught = self._ctx.__enter__()  # the filters stay: what footzoo ignores on purpose stays ignored
        return self.caught

    def __exit__(self, *exc: Any) -> None:
        self._ctx.__exit__(*exc)
        if not self.quiet:
            shown: set[str] = set()
            for w in self.caught:
                if str(w.message) not in shown:
                    shown.add(str(w.message))
                    warnings.showwarning(w.message, w.category, w.filename, w.lineno)


def tell_unshown(args: argparse.Namespace, texts: list[str], log: Path | None = None) -> None:
    """With ``--quiet``: one line saying how many warnings were not shown, and where they are kept (``log``, the
    command's folder log, when it wrote one)."""
    if getattr(args, "quiet", False) and texts:
        where = (f"they are kept in {log}" if log is not None
                 else f"without --quiet they are printed, with --out they are kept in OUT/{LOG}")
        print(f"footzoo: {len(texts)} warning(s) not shown (--quiet); {where}", file=sys.stderr)


def logged_texts(log: Path) -> list[str]:
    """The warnings a command's folder log lists (none when it is absent or says there were none)."""
    try:
        lines = log.read_text(encoding="utf-8").splitlines()
    except OSError:
        return []
    return [] if lines == ["no warnings"] else [line for line in lines if line.strip()]


def _run_session(args: argparse.Namespace, pipeline) -> int:
    """Both feet of a gaitmap file: per-foot metrics, the bilateral table, per-foot outputs."""
    # deferred: pandas and the engine: the command line starts without them
    from ..runtime.session import Session

    options = _reader_options(args)
    session = Session.load(args.data, format=args.format, **options)
    inputs = [f for rec in session.recordings.values() for f in _inputs(args, rec)]
    if args.out is not None:
        out = Path(args.out)
        _check_outputs(out, ("steps.csv", "bilateral.csv", "manifest.json", LOG), inputs)
        for foot in session.recordings:
            _check_outputs(out / foot, RUN_OUTPUTS, inputs)
    with kept_warnings(args) as caught:
        res = session.run(pipeline)
        for r in res.results.values():
            _ = r.metrics  # their warnings (refused metrics) are the command's too
    texts = warning_texts(caught)
    for r in res.results.values():
        r.diagnostics["warnings"] = texts  # the command's warnings, both feet's
    for foot, r in res.results.items():
        rec = session.recordings[foot]
        ref = f"; reference: {rec.truth.source}" if rec.truth is not None and rec.truth.source else ""
        _print_metrics(f"pipeline  {pipeline.name}  on  {rec.name}  ({rec.n} samples, {rec.rate:.1f} Hz{ref})",
                       r.metrics, r.metric_notes)
    print("bilateral (medians; symmetry index = 100 |L - R| / mean, %)")
    print(res.bilateral.to_string(float_format=lambda v: f"{v:.4f}"))
    if args.out is not None:
        out = Path(args.out)
        figures = {foot: _figures(r, session.recordings[foot]) for foot, r in res.results.items()} if args.plot else {}
        res.save(out.absolute(), backend="csv", inputs=inputs, files={**figures, ".": {LOG: log_text(texts)}})
        written = sorted(p.name for p in (out / next(iter(res.results))).iterdir() if p.name in RUN_OUTPUTS)
        written += sorted(next(iter(figures.values()), {}))
        print(f"wrote {'/ and '.join(res.results)}/ ({', '.join(written)}), steps.csv, bilateral.csv and {LOG} to "
              f"{out} (footzoo.SessionResult.load({str(out)!r}) reads it back)")
    tell_unshown(args, texts, None if args.out is None else Path(args.out) / LOG)
    return 0


def cmd_list(args: argparse.Namespace) -> int:
    """Print every plug-in (or one kind, or one by name) with its parameters, and the config's settings."""
    theirs: list[str] = []
    if args.plugins:
        from ..plugins.extensions import load_plugins  # deferred: the plug-ins' imports

        for i, loaded in enumerate(load_plugins(args.plugins, where="--plugins")):
            theirs += registered_by(loaded["module"])
            if not registered_by(loaded["module"]):
                warnings.warn(FootzooWarning(
                    f"--plugins[{i}]: {loaded['path']} registers no plug-in, so nothing of it is listed: decorate "
                    "each plug-in class with @footzoo.register (a subclass of a footzoo kind, e.g. Detector)"),
                    stacklevel=user_stacklevel())
        if args.kind is None and args.name is None:  # the files' plug-ins, not buried among footzoo's own
            if theirs:
                print("".join(describe(None, name) for name in dict.fromkeys(theirs)), end="")
                print("(the plug-ins of --plugins; footzoo list without it lists footzoo's own)")
            return EXIT_OK
    if args.kind == "settings" or (args.kind is None and args.name is None):
        plugins = describe() if args.kind is None else ""
        print(plugins + ("\n" if plugins else "") + describe_settings(), end="")
        return EXIT_OK
    print(describe(args.kind, args.name), end="")
    return EXIT_OK


def describe_settings() -> str:
    """The settings of a pipeline config (``gravity``, ``init``, ``navigation``, ``guards``), as declared."""
    # deferred: pandas and the engine: the command line starts without them
    from ..runtime.validate import settings_declarations

    lines = ["settings (top-level blocks of a pipeline config):"]
    lines += describe_parameters(settings_declarations(), indent="  ")
    return "\n".join(lines) + "\n"


def cmd_validate(args: argparse.Namespace) -> int:
    """Check a config without running it: ``plugins:`` loaded as ``footzoo run`` loads them, every problem listed."""
    # deferred: yaml, pandas and the engine: the command line starts without them
    from ..config.library import resolve
    from ..config.schema import is_study_file, load_yaml
    from ..runtime.pipeline import Pipeline
    from ..runtime.validate import config_errors

    path = resolve(args.config)
    data = load_yaml(path)
    if is_study_file(data):
        return _validate_study(args.config, path, "tune" in data)
    errors = config_errors(data, base_dir=path.parent)
    if errors:
        print(f"{args.config}: {len(errors)} problem(s)", file=sys.stderr)
        for e in errors:
            print(f"  - {e}", file=sys.stderr)
        return EXIT_USAGE
    pipeline = Pipeline.from_yaml(path)
    print(f"{args.config}: valid")
    print(live_summary(pipeline))
    if args.resolved:
        import yaml

        print("# the config with every default filled in (what footzoo run runs):")
        print(yaml.safe_dump(json.loads(json.dumps(pipeline.to_dict())), sort_keys=False), end="")
    return EXIT_OK


def _validate_study(name: str, path: Path, tune: bool) -> int:
    """Check a study (or tune) file as ``footzoo ablate`` (``tune``) does before its first run, without running it."""
    # deferred: the study runner: the command line starts without it
    from ..studies import Study
    from ..studies.tune import check_groups, load_tune_file, recording_groups

    if tune:
        study, spec = load_tune_file(path)
        study.check()
        groups = recording_groups(study, spec.group_by)
        check_groups(groups, spec.group_by)
        what = (f"tune file: {spec.search} search, objective {spec.objective} ({spec.direction}); "
                f"{len(study.recordings)} recording(s) in {groups.nunique()} groups")
    else:
        study = Study.from_yaml(path)
        study.check()
        what = (f"study: {len(study.configs())} config(s) x {len(study.recordings)} recording(s) = "
                f"{len(study.configs()) * len(study.recordings)} runs")
    command = "footzoo tune" if tune else "footzoo ablate"
    print(f"{name}: valid {what}; every config of the grid and every recording's reader options checked "
          f"(the recordings are read when they run: {command} {name})")
    return EXIT_OK


def live_summary(pipeline: Any) -> str:
    """One line: the pipeline's latency live (at 100 Hz), or why it cannot run live."""

    problems = pipeline.live_problems()
    if problems:
        return "live: no — " + "; ".join(problems)
    return f"live: yes, latency {pipeline.latency(RunContext(rate=100.0, gravity=pipeline.gravity))} (at 100 Hz)"


def cmd_compile(args: argparse.Namespace) -> int:
    """Compile and cache the kernels of pipeline configs (or write them into a wheel's folder with --ship)."""
    # deferred: numba, loaded only to compile
    from .compile import compile_kernels

    for config, seconds in compile_kernels(args.configs, ship=args.ship, smoothed_live=not args.no_smoothed_live):
        print(f"{config}: {seconds:.1f} s")
    return 0


def cmd_simulate(args: argparse.Namespace) -> int:
    """Simulate a recording with ground truth and write it as canonical CSV/Parquet."""

    # deferred: pandas and scipy (the simulator): the command line starts without them
    from ..io.canonical import check_output, write
    from ..sim import (
        DistanceSensors,
        MagneticDisturbance,
        NoiseModel,
        simulate,
        simulate_calibration,
        simulate_pendulum,
    )

    check_output(_writable_file(args.out))
    noise = NoiseModel(scale=args.noise_scale, biases=args.biases, seed=args.seed)
    if args.scenario == "pendulum":
        rec = simulate_pendulum(rate=args.rate, noise=noise, sampling=args.sampling)
    elif args.scenario == "calibration":
        rec = simulate_calibration(mount_yaw=np.radians(args.mount_yaw), foot=args.foot, rate=args.rate, noise=noise)
    else:
        rec = simulate(
            path=args.scenario, n_strides=args.strides, stride_length=args.stride_length, rate=args.rate,
            profile=args.profile, sampling=args.sampling, noise=noise, seed=args.seed,
            fpa=np.radians(args.fpa), mount_yaw=np.radians(args.mount_yaw), foot=args.foot,
            distance_sensors=DistanceSensors() if args.distance_sensors else False,
            disturbance=MagneticDisturbance() if args.disturbance else None,
        )
    out = write(rec, args.out)
    closed = "closed loop" if rec.truth.closed_loop else "open path"
    print(f"wrote {out} ({rec.n} samples at {rec.rate:.0f} Hz, {rec.t[-1]:.1f} s, {closed}, "
          f"{0 if rec.truth.steps is None else len(rec.truth.steps)} strides)")
    return 0


def cmd_calibrate(args: argparse.Namespace) -> int:
    """Foot vector from a calibration recording (Huang et al. 2016, eq. 11), saved as YAML."""

    # deferred: pandas and the readers: the command line starts without them
    from ..analysis.foot_vector import calibrate_foot_vector, calibration_trial_problems

    if Path(args.out).suffix.lower() not in YAML_SUFFIXES:  # huang_fpa reads its calibration as YAML
        raise ConfigError(f"--out {args.out!r}: the foot-vector calibration is a YAML file, which huang_fpa's "
                          f"calibration: reads; name it '{Path(args.out).stem}.yaml'")
    target = _writable_file(args.out)
    rec = _load_recording(args)
    refuse_inputs([target], _inputs(args, rec), "--out")
    fv = calibrate_foot_vector(rec, still=tuple(args.still) if args.still else None,
                               flex=tuple(args.flex) if args.flex else None)
    problems = calibration_trial_problems(rec, fv)
    if problems:
        raise RecordingError(f"{rec.name} is not a calibration trial (stand still, then slow dorsi-/plantar-flexions "
                             "about the ankle, e.g. footzoo simulate calibration): " + "; ".join(problems)
                             + ". Record one, or give its periods with --still T0 T1 --flex T0 T1")
    with atomic_path(target, inputs=_inputs(args, rec), what="--out") as tmp:
        fv.save(tmp)
    yaw = np.degrees(np.arctan2(-fv.vector[1], fv.vector[0]))
    print(f"foot vector (sensor frame, FRD): {np.round(fv.vector, 4).tolist()}  "
          f"(sensor yawed {yaw:.2f}° on the foot)")
    print(f"still {fv.still[0]:.2f}-{fv.still[1]:.2f} s, flexions {fv.flex[0]:.2f}-{fv.flex[1]:.2f} s")
    print(f"wrote {args.out}; use it with analysis: [{{type: huang_fpa, calibration: {args.out}}}]")
    return 0


def cmd_ablate(args: argparse.Namespace) -> int:
    """Run a study: every config × recording cell, in parallel, cached, with tables and plots."""
    # deferred: pandas, scipy and the study runner: the command line starts without them
    from ..studies import run_study
    from ..studies.report import compared, crossed, readable, summarise, to_markdown

    out = Path(args.out or f"ablation_{Path(args.study).stem}")  # printed as 'results in study/', not 'study//'
    prune = {"max_age_days": 0.0 if args.prune_cache else args.cache_max_age,
             "max_bytes": None if args.cache_max_size is None else int(args.cache_max_size * 1e6)}
    with kept_warnings(args):  # and in OUT/footzoo.log, written with the study's report
        table = run_study(args.study, jobs=args.jobs, scheduler=args.scheduler, out=out, progress=not args.quiet,
                          max_cells=args.max_cells, prune=prune)
    a = table.attrs
    notes = [f"{len(a['recomputed'])} damaged cache entries run again (see {out}/cache_report.log)"
             if a["recomputed"] else "", f"{len(a['retried'])} failed runs retried" if a["retried"] else ""]
    if a.get("pruned", {}).get("removed"):
        notes.append(f"{a['pruned']['removed']} old cache entries removed")
    notes = "".join(f", {n}" for n in notes if n)
    print(f"{a['computed'] + a['cached']} runs ({a['computed']} computed, {a['cached']} from the cache, "
          f"{a['failed']} failed{notes}); results in {out}/")
    tell_unshown(args, logged_texts(out / LOG), out / LOG)
    total = a["computed"] + a["cached"]
    if a["causes"]:
        failed = "every run" if a["failed"] == total else f"{a['failed']} run{'' if a['failed'] == 1 else 's'}"
        print(f"{failed} failed; the distinct causes:", file=sys.stderr)
        for cause, n in list(a["causes"].items())[:5]:
            print(f"  - {cause} ({n} run{'' if n == 1 else 's'})", file=sys.stderr)
    if total and a["failed"] == total:
        return _failed_exit_code(a["causes"])
    factors = [c for c in table.columns
               if c not in ("run", "base", "recording", "metric", "value", "error", "note")]
    shown = compared(table, factors)
    for f in shown[:3]:
        s = readable(summarise(table, f), f)
        keep = s[s["metric"].isin(args.show)] if args.show else s
        print(f"\n{f}:")
        print(to_markdown(keep), end="")
    if len(shown) == 2:  # two factors: the median of each pair of levels too (summary.md has every pair)
        s = crossed(table, *shown)
        print(f"\n{shown[0]} × {shown[1]} (median):")
        print(to_markdown(s[s["metric"].isin(args.show)] if args.show else s), end="")
    return 0


def cmd_tune(args: argparse.Namespace) -> int:
    """Choose a setting by leave-one-group-out cross-validation; write it as a config YAML."""
    # deferred: pandas, scipy and the study runner: the command line starts without them
    from ..studies.report import to_markdown
    from ..studies.tune import load_tune_file, tune

    study, spec = load_tune_file(args.study)
    out = _writable_dir(args.out or f"tune_{Path(args.study).stem}")
    if args.config:
        spec.config = str(_writable_file(args.config, "--config"))
    with kept_warnings(args):  # and in OUT/footzoo.log, written with the tune's tables
        result = tune(study, spec, jobs=args.jobs, scheduler=args.scheduler, out=out, progress=not args.quiet)
    print(f"{len(result.settings_)} settings x {len(result.values_)} recordings in {result.groups_.nunique()} "
          f"groups; objective {spec.objective} ({spec.aggregate}, {spec.direction})")
    print("leave-one-group-out (each group scored by the setting chosen without it):")
    print(to_markdown(result.folds_), end="")
    print(f"chosen on every group: {result.best_}")
    for edge in result.edges_:
        print(f"  at the edge of the search: {edge}")
    print(f"wrote {spec.config or out / 'best.yaml'} (footzoo run it), {out}/tune_folds.csv, {out}/tune_scores.csv")
    tell_unshown(args, logged_texts(out / LOG), out / LOG)
    return EXIT_OK


def _failed_exit_code(causes: dict[str, int]) -> int:
    """The exit code of a study whose every run failed: data error when a recording is at fault, else usage."""
    kinds = {c.partition(":")[0] for c in causes}
    return EXIT_DATA if kinds & {"RecordingError", "FormatError", "OutputError"} else EXIT_USAGE


def cmd_formats(args: argparse.Namespace) -> int:
    """Print every reader footzoo can use (built-in and installed): name, extensions, description, options."""
    # deferred: pandas and the readers: the command line starts without them
    from ..io.registry import available

    readers = available()
    for name, reader in readers.items():
        origin = readers.origins.get(name, "")
        exts = ", ".join(getattr(reader, "extensions", ()) or ()) or "any file"
        print(f"{name:<14} {getattr(reader, 'description', '')}")
        print(f"{'':<14} files: {exts}{'' if origin == 'footzoo' else f'; from {origin}'}")
        for opt, spec in (getattr(reader, "options", None) or {}).items():
            unit = f" [{spec.unit}]" if getattr(spec, "unit", "") else ""
            print(f"{'':<16} --option {opt}=...{unit}  default {getattr(spec, 'default', None)!r}: "
                  f"{getattr(spec, 'doc', '')}")
        if "axes" not in (getattr(reader, "options", None) or {}):
            print(f"{'':<16} --option axes=...  default '[x, y, z]': the axes of what the reader returns -> FRD, "
                  "applied by footzoo after the reader (footzoo.io.axes)")
    for name, reason in readers.broken.items():
        print(f"{name:<14} NOT AVAILABLE: {reason}")
    print("read a file with: footzoo run CONFIG --data FILE [--format NAME] [--option NAME=VALUE ...]; an axis map "
          "on the command line: --option 'axes=[x, -y, -z]' (quoted) or --option axes=x,-y,-z")
    return EXIT_OK


def cmd_list_compat(args: argparse.Namespace) -> int:
    """Print which orientation × correction combinations validate, with the reasons for the others."""
    # deferred: pandas and the engine (it builds pipelines): the command line starts without them
    from .compat import compatibility_matrix

    print(compatibility_matrix(), end="")
    return 0


def cmd_configs(args: argparse.Namespace) -> int:
    """List the shipped configs with the first line of their description, or copy one (``--copy``)."""
    # deferred: yaml: the command line starts without it
    from ..config import library

    if not args.copy and (args.to is not None or args.force):
        given = "--to" if args.to is not None else "--force"
        raise ConfigError(f"{given} goes with --copy NAME (the shipped config to copy): footzoo configs --copy NAME "
                          "--to DEST")
    if args.copy:
        target = library.copy(args.copy, args.to or ".", overwrite=args.force)
        print(f"wrote {target} (a copy of the shipped {library.path(args.copy).stem}); edit it and run "
              f"footzoo run {target}")
        return EXIT_OK
    # deferred: pandas and the engine: the command line starts without them
    from ..runtime.pipeline import Pipeline

    for kind in ("pipeline", "study"):
        print(f"{kind} configs ({'footzoo ablate NAME' if kind == 'study' else 'footzoo run NAME'}):")
        indent = " " * 27
        for name in library.names(kind):
            print(textwrap.fill(_first_sentence(library.path(name)), width=110, initial_indent=f"  {name:<24} ",
                                subsequent_indent=indent))
            if kind == "pipeline":
                print(textwrap.fill(live_summary(Pipeline.from_yaml(name)), width=110, initial_indent=indent,
                                    subsequent_indent=indent))
    print("copy one to edit it: footzoo configs --copy NAME [--to FOLDER]")
    return EXIT_OK


#: The end of a sentence: a full stop before a capital or a number, not the one of an abbreviation ("et al.", "Fig.",
#: "eq.", "K.F.").
_SENTENCE_END = re.compile(r"(?<!\bal)(?<!\bFig)(?<!\b[Ee]q)(?<!\b[Ee]qs)(?<!\bSec)(?<!\bvs)(?<!\b[A-Z])"
                           r"\.\s+(?=[A-Z0-9(])")


def _first_sentence(path: Path) -> str:
    """The first sentence of a YAML file's leading comment block, without the ``#`` (its lines joined)."""
    lines = []
    for line in path.read_text().splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("#").strip())
    text = " ".join(x for x in lines if x)
    end = _SENTENCE_END.search(text)
    return text[: end.start() + 1] if end else text


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``footzoo`` command."""
    parser = argparse.ArgumentParser(
        prog="footzoo", description="Foot-mounted IMU motion estimation: a zoo of published building blocks.",
        epilog=EXIT_CODES_HELP, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--debug", action="store_true", help="show the Python traceback of an error")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help="show the Python traceback of an error")
    common.add_argument("--quiet", action="store_true", help="no warnings and no progress bar on the terminal: a "
                        f"command writing a folder (--out) keeps them in its {LOG} (run --out also in the saved "
                        "result); the others say how many they did not show")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_subparser(common))

    run = sub.add_parser("run", help="run a pipeline config on a recording (default: the built-in walk)")
    run.add_argument("config", type=_input_yaml, help="pipeline YAML, e.g. yun2012")
    run.add_argument("--data", type=_recording_path, help="recording file (default: built-in x-io short walk)")
    run.add_argument("--format", help=f"reader name: {', '.join(BUILTIN)} or an installed one "
                     "(footzoo formats lists them; default: detect)")
    run.add_argument("--foot", choices=["left", "right", "both"],
                     help="foot to read from a two-foot file (gaitmap; default: both when the file has both), "
                          "or the foot a one-foot recording is from")
    run.add_argument("--acc-unit", choices=list(ACC_UNITS), help="accelerometer unit (default: the format's)")
    run.add_argument("--gyr-unit", choices=list(GYR_UNITS), help="gyroscope unit (default: the format's)")
    run.add_argument("--option", action="append", type=_reader_option, metavar="NAME=VALUE",
                     help="a reader option (repeatable), e.g. --option rate=820; footzoo formats lists them")
    run.add_argument("--out", type=_output, help="directory for the result: samples.csv, steps.csv, metrics.json "
                     "(+ result.json, arrays.npz, manifest.json: footzoo.Result.load(DIR) reads it back); written "
                     "atomically, never over an input")
    run.add_argument("--plot", action="store_true", help="also write the run's figures: trajectory, states, "
                     "errors (with a reference), strides, fpa (.png, needs --out)")
    run.set_defaults(func=cmd_run)

    comp = sub.add_parser("compile", help="compile the kernels of pipeline configs now, so that their first "
                          "run loads them from numba's cache (e.g. before a study on a new machine)")
    comp.add_argument("configs", nargs="+", type=_input_yaml,
                      help="pipeline YAML files or study files (every config of the grid), "
                           "e.g. configs/*.yaml")
    comp.add_argument("--ship", metavar="DIR", type=_folder, help="write the machine code into DIR instead of "
                      "numba's cache (what setup.py does for a wheel's footzoo/_compiled)")
    comp.add_argument("--no-smoothed-live", action="store_true", help="leave out the live runs of step-wise "
                      "smoothed configs (their live loop: about 14 s more each; what setup.py does for a wheel)")
    comp.set_defaults(func=cmd_compile)

    sim = sub.add_parser("simulate", help="simulate a foot-mounted IMU recording with ground truth")
    sim.add_argument("scenario", choices=["straight", "rectangle", "track", "figure_eight", "mixed_speed", "run",
                                          "stairs", "pendulum", "calibration"],
                     help="the walk (run: a running gait; stairs: a flight up, from a level start), a pendulum or a "
                          "foot-vector calibration trial")
    sim.add_argument("--out", required=True, type=_output,
                     help="output file (.csv or .parquet); truth in true_* columns, with its sidecars")
    sim.add_argument("--strides", type=_number(1, 100_000, integer=True), default=100,
                     help="strides of a straight walk (default 100)")
    sim.add_argument("--stride-length", type=_number(0.05, 5.0, "m"), default=1.2,
                     help="stride length in m (default 1.2)")
    sim.add_argument("--rate", type=_number(10.0, 20_000.0, "Hz"), default=50.0,
                     help="sampling rate in Hz (default 50)")
    sim.add_argument("--profile", choices=["paper", "physical"], default="paper", help="stance kinematics")
    sim.add_argument("--sampling", choices=["interval", "instantaneous"], default="interval")
    sim.add_argument("--noise-scale", type=_number(0.0, 1000.0), default=1.0,
                     help="factor on Table II noise σ (default 1)")
    sim.add_argument("--biases", type=_biases, default=("acc", "gyr", "mag"),
                     help="Table II biases to include, comma-separated: acc,gyr,mag (default), or none")
    sim.add_argument("--seed", type=_number(0, 2**63 - 1, integer=True), default=0,
                     help="seed of the noise (a whole number >= 0; default 0)")
    sim.add_argument("--fpa", type=_number(-90.0, 90.0, "deg"), default=0.0,
                     help="foot progression angle in deg (toe-out +)")
    sim.add_argument("--mount-yaw", type=_number(-180.0, 180.0, "deg"), default=0.0,
                     help="sensor yaw on the foot in deg")
    sim.add_argument("--foot", choices=["right", "left"], default="right")
    sim.add_argument("--distance-sensors", action="store_true", help="add two VL6180-like range sensors")
    sim.add_argument("--disturbance", action="store_true", help="add a magnetic disturbance (first 10 m north)")
    sim.set_defaults(func=cmd_simulate)

    cal = sub.add_parser("calibrate", help="foot vector from a still period and slow dorsi-/plantar-flexions")
    cal.add_argument("--data", required=True, type=_recording_path, help="calibration recording")
    cal.add_argument("--format", help="reader format (default: detect)")
    cal.add_argument("--foot", choices=["left", "right"], help="foot to read from a two-foot file (gaitmap)")
    cal.add_argument("--acc-unit", choices=list(ACC_UNITS), help="accelerometer unit (default: the format's)")
    cal.add_argument("--gyr-unit", choices=list(GYR_UNITS), help="gyroscope unit (default: the format's)")
    cal.add_argument("--still", nargs=2, type=_number(-1e12, 1e12, "s"), metavar=("T0", "T1"),
                     help="still period (s); default: found")
    cal.add_argument("--flex", nargs=2, type=_number(-1e12, 1e12, "s"), metavar=("T0", "T1"),
                     help="flexion period (s); default: found")
    cal.add_argument("--option", action="append", type=_reader_option, metavar="NAME=VALUE",
                     help="a reader option (repeatable), e.g. --option rate=820")
    cal.add_argument("--out", required=True, type=_output, help="YAML file to write (never over the recording)")
    cal.set_defaults(func=cmd_calibrate)

    abl = sub.add_parser("ablate", aliases=["study"],
                         help="run an ablation study (configs x recordings) and write tables and plots")
    abl.add_argument("study", type=_input_yaml, help="study YAML, e.g. study_quick")
    abl.add_argument("--jobs", type=_jobs, help="local worker processes (joblib); -1 = all cores (default: the "
                     "study's jobs, else 1)")
    abl.add_argument("--max-cells", type=_number(1, 1e15, integer=True), metavar="N",
                     help="allow a grid of up to N runs (default: the study's max_cells, else 10000)")
    abl.add_argument("--scheduler", type=_scheduler,
                     help="address of an existing Dask scheduler, e.g. tcp://10.0.0.5:8786")
    abl.add_argument("--out", type=_output,
                     help="output folder (default: ablation_<study>); its cache/ makes reruns resume")
    abl.add_argument("--show", type=_metric_names, help="comma-separated metrics to print (default: all)")
    abl.add_argument("--prune-cache", action="store_true",
                     help="remove every cache entry this study did not use (other studies' runs in the same --out)")
    abl.add_argument("--cache-max-age", type=_number(0, 1e6, "days"), default=30.0, metavar="DAYS",
                     help="remove cache entries no study used for DAYS days (default 30)")
    abl.add_argument("--cache-max-size", type=_number(0, 1e12, "MB"), metavar="MB",
                     help="then remove the least recently used entries until the cache is at most MB megabytes")
    abl.set_defaults(func=cmd_ablate)

    tun = sub.add_parser("tune", help="choose a setting by leave-one-group-out cross-validation (a study file "
                         "with a tune: block) and write it as a config")
    tun.add_argument("study", type=_input_yaml,
                     help="tune YAML: a study file with a tune: block (objective, search, group_by)")
    tun.add_argument("--jobs", type=_jobs, help="local worker processes (joblib); -1 = all cores")
    tun.add_argument("--scheduler", type=_scheduler,
                     help="address of an existing Dask scheduler, e.g. tcp://10.0.0.5:8786")
    tun.add_argument("--out", type=_output, help="output folder (default: tune_<file>): cache/, tune_folds.csv, "
                     "tune_scores.csv, best.yaml")
    tun.add_argument("--config", type=_output, help="write the chosen config here (default: the tune block's "
                     "config, else OUT/best.yaml)")
    tun.set_defaults(func=cmd_tune)

    lst = sub.add_parser("list", help="list plug-ins with their parameters (default, unit, accepted range, meaning, "
                         "source) and papers, and the config's settings blocks")
    lst.add_argument("name", nargs="?", help="only the plug-in of this name (e.g. shoe)")
    lst.add_argument("--kind", choices=[*_kinds(), "settings"],
                     help="only this kind of plug-in, or the settings blocks (gravity, init, navigation, guards)")
    lst.add_argument("--compatibility", action="store_true",
                     help="print which orientation x correction combinations validate, and why not")
    lst.add_argument("--plugins", nargs="+", metavar="FILE", default=[],
                     help="your own plug-ins too: .py files or module names, as a config's plugins: lists them")
    lst.set_defaults(func=lambda a: cmd_list_compat(a) if a.compatibility else cmd_list(a))

    fmt = sub.add_parser("formats", help="list the readers (file formats) with their options, installed ones too")
    fmt.set_defaults(func=cmd_formats)

    cfg = sub.add_parser("configs", help="list the shipped configs, or copy one next to your data to edit it")
    cfg.add_argument("--copy", metavar="NAME", type=_input_yaml, help="the shipped config to copy (e.g. recommended)")
    cfg.add_argument("--to", default=None, metavar="DEST", type=_destination,
                     help="folder or file name of the copy (default: here)")
    cfg.add_argument("--force", action="store_true", help="overwrite an existing file")
    cfg.set_defaults(func=cmd_configs)

    val = sub.add_parser("validate", help="check a pipeline config (or a study or tune file: every config of its "
                                          "grid) without running it")
    val.add_argument("config", type=_input_yaml, help="pipeline YAML, or a study or tune file")
    val.add_argument("--resolved", action="store_true", help="also print the config with every default filled in "
                     "(YAML, as footzoo run runs it)")
    val.set_defaults(func=cmd_validate)
    return parser


def _kinds() -> list[str]:
    """The plug-in kinds (``calibration``, ``orientation``, ``detector``, ``correction``, ``analysis``)."""

    return list(BASES)


def _subparser(common: argparse.ArgumentParser) -> type[argparse.ArgumentParser]:
    """Sub-command parsers that also take ``--debug`` and list the exit codes in their help."""

    class SubParser(argparse.ArgumentParser):
        def __init__(self, **kwargs: Any):
            kwargs.setdefault("parents", [common])
            kwargs.setdefault("epilog", EXIT_CODES_HELP)
            kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
            super().__init__(**kwargs)

    return SubParser


#: Extensions of YAML files (configs, studies) and of recordings, to recognise arguments given in the wrong place.
YAML_SUFFIXES = (".yaml", ".yml")


def _swap_hint(args: argparse.Namespace, extras: list[str]) -> str:
    """The fix for arguments in the wrong place (``footzoo run walk.csv config.yaml``), or ``""``."""
    # deferred: yaml, read only for a usage error
    from ..core.yamlsafe import RECORDING_SUFFIXES

    given = getattr(args, "config", None) or getattr(args, "study", None)
    yaml_extra = next((e for e in extras if Path(e).suffix.lower() in YAML_SUFFIXES), None)
    if yaml_extra is None and args.command == "run" and given and Path(given).suffix.lower() in RECORDING_SUFFIXES:
        yaml_extra = next((e for e in extras if not e.startswith("-") and not Path(e).suffix), None)  # a shipped name
    if args.command == "run" and yaml_extra and given and Path(given).suffix.lower() in RECORDING_SUFFIXES:
        return (f"; the config comes first and the recording after --data (swapped?): footzoo run {yaml_extra} "
                f"--data {given}")
    data = next((e for e in extras if Path(e).suffix.lower() in RECORDING_SUFFIXES), None)
    if args.command == "run" and data:
        return f"; a recording goes after --data: footzoo run {given or 'CONFIG'} --data {data}"
    return ""


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    print(f"footzoo: warning: {message}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``footzoo`` console script; returns the exit code (see the module docstring)."""
    _printable_output()
    parser = build_parser()
    try:
        args, extras = parser.parse_known_args(argv)
        if extras:
            parser.error(f"unrecognized arguments: {' '.join(extras)}{_swap_hint(args, extras)}")
    except SystemExit as stop:  # --help (0) or a usage error (2, message already printed)
        return int(stop.code) if isinstance(stop.code, int) else EXIT_USAGE
    debug = bool(getattr(args, "debug", False))
    if not debug:
        warnings.showwarning = _show_warning
    with used_from("command line"):  # a message names the command line's fix (an option, not a keyword)
        return _run_command(args, debug)


def _printable_output() -> None:
    """Let stdout and stderr write any text: a name or path the terminal's encoding (``LC_ALL=C``, an ASCII
    ``PYTHONIOENCODING``) cannot show is printed with backslash escapes instead of failing the command."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, ValueError, OSError):  # not a text file (e.g. replaced, closed)
            stream.reconfigure(errors="backslashreplace")


def _run_command(args: argparse.Namespace, debug: bool) -> int:
    """Run the parsed command; its exit code (an error is printed, with a traceback only with ``--debug``)."""
    try:
        if not getattr(args, "quiet", False):
            return args.func(args)
        with kept_warnings(args) as caught:  # commands with a result or a log keep their own
            code = args.func(args)
        tell_unshown(args, warning_texts(caught))
        return code
    except KeyboardInterrupt:
        print("footzoo: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # output piped into e.g. `head`, which stopped reading: not an error
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_OK
    except Exception as err:  # the command line's last line of defence: no traceback unless --debug
        if debug:
            traceback.print_exc()
        code, text = _classify(err)
        print(f"footzoo: {text}", file=sys.stderr)
        return code


def _classify(err: Exception) -> tuple[int, str]:
    """Exit code and message for an exception leaving a command."""
    if isinstance(err, PluginError):
        return EXIT_PLUGIN, f"plug-in error: {err}"
    if isinstance(err, ReaderOptionError):  # an argument's problem, though a reader raised it
        return EXIT_USAGE, f"error: {err}"
    if isinstance(err, (RecordingError, FormatError, OutputError)):
        return EXIT_DATA, f"error: {err}"
    if isinstance(err, (ConfigError, FootzooError)):
        return EXIT_USAGE, f"error: {err}"
    if isinstance(err, PermissionError):
        return EXIT_DATA, (f"error: permission denied: {err.filename!r}; check the file's permissions or choose "
                           "another location")
    if isinstance(err, OSError):
        where = f" {err.filename!r}" if err.filename else ""
        return EXIT_DATA, f"error: cannot access{where}: {err.strerror or err}"
    if isinstance(err, MemoryError):
        return EXIT_DATA, "error: out of memory; use a smaller recording or study"
    return EXIT_INTERNAL, (f"internal error: {type(err).__name__}: {err}. This is a bug in footzoo: rerun with "
                           "--debug and report the traceback")


if __name__ == "__main__":
    sys.exit(main())
