"""Axis maps: how a sensor's axes become footzoo's FRD body frame (x toward the toe, y right, z down).

Every reader takes one, as the option ``axes`` (command line ``--option 'axes=[x, -y, -z]'``,
Python ``footzoo.load(path, axes="[x, -y, -z]")``, a sidecar's ``axes:`` key), written in one
notation everywhere (:func:`footzoo.core.conventions.axis_map_text`): a **signed permutation**,
one sensor axis per FRD axis::

    axes: [x, -y, -z]     # FRD x = sensor x, FRD y = -(sensor y), FRD z = -(sensor z): 180° about x

or a **rotation matrix** ``R`` whose rows are the FRD axes expressed in sensor coordinates, so that
``v_FRD = R · v_sensor``::

    axes: [[0.866025, 0, -0.5], [0, 1, 0], [0.5, 0, 0.866025]]   # a sensor pitched 30° on the foot

On input the brackets may be left out or be parentheses (``x, -y, -z``, ``(x, -y, -z)``; on the
command line ``--option axes=x,-y,-z`` needs no quotes), and ``−`` (U+2212) is a minus.

The map must be a proper rotation (determinant +1). A map with determinant −1 (one sign flipped
too many or too few, or two axes swapped without a sign change) describes a mirror image: every
turn would come out the wrong way round, so it is refused with the fix. The same map applies to
the accelerometer, the gyroscope and the magnetometer (a rotation maps polar and axial vectors
alike).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..core.conventions import axis_map_text
from ..core.errors import FormatError
from ..core.yamlsafe import load_text

#: The identity map.
IDENTITY = "[x, y, z]"
#: Tolerance on orthonormality of a rotation matrix (each entry).
ORTHO_TOL = 1e-6


def _axis_token(token: Any, where: str) -> tuple[int, float]:
    text = str(token).strip().lower().replace(" ", "").replace("\u2212", "-")
    sign = -1.0 if text.startswith("-") else 1.0
    name = text.lstrip("+-")
    if name not in ("x", "y", "z") or text.count("-") + text.count("+") > 1:
        raise FormatError(f"{where}: {token!r} is not a sensor axis; write x, y or z with an optional sign "
                          "(e.g. [x, -y, -z])")
    return "xyz".index(name), sign


def parse_axes(spec: Any, where: str = "axes") -> np.ndarray:
    """The rotation matrix ``R`` (3, 3) of an axis map (``v_FRD = R · v_sensor``).

    Parameters
    ----------
    spec : str, sequence of 3 axis names, or (3, 3) nested sequence
        ``"[x, -y, -z]"`` (or without the brackets), ``["x", "-y", "-z"]``, or a rotation matrix
        (rows: FRD axes in sensor coordinates), also as text ``"[[1, 0, 0], [0, -1, 0], [0, 0, -1]]"``.
    where : str
        What the map is (a sidecar key, a reader option), for messages.

    Raises
    ------
    FormatError
        For an unreadable map, an axis used twice, a matrix that is not a rotation, or a left-handed map.
    """
    if isinstance(spec, str):
        spec = _split(spec, where)
    if not isinstance(spec, Sequence) or isinstance(spec, (bytes, str)) or len(spec) != 3:
        raise FormatError(f"{where}: expected three sensor axes such as [x, -y, -z] or a 3x3 rotation matrix, "
                          f"got {spec!r:.80}")
    if all(isinstance(s, str) for s in spec):
        rows = np.zeros((3, 3))
        used: dict[int, str] = {}
        for i, token in enumerate(spec):
            k, sign = _axis_token(token, where)
            if k in used:
                raise FormatError(f"{where}: sensor axis {'xyz'[k]} is used twice ({used[k]!r} and {token!r}); "
                                  "each FRD axis needs a different sensor axis")
            used[k] = str(token)
            rows[i, k] = sign
    else:
        try:
            rows = np.array(spec, dtype=float)
        except (TypeError, ValueError):
            raise FormatError(f"{where}: a rotation matrix must be 3 rows of 3 numbers, got {spec!r:.80}") from None
        if rows.shape != (3, 3) or not np.isfinite(rows).all():
            raise FormatError(f"{where}: a rotation matrix must be 3 rows of 3 finite numbers, got shape "
                              f"{rows.shape}")
        if not np.allclose(rows @ rows.T, np.eye(3), atol=ORTHO_TOL * 10, rtol=0):
            raise FormatError(f"{where}: the matrix {np.array2string(rows, precision=4)} is not a rotation (its rows "
                              "must be unit vectors at right angles); give it to at least 6 decimals")
    det = float(np.linalg.det(rows))
    if det < 0:
        raise FormatError(
            f"{where}: the axis map {axis_map_text(rows)} is left-handed (a mirror image, determinant -1): with it "
            "every turn of the foot would come out the wrong way round. A sensor's axes are right-handed, so one "
            "FRD axis has the wrong sign: check which sensor axis points down (z must be down in FRD) and flip "
            "the sign of another axis, e.g. " + _suggest(rows)
        )
    return rows


def _split(text: str, where: str) -> list[Any]:
    """The three axis names of ``"[x, -y, -z]"`` (brackets, parentheses, commas or spaces), or a matrix's rows."""
    text = text.replace("\u2212", "-").strip()
    if text.startswith("[["):
        return load_text(text, where, FormatError)
    for ch in "[]();,":
        text = text.replace(ch, " ")
    tokens = text.split()
    # "- y" (a sign written apart from its axis) joins its axis
    out: list[str] = []
    for tok in tokens:
        if out and out[-1] in ("-", "+"):
            out[-1] += tok
        else:
            out.append(tok)
    return out


def _suggest(rows: np.ndarray) -> str:
    fixed = rows.copy()
    fixed[1] = -fixed[1]
    return f"{axis_map_text(fixed)} (y flipped) if x and z are right"


def apply_axes(rows: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` (N, 3) in sensor axes, rotated into FRD: ``values @ R.T``.

    A signed permutation picks and negates columns (exact, and a missing value stays in its own
    column, so an error about it names the right one); any other rotation multiplies.
    """
    values = np.asarray(values, dtype=float)
    k = np.argmax(np.abs(rows), axis=1)
    if np.array_equal(np.abs(rows), np.eye(3)[k]):
        return values[:, k] * rows[np.arange(3), k]
    return values @ rows.T


def describe_axes(rows: np.ndarray) -> str:
    """A map as footzoo writes it (``[x, -y, -z]``, or the matrix's rows), for metadata and messages."""
    return axis_map_text(rows)


def axes_fix(rows: np.ndarray | str) -> str:
    """How to read a file with the axis map ``rows``, spelled for the command line and for Python.

    ``--option 'axes=[x, -y, -z]'`` (command line) / ``footzoo.load(path, axes="[x, -y, -z]")``
    (Python): every reader accepts the option (:func:`footzoo.io.load`).
    """
    text = rows if isinstance(rows, str) else axis_map_text(rows)
    return f"--option 'axes={text}' on the command line, footzoo.load(path, axes=\"{text}\") in Python"


def rotate_columns(frame: Any, rows: np.ndarray) -> None:
    """Rotate the ``acc_*``, ``gyr_*`` and ``mag_*`` column triples of a DataFrame into FRD, in place."""
    for block in ("acc", "gyr", "mag"):
        cols = [f"{block}_{a}" for a in "xyz"]
        if all(c in frame.columns for c in cols):
            frame[cols] = apply_axes(rows, frame[cols].to_numpy(dtype=float))
