"""The readers footzoo knows: the entry-point group ``footzoo.readers``, and which reader takes a file.

Every reader, built-in or third-party, is an entry point of the group ``footzoo.readers``:
its name is the format's name and its value the reader class (or object), e.g. in a package's
``pyproject.toml``::

    [project.entry-points."footzoo.readers"]
    mylogger = "mylogger_reader:MyLoggerReader"

footzoo's own formats are registered the same way in its ``setup.cfg``; :data:`BUILTIN` holds
the same table, so that a source checkout that was never installed reads them too.

**Which reader opens a file** (:func:`detect`): an explicit ``format=`` always wins. Otherwise
every reader's ``guess_can_open(path)`` is asked, in a stable order: the built-in formats in
the order of :data:`BUILTIN`, then the third-party ones by name. Exactly one that accepts the
file reads it; none, or more than one, is a :class:`~footzoo.core.errors.FormatError` that lists
the formats (with what each expects) and says how to pass ``format=``.

A third-party reader that cannot be imported, that reuses a built-in name, or whose
``guess_can_open`` raises is skipped with a :class:`~footzoo.core.errors.FootzooWarning` (asking for
it by name gives the reason); footzoo's own formats keep working.
"""

from __future__ import annotations

import importlib
import re
import warnings
from collections.abc import Iterator, Mapping
from functools import lru_cache
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

from ..core.errors import FootzooWarning, FormatError, did_you_mean, user_stacklevel
from ..core.files import SNIFF_BYTES, foreign_encoding
from .base import MAT_ROUTE, first_line, second_line

#: The entry-point group readers register under.
GROUP = "footzoo.readers"

#: footzoo's own readers, in detection order (the same table as ``setup.cfg``'s entry points).
BUILTIN: dict[str, str] = {
    "canonical": "footzoo.io.canonical:CanonicalReader",
    "xio": "footzoo.io.xio:XioReader",
    "pyshoe": "footzoo.io.pyshoe:PyShoeReader",
    "gaitmap": "footzoo.io.gaitmap:GaitmapReader",
    "sensorconnect": "footzoo.io.sensorconnect:SensorConnectReader",
    "openshoe": "footzoo.io.openshoe:OpenShoeReader",
    "xsens": "footzoo.io.xsens:XsensReader",
    "generic": "footzoo.io.generic:GenericReader",
}

_NAME = re.compile(r"^[a-z][a-z0-9_]*$")


def _load_target(target: str) -> Any:
    module, _, attr = target.partition(":")
    obj: Any = importlib.import_module(module)
    for part in attr.split(".") if attr else []:
        obj = getattr(obj, part)
    return obj


def _instance(name: str, obj: Any, origin: str) -> Any:
    """The reader object of an entry point's target (a class is instantiated), checked for the two methods."""
    reader = obj() if isinstance(obj, type) else obj
    missing = [m for m in ("guess_can_open", "open") if not callable(getattr(reader, m, None))]
    if missing:
        raise TypeError(f"{origin}: the reader has no {' or '.join(missing)} method (see footzoo.io.base.Reader)")
    if not getattr(reader, "name", ""):
        try:
            reader.name = name
        except AttributeError:
            pass
    return reader


