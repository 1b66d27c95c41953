"""Declared parameters: one declaration per parameter drives validation, listings, docs and the fuzz tests.

A plug-in (or a settings block of a config) declares each of its parameters once, in a
``parameters`` mapping next to its ``__init__``; the default stays in the signature, where Python,
``inspect`` and an editor see it::

    parameters = {
        "threshold": Real("rad/s", "(0, 10]", "Ω_th: stance while |ω| stays below it",
                          source="footzoo's design notes (the paper gives none)"),
        "min_duration": Real("s", "[0, 1]", "Γ_th: how long |ω| must stay across Ω_th for a switch",
                             source="footzoo's: 5 samples at the paper's 50 Hz"),
    }

    def __init__(self, threshold: float = 0.6, min_duration: float = 0.1):
        self.threshold = threshold
        self.min_duration = min_duration

The kinds of parameter (scikit-learn's ``_parameter_constraints`` is the model):

=====================  =====================================================================
:class:`Real`          a finite number in a unit and an interval (open or closed ends)
:class:`Integer`       a whole number in an interval
:class:`Boolean`       ``true`` or ``false`` (strict: ``'no'``, ``0`` or ``'false'`` are refused)
:class:`Choice`        one of a few names (a misspelling gets a did-you-mean)
:class:`Vector`        a list of ``n`` finite numbers (optionally each in an interval, not all zero)
:class:`Vectors`       a list of such vectors (e.g. one per sensor)
:class:`File`          a file path (text), optionally with given suffixes
=====================  =====================================================================

Each takes ``optional=True`` (``None``, YAML ``null``, is then accepted), ``source`` (where the
default comes from: the paper's table or equation, or why footzoo chose it) and ``why`` (why the
range is what it is, where that is not obvious). :meth:`Param.validate` returns the value in its
declared type (an int given for a float becomes that float, a tuple a list: equal to what was given)
or raises :class:`~footzoo.core.errors.ConfigError` naming the parameter as written, the unit, the
accepted range and the fix.

The accepted range of a physical quantity is the *plausible* one, and values beyond it are refused,
not warned about: a value beyond physical plausibility is almost always one given in another unit
(35 for a threshold of 35 °/s declared in rad/s, 500 for 500 ms declared in s, 1 for 1 g declared in
m/s²), and it would give a silently wrong result; a warning is easily lost among hundreds of study
runs, a refusal costs one edit. When a refused value would be plausible in a unit it is often given
in by mistake (:data:`UNIT_SLIPS`), the message says so: ``35 rad/s is 2005 °/s: threshold is in
rad/s (the default 0.6 rad/s is 34.4 °/s); for 35 °/s write 0.611``.

:func:`declared` binds the declarations of a class to the names and defaults of its signature
(searching the class and its bases, so a subclass redeclares only what it changes); the
``invalid_values`` and ``edge_values`` of each parameter feed the fuzz tests, so a new plug-in is
covered without writing tests for it.
"""

from __future__ import annotations

import copy
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import ConfigError, did_you_mean


class _Required:
    """The default of a parameter that has none (a required argument)."""

    def __repr__(self) -> str:
        return "REQUIRED"


#: Marks a parameter without a default (a required argument).
REQUIRED = _Required()

#: Units a value is often given in by mistake, per declared unit: ``(unit, size of one of it in the declared unit)``.
UNIT_SLIPS: dict[str, tuple[tuple[str, float], ...]] = {
    "rad/s": (("°/s", math.pi / 180.0),),
    "rad": (("°", math.pi / 180.0),),
    "m/s^2": (("g", 9.81),),
    "s": (("ms", 1e-3),),
}


def shown(value: Any) -> str:
    """A value as the user wrote it, for messages (numpy scalars as plain numbers)."""
    if isinstance(value, np.generic):
        value = value.item()
    text = repr(value)
    return text if len(text) <= 80 else f"{text[:60]}... ({len(text)} characters)"


