"""A whole recording's sample indices (footzoo.runtime.chain.SampleIndices) read as numpy's arange reads."""

from __future__ import annotations

import numpy as np
import pytest

from footzoo.runtime.chain import SampleIndices


@pytest.mark.parametrize("start, stop", [(0, 0), (0, 1), (0, 37), (5, 12)])
def test_reads_as_arange(start, stop):
    k, ref = SampleIndices(start, stop), np.arange(start, stop)
    assert len(k) == len(ref)
    np.testing.assert_array_equal(np.asarray(k), ref)
    assert np.asarray(k).dtype == ref.dtype
    for s in (slice(None), slice(2, 9), slice(-3, None), slice(None, -2), slice(1, 30, 4), slice(50, 60)):
        np.testing.assert_array_equal(k[s], ref[s])
    for i in range(-len(ref), len(ref)):
        assert k[i] == ref[i]
    for i in (len(ref), -len(ref) - 1):
        with pytest.raises(IndexError):
            k[i]


def test_the_gait_scan_reads_them_as_an_array():
    """The estimate's gait scan reads the indices block by block: the same strides as from np.arange."""
    from footzoo.core.plausibility import GaitScan
    from footzoo.sim import NoiseModel, simulate

    walk = simulate(n_strides=12, rate=100.0, noise=NoiseModel(seed=1))
    tables = []
    for k in (np.arange(walk.n), SampleIndices(0, walk.n)):
        scan = GaitScan("walk")
        scan.push(k, walk.t, walk.acc, walk.gyr, walk.truth.stance, walk.truth.pos)
        scan.finish()
        tables.append(scan.strides)
    assert len(tables[0]) >= 10  # the strides of the walk were measured
    np.testing.assert_array_equal(tables[0], tables[1])
