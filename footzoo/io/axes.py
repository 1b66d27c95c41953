"""Axis maps: how a sensor's axes become footzoo's FRD body frame (x toward the toe, y right, z down).

A map is written either as a **signed permutation**, one sensor axis per FRD axis::

    axes: [x, -y, -z]     # FRD x = sensor x, FRD y = -(sensor y), FRD z = -(sensor z): 180° about x

(a string ``"x, -y, -z"`` works too), or as a **rotation matrix** ``R`` whose rows are the FRD
axes expressed in sensor coordinates, so that ``v_FRD = R · v_sensor``::

    axes: [[0.866, 0, -0.5], [0, 1, 0], [0.5, 0, 0.866]]   # a sensor pitched 30° on the foot

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

from ..core.errors import FormatError

#: The identity map.
IDENTITY = ("x", "y", "z")
#: Tolerance on orthonormality of a rotation matrix (each entry).
ORTHO_TOL = 1e-6


def _axis_token(token: Any, where: str) -> tuple[int, float]:
    text = str(token).strip().lower().replace(" ", "")
    sign = -1.0 if text.startswith("-") else 1.0
    name = text.lstrip("+-")
    if name not in ("x", "y", "z") or text.count("-") + text.count("+") > 1:
        raise FormatError(f"{where}: {token!r} is not a sensor axis; write x, y or z with an optional sign "
                          "(e.g. [x, -y, -z])")
    return "xyz".index(name), sign


def _describe(rows: np.ndarray) -> str:
    """``(x, -y, -z)`` for a signed permutation, else the matrix."""
    names = []
    for row in rows:
        k = int(np.argmax(np.abs(row)))
        if not np.isclose(abs(row[k]), 1.0) or np.count_nonzero(np.round(row, 12)) != 1:
            return np.array2string(rows, precision=4)
        names.append(("-" if row[k] < 0 else "") + "xyz"[k])
    return "(" + ", ".join(names) + ")"


def parse_axes(spec: Any, where: str = "axes") -> np.ndarray:
    """The rotation matrix ``R`` (3, 3) of an axis map (``v_FRD = R · v_sensor``).

    Parameters
    ----------
    spec : str, sequence of 3 axis names, or (3, 3) nested sequence
        ``"x, -y, -z"``, ``["x", "-y", "-z"]`` or a rotation matrix (rows: FRD axes in sensor coordinates).
    where : str
        What the map is (a sidecar key, a reader option), for messages.

    Raises
    ------
    FormatError
        For an unreadable map, an axis used twice, a matrix that is not a rotation, or a left-handed map.
    """
    if isinstance(spec, str):
        spec = [s for s in spec.replace("(", "").replace(")", "").replace(";", ",").split(",") if s.strip()]
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
            f"{where}: the axis map {_describe(rows)} is left-handed (a mirror image, determinant -1): with it "
            "every turn of the foot would come out the wrong way round. A sensor's axes are right-handed, so one "
            "FRD axis has the wrong sign: check which sensor axis points down (z must be down in FRD) and flip "
            "the sign of another axis, e.g. " + _suggest(rows)
        )
    return rows


def _suggest(rows: np.ndarray) -> str:
    fixed = rows.copy()
    fixed[1] = -fixed[1]
    return f"{_describe(fixed)} (y flipped) if x and z are right"


def apply_axes(rows: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` (N, 3) in sensor axes, rotated into FRD: ``values @ R.T``."""
    return np.asarray(values, dtype=float) @ rows.T


def describe_axes(rows: np.ndarray) -> str:
    """A short text of a map (``(x, -y, -z)`` or the matrix), for metadata and messages."""
    return _describe(rows)