def _g(x: float) -> str:
    """A number for a hint: three significant digits, whole numbers from 100 on (``2005``, not ``2.01e+03``)."""
    return f"{x:.0f}" if 100 <= abs(x) < 1e15 else f"{x:.3g}"


# --------------------------------------------------------------------------- intervals


def _bound(text: str) -> float:
    """One end of an interval: a number, ``inf``, ``pi``, or a fraction of them (``pi/2``, ``1/3``)."""
    t = text.strip().replace("π", "pi").replace("∞", "inf")
    sign = -1.0 if t.startswith("-") else 1.0
    t = t.lstrip("+-")
    num, _, den = t.partition("/")
    value = math.pi if num == "pi" else math.inf if num == "inf" else float(num)
    if den:
        value /= float(den)
    return sign * value


@dataclass(frozen=True)
class Interval:
    """An interval of the real line, ends open or closed: ``Interval.parse("(0, 10]")``."""

    lo: float
    hi: float
    lo_open: bool = False
    hi_open: bool = False
    text: str = ""

    @classmethod
    def parse(cls, text: str) -> Interval:
        """``"[a, b]"``, ``"(a, b]"``, ``"[0, inf)"``, ``"(0, pi]"`` ..."""
        t = text.strip()
        if len(t) < 5 or t[0] not in "[(" or t[-1] not in "])" or "," not in t:
            raise TypeError(f"an interval is written like '(0, 10]' or '[0, inf)', got {text!r}")
        try:
            lo_text, hi_text = t[1:-1].split(",")
            lo, hi = _bound(lo_text), _bound(hi_text)
        except ValueError:
            raise TypeError(f"an interval is written like '(0, 10]' or '[0, inf)', got {text!r}") from None
        if not lo <= hi:
            raise TypeError(f"interval {text!r}: the lower end must not exceed the upper one")
        shown_text = f"{t[0]}{lo_text.strip()}, {hi_text.strip()}{t[-1]}".replace("pi", "π")
        return cls(lo, hi, t[0] == "(" or math.isinf(lo), t[-1] == ")" or math.isinf(hi), shown_text)

    def __contains__(self, v: float) -> bool:
        return (v > self.lo if self.lo_open else v >= self.lo) and (v < self.hi if self.hi_open else v <= self.hi)

    def __str__(self) -> str:
        """``(0, 10]``; empty for the whole real line (no bound)."""
        if self.unbounded:
            return ""
        return self.text or f"{'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}{')' if self.hi_open else ']'}"

    @property
    def unbounded(self) -> bool:
        """Whether this is the whole real line."""
        return math.isinf(self.lo) and math.isinf(self.hi)

    def requirement(self, unit: str) -> str:
        """``lie in (0, 10] rad/s``, or ``be > 0 s`` for a half-infinite interval."""
        u = f" {unit}" if unit else ""
        if math.isinf(self.hi) and not math.isinf(self.lo):
            return f"be {'>' if self.lo_open else '>='} {_bound_text(self, 0)}{u}"
        if math.isinf(self.lo) and not math.isinf(self.hi):
            return f"be {'<' if self.hi_open else '<='} {_bound_text(self, 1)}{u}"
        return f"lie in {self}{u}"

    def inside(self) -> list[float]:
        """The accepted values at the ends (the ends themselves, or the nearest floats inside)."""
        out = []
        if math.isfinite(self.lo):
            out.append(float(np.nextafter(self.lo, math.inf)) if self.lo_open else self.lo)
        if math.isfinite(self.hi):
            out.append(float(np.nextafter(self.hi, -math.inf)) if self.hi_open else self.hi)
        return [v for v in out if v in self]

    def outside(self) -> list[float]:
        """Refused values just beyond each finite end, and far beyond."""
        out = []
        if math.isfinite(self.lo):
            out += [self.lo if self.lo_open else float(np.nextafter(self.lo, -math.inf)), -1e300]
        if math.isfinite(self.hi):
            out += [self.hi if self.hi_open else float(np.nextafter(self.hi, math.inf)), 1e300]
        return [v for v in out if v not in self]


