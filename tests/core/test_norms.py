"""Row norms of sample arrays: the compiled pass gives numpy's numbers, for every kind of input array."""

from __future__ import annotations

import numpy as np
import pytest

from footzoo.core.norms import row_norms, row_norms_squared


def _inputs():
    rng = np.random.default_rng(7)
    x = rng.normal(scale=50.0, size=(1000, 3))
    frozen = x.copy()
    frozen.flags.writeable = False
    return {"C-contiguous": x, "read-only": frozen, "strided": np.column_stack([x, x])[:, ::2],
            "float32": x.astype(np.float32), "integers": np.arange(30).reshape(10, 3),
            "four columns": rng.normal(size=(9, 4)), "empty": np.zeros((0, 3))}


@pytest.mark.parametrize("kind", list(_inputs()))
def test_row_norms_equal_numpy(kind):
    x = _inputs()[kind]
    xf = np.asarray(x, dtype=float)
    assert np.array_equal(row_norms(x), np.linalg.norm(xf, axis=1))
    assert np.array_equal(row_norms_squared(x), np.add.reduce(xf * xf, axis=1))


def test_hand_made_rows():
    x = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, -2.0], [1.0, 2.0, 2.0]])
    assert row_norms(x).tolist() == [5.0, 2.0, 3.0]
    assert row_norms_squared(x).tolist() == [25.0, 4.0, 9.0]


@pytest.mark.parametrize("kind", list(_inputs()))
def test_unit_error_is_the_largest_distance_of_a_squared_norm_from_one(kind):
    from footzoo.core.norms import unit_error

    x = _inputs()[kind]
    x = np.asarray(x, dtype=float) / 50.0
    err, k = unit_error(x)
    if not len(x):
        assert (err, k) == (0.0, -1)
        return
    expected = np.abs(np.add.reduce(x * x, axis=1) - 1.0)
    assert err == expected.max() and k == int(np.argmax(expected))


def test_unit_error_of_hand_made_quaternions():
    from footzoo.core.norms import unit_error

    q = np.array([[1.0, 0.0, 0.0, 0.0], [0.6, 0.8, 0.0, 0.0], [0.0, 0.0, 0.0, 1.001], [0.5, 0.5, 0.5, 0.5]])
    err, k = unit_error(q)
    assert k == 2 and abs(err - (1.001**2 - 1.0)) < 1e-15
