"""The recommended config: one setting that finds every stance walking, running and on stairs (simulated)."""

import pytest

from footzoo.evaluation.metrics import armse, step_detection
from footzoo.runtime.pipeline import Pipeline
from footzoo.sim import simulate

SCENARIOS = {
    "walk": ({"path": "rectangle", "length": 10.0, "width": 5.0, "rate": 100.0}, 0.1),  # 30 m
    "run": ({"path": "run", "n_strides": 20, "rate": 200.0}, 0.2),  # 48 m at 3.2 m/s
    "stairs": ({"path": "stairs", "n_strides": 4, "cycle": 1.2, "clearance": 0.1, "rate": 100.0}, 0.1),
    # the foot stops in the air before each stair: at 250 Hz and above that was a stance (0.78 m ARMSE)
    "stairs_250hz": ({"path": "stairs", "n_strides": 4, "cycle": 1.2, "clearance": 0.1, "rate": 250.0}, 0.1),
    "stairs_400hz": ({"path": "stairs", "n_strides": 4, "cycle": 1.2, "clearance": 0.1, "rate": 400.0}, 0.1),
}


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_recommended_finds_every_stance_and_tracks_the_truth(scenario):
    spec, bound = SCENARIOS[scenario]
    rec = simulate(**spec, profile="physical", noise={"scale": 1.0, "seed": 0})
    res = Pipeline.from_yaml("recommended").run(rec)
    sd = step_detection(res.stance, rec.truth.stance, rec.t)
    assert sd["error_rate"] == 0.0
    assert len(res.steps) == len(rec.truth.steps)
    # decimetres over tens of metres with Table II noise and biases: the zero-velocity updates hold
    assert armse(res.pos, rec.truth.pos) < bound