def _bound_text(interval: Interval, which: int) -> str:
    inner = interval.text[1:-1].split(",") if interval.text else []
    if len(inner) == 2:
        return inner[which].strip()
    return f"{(interval.lo, interval.hi)[which]:g}"


def interval(value: str | Interval | None) -> Interval:
    """An :class:`Interval` from its text (None: the whole real line)."""
    if value is None:
        return Interval(-math.inf, math.inf, True, True, "")
    return value if isinstance(value, Interval) else Interval.parse(value)


# --------------------------------------------------------------------------- parameters


class Param:
    """Base of the declared kinds of parameter (see the module docstring).

    Parameters
    ----------
    doc : str
        One line: what the parameter is, with its paper's symbol (``"Ω_th: ..."``).
    unit : str
        Its unit (``"1"`` for a dimensionless number; empty for flags, names and paths).
    source : str
        Where the default comes from: the paper's table, figure or equation, or footzoo's reason.
    optional : bool
        ``None`` (YAML ``null``) is accepted.
    why : str
        Why the accepted range is what it is, where that is not obvious (shown with a refusal).
    """

    type_name = "value"

    def __init__(self, doc: str = "", *, unit: str = "", source: str = "", optional: bool = False, why: str = ""):
        self.doc = doc
        self.unit = unit
        self.source = source
        self.optional = optional
        self.why = why

    # --------------------------------------------------------------- validation
    def validate(self, name: str, value: Any, default: Any = REQUIRED) -> Any:
        """The value in its declared type, or a :class:`ConfigError` naming ``name``, the problem and the fix."""
        if value is None:
            if self.optional:
                return None
            raise ConfigError(f"{name} must be {self.expected()}, got None (null){self._example(default)}")
        return self.check(name, value, default)

    def check(self, name: str, value: Any, default: Any) -> Any:
        """Validate a value that is not None (the kinds implement it)."""
        raise NotImplementedError

    def expected(self) -> str:
        """What a valid value is, in words (``"a number in rad/s"``)."""
        return f"a {self.type_name}"

    def _example(self, default: Any) -> str:
        if default is REQUIRED or default is None:
            return ""
        return f"; e.g. the default {_plain_text(default)}{self._u}"

    @property
    def _u(self) -> str:
        return f" {self.unit}" if self.unit and self.unit != "1" else ""

    # --------------------------------------------------------------- description
    @property
    def type_text(self) -> str:
        """The type for listings and docs (``float``, ``bool``, ``3 floats``, ... ``or null``)."""
        return self.type_name + (" or null" if self.optional else "")

    @property
    def range_text(self) -> str:
        """The accepted values beyond the type, for listings and docs (``(0, 10]``); empty when any."""
        return ""

    # --------------------------------------------------------------- fuzzing
    def invalid_values(self) -> list[Any]:
        """Values this declaration refuses (wrong types, non-finite numbers, values just out of range)."""
        out: list[Any] = [{"a": 1}, _Opaque()]
        if not self.optional:
            out.append(None)
        return out

    def edge_values(self, default: Any = REQUIRED) -> list[Any]:
        """Values this declaration accepts at the edges of what it allows (with the default)."""
        return [] if default is REQUIRED else [default]

    def replace(self, **changes: Any) -> Param:
        """A copy with some attributes changed (a subclass that only changes the source or the range)."""
        out = copy.copy(self)
        if "range" in changes:
            out.interval = interval(changes.pop("range"))  # type: ignore[attr-defined]
        for key, value in changes.items():
            if not hasattr(out, key):
                raise TypeError(f"{type(self).__name__} has no attribute {key!r}")
            setattr(out, key, value)
        return out

    def __repr__(self) -> str:
        extra = f", {self.range_text}" if self.range_text else ""
        return f"{type(self).__name__}({self.type_text}{extra}{self._u}: {self.doc!r})"


