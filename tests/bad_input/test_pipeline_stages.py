"""A Pipeline's step-by-step methods given mismatched pieces: each refused, naming the method, the input and the fix.

A stance, an attitude or positions of another recording (another length), a detector fitted on another
recording or not fitted at all, a q0 that is not one quaternion, an unknown engine: each used to run on
misaligned samples (a silently wrong result) or to fail deep inside a plug-in. Pieces that mean the same
(a 1/0 stance, a q0 not of norm 1, a list) give the same result as the canonical ones.
"""

from __future__ import annotations

import numpy as np
import pytest

from footzoo import Pipeline, Stream
from footzoo.core.data import Recording
from footzoo.core.errors import ConfigError, NotARecordingError, RecordingError
from footzoo.sim import NoiseModel, simulate

CONFIG = {"name": "steps", "orientation": {"type": "fqa_complementary"},
          "detector": {"type": "angular_rate_fsm", "threshold": 0.6}, "corrections": [{"type": "zvu_dedrift"}]}


@pytest.fixture(scope="module")
def parts():
    pipe = Pipeline.from_dict(CONFIG)
    raw = simulate(n_strides=2, rate=100.0, noise=NoiseModel(seed=3))
    rec, q0, _ = pipe.prepare(raw)
    detector = pipe.detect(rec)
    stance, _ = pipe.guard(rec, detector)
    quat = pipe.orient(rec, stance, q0)
    nav = pipe.navigate(rec, stance, q0, quat)
    other = Recording(t=raw.t[:300], acc=raw.acc[:300], gyr=raw.gyr[:300], meta={"name": "start"})
    return dict(pipe=pipe, rec=rec, q0=q0, detector=detector, stance=stance, quat=quat, nav=nav, other=other)


@pytest.mark.parametrize("call, error, words", [
    (lambda p: p["pipe"].guard(p["rec"], p["stance"]), RecordingError, "guard: detector must be a fitted detector"),
    (lambda p: p["pipe"].guard(p["rec"], p["pipe"].detector.clone()), RecordingError, "not fitted yet"),
    (lambda p: p["pipe"].guard(p["rec"], p["pipe"].detect(p["other"])), RecordingError,
     "fitted on another recording; pipe.detect"),
    (lambda p: p["pipe"].detect(p["rec"], ctx="100 Hz"), ConfigError, "ctx must be a footzoo RunContext"),
    (lambda p: p["pipe"].orient(p["rec"], p["stance"][:-10], p["q0"]), RecordingError,
     r"orient: stance has \d+ samples but the recording"),
    (lambda p: p["pipe"].orient(p["rec"], p["stance"][:, None], p["q0"]), RecordingError, "stance must be a 1-D"),
    (lambda p: p["pipe"].orient(p["rec"], None, p["q0"]), RecordingError, "stance is None"),
    (lambda p: p["pipe"].orient(p["rec"], 2 * p["stance"].astype(int), p["q0"]), RecordingError,
     "True/False .* got 2 at sample"),
    (lambda p: p["pipe"].orient(p["rec"], p["stance"], p["q0"][1:]), RecordingError, r"q0 must be one quaternion"),
    (lambda p: p["pipe"].orient(p["rec"], p["stance"], np.tile(p["q0"], (5, 1))), RecordingError, "got shape"),
    (lambda p: p["pipe"].orient(p["rec"], p["stance"], np.zeros(4)), RecordingError, "is not a rotation"),
    (lambda p: p["pipe"].orient(p["rec"], p["stance"], 2 * p["q0"]), RecordingError, "has norm 2, not 1"),
    (lambda p: p["pipe"].navigate(p["rec"], p["stance"], [1.0, 0.2, 0.0, 0.0], None), RecordingError,
     r"has norm 1\.02, not 1"),
    (lambda p: p["pipe"].navigate(p["rec"], p["stance"], p["q0"], p["quat"][:-5]), RecordingError,
     "navigate: quat has"),
    (lambda p: p["pipe"].navigate(p["rec"], p["stance"], p["q0"], p["quat"][:, 1:]), RecordingError,
     r"quat must be \(N, 4\)"),
    (lambda p: p["pipe"].navigate(p["rec"], p["stance"], p["q0"], p["quat"] * np.nan), RecordingError,
     "quat at sample 0"),
    (lambda p: p["pipe"].navigate(p["rec"], p["stance"][::2], p["q0"], p["quat"]), RecordingError, "stance has"),
    (lambda p: p["pipe"].navigate(p["rec"], p["stance"], p["q0"], p["quat"], engine="turbo"), ConfigError,
     "navigate: engine must be one of"),
    (lambda p: p["pipe"].analyse(p["rec"], p["stance"], p["nav"]["quat"], p["nav"]["pos"][:-20]), RecordingError,
     "analyse: pos has"),
    (lambda p: p["pipe"].analyse(p["rec"], p["stance"], None, p["nav"]["pos"]), RecordingError, "quat is None"),
    (lambda p: p["pipe"].analyse(None, p["stance"], p["nav"]["quat"], p["nav"]["pos"]), NotARecordingError,
     "analyse expects a footzoo Recording"),
    (lambda p: Stream(p["pipe"], rate=100.0, engine="turbo"), ConfigError, "engine must be one of"),
    (lambda p: p["pipe"].run(p["rec"], covariance="no"), ConfigError,
     "Pipeline.run: covariance must be true or false, got str 'no'"),
])
def test_a_mismatched_piece_is_named_with_its_fix(parts, call, error, words):
    with pytest.raises(error, match=words):
        call(parts)


def test_pieces_that_mean_the_same_give_the_same_result(parts):
    """A 1/0 stance, a q0 rounded to a norm within 1 % of 1 and a q0 given as a list are the canonical stance and q0
    (a q0 farther from norm 1 is refused: test_a_mismatched_piece_is_named_with_its_fix)."""
    pipe, rec, stance, q0 = parts["pipe"], parts["rec"], parts["stance"], parts["q0"]
    np.testing.assert_allclose(pipe.orient(rec, stance.astype(int), 1.005 * q0), parts["quat"], atol=1e-12)
    np.testing.assert_array_equal(pipe.orient(rec, stance, list(q0)), parts["quat"])


@pytest.mark.parametrize("chunk", [[], 0, -3, 2.5, "ten", [5, 0]])
def test_stream_run_refuses_chunk_sizes_that_are_not_whole_numbers_of_samples(parts, chunk):
    with pytest.raises(ConfigError, match="chunk must be a number of samples >= 1"):
        Stream(parts["pipe"], rate=100.0).run(parts["other"], chunk=chunk)


def test_stream_run_of_a_path_says_how_to_load_it(parts):
    with pytest.raises(NotARecordingError, match="Stream.run expects a footzoo Recording"):
        Stream(parts["pipe"], rate=100.0).run("walk.csv")