class Readers(Mapping[str, Any]):
    """The available readers, by format name, in detection order.

    Attributes
    ----------
    broken : dict
        Third-party entry points that could not be used: name -> the reason.
    origins : dict
        Where each reader comes from: ``"footzoo"`` or the distribution that registered it.
    """

    def __init__(self) -> None:
        self._readers: dict[str, Any] = {}
        self.broken: dict[str, str] = {}
        self.origins: dict[str, str] = {}
        for name, target in BUILTIN.items():
            self._readers[name] = _instance(name, _load_target(target), f"footzoo reader {name!r}")
            self.origins[name] = "footzoo"
        third: dict[str, tuple[Any, str]] = {}
        for ep in entry_points(group=GROUP):
            dist = getattr(getattr(ep, "dist", None), "name", None) or "an installed package"
            if ep.name in BUILTIN:
                if ep.value != BUILTIN[ep.name] and dist != "footzoo":
                    self._skip(ep.name, f"{dist} registers a reader named {ep.name!r}, which is a built-in "
                                        f"format's name; rename its entry point (e.g. {dist.lower()}_{ep.name})",
                               record=False)
                continue
            if not _NAME.match(ep.name):
                self._skip(ep.name, f"{dist}: the reader name {ep.name!r} must be lower case letters, digits "
                                    "and underscores, starting with a letter; rename the entry point")
                continue
            if ep.name in third:
                self._skip(ep.name, f"two packages register the reader {ep.name!r} ({third[ep.name][1]} and "
                                    f"{dist}); uninstall one")
                continue
            try:
                third[ep.name] = (_instance(ep.name, ep.load(), f"reader {ep.name!r} ({dist})"), dist)
            except Exception as err:  # a broken third-party package must not break footzoo's own readers
                self._skip(ep.name, f"the reader {ep.name!r} of {dist} ({ep.value}) cannot be loaded: "
                                    f"{type(err).__name__}: {err}")
        for name in sorted(third):
            self._readers[name], self.origins[name] = third[name]

    def _skip(self, name: str, reason: str, record: bool = True) -> None:
        if record:
            self.broken[name] = reason
        warnings.warn(FootzooWarning(f"reader skipped: {reason}"), stacklevel=user_stacklevel())

    def __getitem__(self, name: str) -> Any:
        return self._readers[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._readers)

    def __len__(self) -> int:
        return len(self._readers)

    def __repr__(self) -> str:
        return f"Readers({list(self._readers)})"

    def get_reader(self, name: str) -> Any:
        """The reader of format ``name``, or a :class:`FormatError` listing the valid names."""
        if not isinstance(name, str) or name not in self._readers:
            if isinstance(name, str) and name in self.broken:
                raise FormatError(f"format {name!r} is not available: {self.broken[name]}")
            raise FormatError(f"unknown format {name!r}{did_you_mean(str(name), list(self._readers))}; "
                              f"valid: {sorted(self._readers)}")
        return self._readers[name]

    def listing(self) -> str:
        """One line per format: name, extensions and description."""
        return "; ".join(f"{n} ({', '.join(getattr(r, 'extensions', ()) or ()) or 'any file'}): "
                         f"{getattr(r, 'description', '') or type(r).__name__}" for n, r in self._readers.items())

    def detect(self, path: str | Path) -> str:
        """The format of ``path``: the one reader whose ``guess_can_open`` accepts it (see the module doc)."""
        p = Path(path)
        accepted = []
        for name, reader in self._readers.items():
            try:
                ok = reader.guess_can_open(p)
            except Exception as err:  # a reader's bug: skip it, say so
                if self.origins[name] == "footzoo":
                    raise
                warnings.warn(FootzooWarning(
                    f"reader {name!r} ({self.origins[name]}): guess_can_open raised {type(err).__name__}: {err}; "
                    "it was skipped for this file (fix the reader, or pass format=)"), stacklevel=user_stacklevel())
                continue
            if ok is True or (ok and ok is not NotImplemented):
                accepted.append(name)
        if len(accepted) == 1:
            return accepted[0]
        how = f"pass format= one of {sorted(self._readers)} (command line: --format NAME)"
        if accepted:
            raise FormatError(f"{p}: more than one reader recognises this file ({', '.join(accepted)}); say which "
                              f"one to use: format={accepted[0]!r} or format={accepted[1]!r} "
                              "(command line: --format NAME)")

        if p.suffix.lower() in (".yaml", ".yml"):
            raise FormatError(f"{p}: a YAML file (a config or study?), not a recording; a config is the first "
                              f"argument (footzoo run {p.name} --data RECORDING), a recording goes to --data")
        head = ""
        try:
            if p.suffix.lower() not in (".mat", ".parquet", ".pq", ".npz", ".h5"):
                with open(p, "rb") as fh:
                    problem = foreign_encoding(fh.read(SNIFF_BYTES))
                if problem:
                    raise FormatError(f"{p}: {problem}")
                head = first_line(p).strip()
        except OSError:
            pass
        if p.suffix.lower() in (".csv", ".txt", ".tsv", "") and not head:
            raise FormatError(f"{p}: the file has no header line (it is empty or blank); check the file")
        seen = f" from the header {head[:80]!r}" if head else f" (extension {p.suffix.lower()!r})"
        sep = next((name for ch, name in ((";", "semicolons"), ("\t", "tabs"), ("|", "'|'"), (" ", "spaces"))
                    if head and ch in head and "," not in head), "")
        second = second_line(p) if head and p.suffix.lower() in (".csv", ".txt", ".tsv", "") else ""
        title = next(((ch, name) for ch, name in ((",", "commas"), ("\t", "tabs"), (";", "semicolons"))
                      if second.count(ch) >= 2 and ch not in head), None)
        if title:  # a title line above a delimited header
            seen += (f"; a line without {title[1]} comes before what looks like its header ({second[:60]!r}, "
                     f"separated by {title[1]}): remove that line, or describe the file (skip_rows: 1, or comment: "
                     f"'#') in a sidecar {p.name}.footzoo.yaml")
        elif sep:
            seen += (f"; its values are separated by {sep}, not commas: save it as comma-separated CSV, or "
                     f"describe it (delimiter, decimal) in a sidecar {p.name}.footzoo.yaml")
        if p.suffix.lower() == ".mat":
            seen += f" ({_mat_contents(p)})"
            fix = f"A MATLAB file of another layout: {MAT_ROUTE}; or {how}"
        else:
            fix = (f"Rename the columns, describe them in a sidecar {p.name}.footzoo.yaml (the 'generic' format), "
                   f"or {how}")
        raise FormatError(f"{p}: cannot tell the format: no reader recognises this file{seen}. Formats: "
                          f"{self.listing()}. {fix}")


def _mat_contents(p: Path) -> str:
    """What a ``.mat`` file no reader claims holds: its variables, or that MATLAB's format cannot list them."""
    # deferred: scipy, only for .mat files
    import scipy.io as sio

    try:
        names = [name for name, _, _ in sio.whosmat(p)]
    except Exception as err:  # scipy raises many types for a damaged file
        return f"MATLAB's format cannot list its variables ({type(err).__name__}): a damaged or truncated file?"
    try:
        sio.loadmat(p)
    except Exception as err:
        return (f"its variables {names[:8]} cannot be read ({type(err).__name__}: {str(err)[:80]}): a damaged or "
                "truncated file?")
    return f"variables {names[:12]}; PyShoe's trials have imu and ts"


@lru_cache(maxsize=1)
def available() -> Readers:
    """Every reader footzoo can use now (built-ins and installed entry points), discovered once."""
    return Readers()


def refresh() -> Readers:
    """Discover the readers again (after installing a reader package in the running process)."""
    available.cache_clear()
    return available()