class _Opaque:
    """An object of no YAML type (for the invalid values)."""

    def __repr__(self) -> str:
        return "<object>"


def _plain_text(value: Any) -> str:
    """A value as YAML writes it (``true``, ``null``, ``[1, 0, 0]``, ``'auto'``), numbers to 6 digits."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bool) or value is None:
        return {True: "true", False: "false", None: "null"}[value]
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_plain_text(v) for v in value) + "]"
    return repr(value) if isinstance(value, str) else str(value)


def _number(name: str, value: Any, example: str) -> float:
    """A finite float from a number (not a bool, not text), or a ConfigError."""
    if isinstance(value, (bool, np.bool_)) or isinstance(value, (str, bytes)) or not isinstance(
            value, (int, float, np.integer, np.floating)):
        hint = ""
        if isinstance(value, str):
            try:
                as_number = float(value)
            except ValueError:
                as_number = None
            if as_number is not None and not math.isfinite(as_number):  # 'nan', 'inf': text, and not finite either
                raise ConfigError(f"{name} must be a finite number, got {shown(value)}{example}")
            hint = " (write the number without quotes)" if as_number is not None else ""
        raise ConfigError(f"{name} must be a number, got {type(value).__name__} {shown(value)}{hint}{example}")
    try:
        v = float(value)
    except OverflowError:
        v = math.inf
    if not math.isfinite(v):
        raise ConfigError(f"{name} must be a finite number, got {shown(value)}{example}")
    return v


class Real(Param):
    """A finite number in ``unit`` within ``range`` (``"(0, 10]"``; None: any finite number).

    Example: ``Real("rad/s", "(0, 10]", "Ω_th: stance while |ω| stays below it", source="Yun 2012")``.
    """

    type_name = "float"

    def __init__(self, unit: str, range: str | Interval | None = None, doc: str = "", **kwargs: Any):
        super().__init__(doc, unit=unit, **kwargs)
        self.interval = interval(range)

    def expected(self) -> str:
        return f"a number{f' in {self.unit}' if self._u else ''}"

    @property
    def range_text(self) -> str:
        return str(self.interval)

    def check(self, name: str, value: Any, default: Any) -> Any:
        v = _number(name, value, self._example(default))
        if v not in self.interval:
            why = f" ({self.why})" if self.why else ""
            raise ConfigError(f"{name} = {shown(value)}{self._u} is out of range: it must "
                              f"{self.interval.requirement(self._u.strip())}{why}"
                              f"{self.slip(name, v, default) or self._example(default)}")
        return v

    def slip(self, name: str, v: float, default: Any) -> str:
        """The unit hint for a refused value that is plausible in a unit often given by mistake, or ``""``."""
        for other, size in UNIT_SLIPS.get(self.unit, ()):
            if v * size in self.interval and v * size != 0.0:
                known = ""
                if isinstance(default, (int, float)) and not isinstance(default, bool) and default:
                    known = f" (the default {_g(default)} {self.unit} is {_g(default / size)} {other})"
                short = name.rsplit(".", 1)[-1].split(" ")[-1]
                samples = ""
                if self.unit == "s" and float(v).is_integer() and 1 <= v <= 1000:  # a paper's sample count?
                    samples = f" (a count of samples? durations are in s: {v:g} samples at 100 Hz are {_g(v / 100)} s)"
                return (f". {_g(v)} {self.unit} is {_g(v / size)} {other}: {short} is in {self.unit}{known}; "
                        f"for {_g(v)} {other} write {_g(v * size)}{samples}")
        return ""

    def invalid_values(self) -> list[Any]:
        return [*super().invalid_values(), math.nan, math.inf, -math.inf, "0.5", "abc", True, [1.0],
                *self.interval.outside()]

    def edge_values(self, default: Any = REQUIRED) -> list[Any]:
        return [*super().edge_values(default), *self.interval.inside()]


class Integer(Real):
    """A whole number within ``range`` (a float with an integral value, such as YAML's ``5.0``, is accepted)."""

    type_name = "int"

    def expected(self) -> str:
        return "a whole number"

    def check(self, name: str, value: Any, default: Any) -> Any:
        v = super().check(name, value, default)
        if not float(v).is_integer():
            raise ConfigError(f"{name} must be a whole number, got {shown(value)}{self._example(default)}")
        return int(v)

    def invalid_values(self) -> list[Any]:
        return [*super().invalid_values(), 0.5 + (self.interval.lo if math.isfinite(self.interval.lo) else 0.0)]

    def edge_values(self, default: Any = REQUIRED) -> list[Any]:
        inside = [math.ceil(v) if v == self.interval.lo else math.floor(v) for v in self.interval.inside()]
        return [*Param.edge_values(self, default), *[v for v in inside if v in self.interval]]


class Boolean(Param):
    """``true`` or ``false``; text such as ``'no'`` (truthy in Python), ``0`` or ``1`` is refused."""

    type_name = "bool"

    def expected(self) -> str:
        return "true or false"

    def check(self, name: str, value: Any, default: Any) -> Any:
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        raise ConfigError(f"{name} must be true or false, got {type(value).__name__} {shown(value)}; "
                          "write true or false without quotes")

    def invalid_values(self) -> list[Any]:
        return [*super().invalid_values(), "no", "false", "true", 0, 1, 0.0]

    def edge_values(self, default: Any = REQUIRED) -> list[Any]:
        return [True, False]


class Choice(Param):
    """One of ``options`` (names); a misspelt one is refused with a did-you-mean."""

    type_name = "choice"

    def __init__(self, options: Sequence[str], doc: str = "", **kwargs: Any):
        super().__init__(doc, **kwargs)
        if isinstance(options, str) or not options or not all(isinstance(o, str) for o in options):
            raise TypeError(f"Choice takes a list of names, got {options!r}")
        self.options = tuple(options)

    def expected(self) -> str:
        return f"one of {list(self.options)}"

    @property
    def type_text(self) -> str:
        return "one of " + ", ".join(repr(o) for o in self.options) + (" or null" if self.optional else "")

    def check(self, name: str, value: Any, default: Any) -> Any:
        if isinstance(value, str) and value in self.options:
            return value
        close = did_you_mean(value, list(self.options)) if isinstance(value, str) else ""
        raise ConfigError(f"{name} must be one of {list(self.options)}, got {shown(value)}{close}")

    def invalid_values(self) -> list[Any]:
        return [*super().invalid_values(), self.options[0] + "_x", self.options[0].upper() + "?", 1, True]

    def edge_values(self, default: Any = REQUIRED) -> list[Any]:
        return list(self.options)


def _is_sequence(value: Any) -> bool:
    return isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray) and value.ndim == 1)


class Vector(Real):
    """A list of ``size`` finite numbers, each within ``range`` (None: any); ``nonzero``: not all zero."""

    type_name = "vector"

    def __init__(self, size: int, unit: str, doc: str = "", *, range: str | Interval | None = None,
                 nonzero: bool = False, **kwargs: Any):
        super().__init__(unit, range, doc, **kwargs)
        self.size = int(size)
        self.nonzero = nonzero

    @property
    def type_text(self) -> str:
        return f"{self.size} floats" + (" or null" if self.optional else "")

    @property
    def range_text(self) -> str:
        parts = [f"each in {self.interval}"] if str(self.interval) else []
        if self.nonzero:
            parts.append("not all zero")
        return ", ".join(parts)

    def expected(self) -> str:
        example = ", ".join(["0"] * (self.size - 1) + ["1"])
        return f"a list of {self.size} numbers like [{example}]"

    def check(self, name: str, value: Any, default: Any) -> Any:
        if not _is_sequence(value) or len(value) != self.size:
            size = f" (it has {len(value)})" if _is_sequence(value) else ""
            raise ConfigError(f"{name} must be {self.expected()}{f' ({self.unit})' if self._u else ''}, "
                              f"got {shown(value) if not isinstance(value, np.ndarray) else value.tolist()}{size}")
        out = [Real.check(self, f"{name}[{i}]", v, REQUIRED) for i, v in enumerate(value)]
        if self.nonzero and not any(out):
            raise ConfigError(f"{name} must not be all zeros, got {shown(value)}: its direction is undefined")
        return out

    def slip(self, name: str, v: float, default: Any) -> str:
        return ""

    def invalid_values(self) -> list[Any]:
        good = [1.0] * self.size
        out: list[Any] = [*Param.invalid_values(self), "1, 0, 0", 1.0, [1.0] * (self.size + 1), good[:-1],
                          [math.nan, *good[1:]], [math.inf, *good[1:]], ["1", *good[1:]], [True, *good[1:]]]
        out += [[v, *good[1:]] for v in self.interval.outside()]
        if self.nonzero:
            out.append([0.0] * self.size)
        return out

    def edge_values(self, default: Any = REQUIRED) -> list[Any]:
        return Param.edge_values(self, default)


class Vectors(Vector):
    """A list of at least ``min_count`` vectors of ``size`` numbers each (e.g. one per sensor)."""

    type_name = "vectors"

    def __init__(self, size: int, unit: str, doc: str = "", *, min_count: int = 1, **kwargs: Any):
        super().__init__(size, unit, doc, **kwargs)
        self.min_count = int(min_count)

    @property
    def type_text(self) -> str:
        return f"list of {self.size}-vectors" + (" or null" if self.optional else "")

    @property
    def range_text(self) -> str:
        parts = [f"each in {self.interval}"] if str(self.interval) else []
        if self.nonzero:
            parts.append("none all zero")
        return ", ".join(parts)

    def check(self, name: str, value: Any, default: Any) -> Any:
        rows = value.tolist() if isinstance(value, np.ndarray) and value.ndim == 2 else value
        example = "[" + ", ".join(["0"] * self.size) + "]"
        if not isinstance(rows, (list, tuple)) or len(rows) < self.min_count:
            raise ConfigError(f"{name} must be a list of at least {self.min_count} {example}-like vectors"
                              f"{f' ({self.unit})' if self._u else ''}, got {shown(value)}")
        out = []
        for i, row in enumerate(rows):
            if not _is_sequence(row) or len(row) != self.size:
                raise ConfigError(f"{name} must be a list of {example}-like vectors ({self.size} numbers each); "
                                  f"{name}[{i}] is {shown(row)}")
            vec = [Real.check(self, f"{name}[{i}][{j}]", v, REQUIRED) for j, v in enumerate(row)]
            if self.nonzero and not any(vec):
                raise ConfigError(f"{name} must not contain {[0] * self.size}: a direction needs a non-zero "
                                  f"vector, got {shown(value)}")
            out.append(vec)
        return out

    def invalid_values(self) -> list[Any]:
        good = [1.0] * self.size
        out: list[Any] = [*Param.invalid_values(self), "1, 0, 0", 1.0, good, [good[:-1]], [[math.nan, *good[1:]]],
                          [["1", *good[1:]]]]
        if self.min_count > 0:
            out.append([])
        if self.nonzero:
            out.append([[0.0] * self.size])
        return out


class File(Param):
    """A file path (text); ``suffixes``: the accepted file endings (``(".yaml", ".yml")``)."""

    type_name = "file path"

    def __init__(self, doc: str = "", *, suffixes: Sequence[str] = (), **kwargs: Any):
        super().__init__(doc, **kwargs)
        self.suffixes = tuple(suffixes)

    @property
    def range_text(self) -> str:
        return " or ".join(f"*{s}" for s in self.suffixes)

    def expected(self) -> str:
        ends = f" ending in {' or '.join(self.suffixes)}" if self.suffixes else ""
        return f"a file path (text){ends}"

    def check(self, name: str, value: Any, default: Any) -> Any:
        if isinstance(value, os.PathLike):
            value = os.fspath(value)
        if not isinstance(value, str) or not value.strip():
            raise ConfigError(f"{name} must be {self.expected()}, got {type(value).__name__} {shown(value)}")
        if self.suffixes and not value.lower().endswith(tuple(s.lower() for s in self.suffixes)):
            raise ConfigError(f"{name} must be {self.expected()}, got {value!r}")
        return value

    def invalid_values(self) -> list[Any]:
        out = [*super().invalid_values(), 3, "", True, ["a.yaml"]]
        if self.suffixes:
            out.append("file.unknown_suffix")
        return out


# --------------------------------------------------------------------------- declarations of a class


@dataclass(frozen=True)
class Declared:
    """A parameter of a class: its name, declaration and default (:data:`REQUIRED` when it has none)."""

    name: str
    param: Param
    default: Any = REQUIRED

    def validate(self, value: Any, where: str | None = None) -> Any:
        """``param.validate`` under the name ``where`` (default: the parameter's own name)."""
        return self.param.validate(where or self.name, value, self.default)

    @property
    def default_text(self) -> str:
        """The default as YAML would write it (``required`` when there is none)."""
        return "required" if self.default is REQUIRED else ("null" if self.default is None
                                                           else _plain_text(self.default))


def lookup(cls: type, name: str) -> Param | None:
    """The declaration of ``name`` in the ``parameters`` of ``cls`` or its nearest base that declares it."""
    for klass in cls.__mro__:
        params = klass.__dict__.get("parameters")
        if isinstance(params, Mapping) and name in params:
            return params[name]
    return None


def declared(cls: type, defaults: Mapping[str, Any]) -> dict[str, Declared]:
    """``{name: Declared}`` for each of ``defaults``' names (the signature's, in order) that has a declaration.

    Raises
    ------
    TypeError
        A declaration that is not a :class:`Param`, one naming no parameter of the class (with a
        did-you-mean), or a default its own declaration refuses: mistakes of the plug-in's author,
        reported when the class is defined.
    """
    own = cls.__dict__.get("parameters")
    if own is not None:
        if not isinstance(own, Mapping):
            raise TypeError(f"{cls.__name__}.parameters must be a dict of name: Real(...)/Boolean(...)/..., "
                            f"got {type(own).__name__}")
        for key, p in own.items():
            if key not in defaults:
                raise TypeError(f"{cls.__name__}.parameters declares {key!r}, which is not a parameter of its "
                                f"__init__{did_you_mean(str(key), list(defaults))}; parameters: {list(defaults)}")
            if not isinstance(p, Param):
                raise TypeError(f"{cls.__name__}.parameters[{key!r}] must be a footzoo.core.params.Param "
                                f"(Real, Integer, Boolean, Choice, Vector, Vectors, File), got {p!r}")
    out = {}
    for name, default in defaults.items():
        p = lookup(cls, name)
        if p is None:
            continue
        if default is not REQUIRED:
            try:
                p.validate(name, default, default)
            except ConfigError as err:
                raise TypeError(f"{cls.__name__}: the default of {name!r} is refused by its own declaration: "
                                f"{err}") from None
        out[name] = Declared(name, p, default)
    return out


def describe(declaration: Mapping[str, Declared], indent: str = "      ") -> list[str]:
    """Two lines per parameter, for ``footzoo list``: ``name = default [unit]  range  meaning`` and the source."""
    lines = []
    for name, d in declaration.items():
        p = d.param
        unit = f" [{p.unit}]" if p.unit else ""
        accepted = p.range_text if type(p) is Real else ", ".join(t for t in (p.type_text, p.range_text) if t)
        if type(p) is Real and p.optional:
            accepted += " or null"
        lines.append("  ".join(t for t in (f"{indent}{name} = {d.default_text}{unit}", accepted, p.doc) if t))
        if p.source:
            lines.append(f"{indent}    default: {p.source}")
    return lines
