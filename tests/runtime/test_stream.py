"""Every pipeline runs live: provisional estimates at once, final ones equal to the batch run after the latency."""

import warnings

import numpy as np
import pytest

import footzoo
from footzoo import ConfigError, FootzooWarning, Pipeline, Recording, RecordingError, SensorWarning, Stream
from footzoo.config import names
from footzoo.core.context import RunContext
from footzoo.plugins.incremental import WHOLE_RECORDING, Latency
from footzoo.sim import NoiseModel, simulate

from ..conftest import FPA_ON_TURNS, HARD_IRON_NOT_FITTED, STANCES_GUARDED, UPSIDE_DOWN_TRIAL

CONFIGS = names("pipeline")
#: random block sizes of a sensor's packets (the final estimates do not depend on them)
CHUNKS = np.random.default_rng(1).integers(1, 40, size=101)


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=12, profile="physical", rate=100.0, noise=NoiseModel(seed=3), distance_sensors=True,
                    clearance=0.1)


def live_config(name: str) -> Pipeline:
    """The shipped config, with a whole-recording smoother replaced by the one that streams."""
    p = Pipeline.from_yaml(name)
    if p.smoother == "rts":
        p.smoother = "stepwise"
    return p


def assert_final_equals_batch(final, batch, who):
    assert len(final["t"]) == len(batch.samples), f"{who}: not every sample got its final estimate"
    np.testing.assert_array_equal(final["t"], batch.samples["t"].to_numpy())
    np.testing.assert_array_equal(final["stance"], batch.stance, err_msg=who)
    scale = max(float(np.abs(batch.pos).max()), 1.0)
    for key, ref in (("pos", batch.pos), ("vel", batch.vel), ("quat", batch.quat)):
        err = float(np.abs(final[key] - ref).max())
        assert err <= 1e-9 * scale, f"{who}: final {key} differs from the batch run by {err:.3g}"


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
@pytest.mark.parametrize("config", CONFIGS)
def test_every_shipped_config_runs_live_and_its_final_estimates_equal_the_batch(walk, config):
    p = live_config(config)
    s = Stream(p, rate=walk.rate)
    final = s.run(walk, chunk=CHUNKS)
    batch = (p.with_fits(s.fits) if s.fits is not None else p).run(walk)
    assert_final_equals_batch(final, batch, config)
    assert s.latency.live, f"{config}: declared latency {s.latency} is not live"


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
@pytest.mark.parametrize("config", ["yun2012", "nguyen2016", "duong2015", "huang2016"])
def test_sample_by_sample_gives_a_provisional_estimate_for_every_sample_and_the_same_finals(walk, config):
    rec = Recording(t=walk.t[:700], acc=walk.acc[:700], gyr=walk.gyr[:700], mag=walk.mag[:700],
                    dist=walk.dist[:700], meta={"foot": walk.meta["foot"]})
    p = live_config(config)
    s = Stream(p, rate=rec.rate, warmup=3.0)
    s.log = []
    final = s.run(rec)  # push() one sample at a time
    started = [e for e in s.log if e is not None]
    wait = 3.0 if p.calibration else 0.6  # the still start (and the calibration's warm-up)
    assert len(started) >= rec.n - wait * rec.rate - 1  # every sample after them has an estimate
    for e in started:
        assert set(e) == {"t", "quat", "pos", "vel", "stance", "final"}
        assert np.isfinite(e["pos"]).all() and abs(np.linalg.norm(e["quat"]) - 1) < 1e-9
    batch = (p.with_fits(s.fits) if s.fits is not None else p).run(rec)
    assert_final_equals_batch(final, batch, config)
    # the provisional estimate of a sample is its final one when the pipeline has nothing left to wait for
    assert sum(e["final"] for e in started) > 0 if s.latency.causal else True


# windowed misses stances of these real trials (running, upside down); the guard marks them (expected warning)
# one trial's sensor is mounted upside down, which the mounting report names (expected warning)
# the walking trial circles the room: huang2016's FPA finds its footprints on turns (expected warning)
@pytest.mark.filterwarnings(FPA_ON_TURNS)
@pytest.mark.filterwarnings(UPSIDE_DOWN_TRIAL)
@pytest.mark.filterwarnings(STANCES_GUARDED)
@pytest.mark.parametrize("trial", ["2017-11-22-11-22-03", "2017-11-27-11-12-18", "2018-02-22-10-09-36"])
def test_every_shipped_config_live_on_real_trials_equals_the_batch(trial):
    """Walking, running and an inverted sensor (PyShoe's VICON trials): live final = batch (1e-9)."""
    from tests.conftest import data_file

    rec = footzoo.load(data_file("pyshoe_vicon", f"{trial}.mat"), format="pyshoe")
    for config in CONFIGS:
        p = live_config(config)
        try:
            batch = p.run(rec)
        except RecordingError:  # duong2015 needs distance sensors, which PyShoe's trials lack
            continue
        s = Stream(p, rate=rec.rate, guess=False)
        assert_final_equals_batch(s.run(rec, chunk=CHUNKS), batch, f"{config} on {trial}")


def test_final_estimates_come_out_as_soon_as_the_latency_has_passed(walk):
    """A centred window waits for its half; the state machine twice Γ_th; a dedrift for the swing's end."""
    ctx = RunContext.of(walk)
    p = Pipeline.from_yaml("duong2015_zupt")  # windowed detector (0.05 s), guard (the swing's end), Kalman (0)
    assert p.latency(ctx).seconds == pytest.approx(0.05 + 0.02) and p.latency(ctx).until == ("the end of the swing",)
    s = Stream(p, rate=walk.rate, guess=False)
    behind = []
    for k in range(walk.n):
        s.push(walk.t[k], walk.acc[k], walk.gyr[k])
        done = s.final()
        if len(done["t"]):
            behind.append(walk.t[k] - done["t"][-1])
    behind = np.array(behind)
    stance_lag = np.median(behind)
    assert stance_lag <= 0.07 + 1e-9  # in stance: the window's half and the guard's score window
    assert behind.max() < 1.5  # a swing of the walk waits for its end, never for more


def test_latency_is_declared_for_every_shipped_config_and_printed_by_validate(capsys):
    from footzoo.apps.cli import main

    ctx = RunContext(rate=100.0)
    for config in CONFIGS:
        lat = live_config(config).latency(ctx)
        assert isinstance(lat, Latency) and lat.live, config
    assert Pipeline.from_yaml("recommended").latency(ctx).until[-1] == WHOLE_RECORDING  # rts: offline
    stepwise = live_config("recommended").latency(ctx)  # a stride is final a sample after its stance's end
    assert stepwise.until[-1] == "the end of the next stance" and "the end of the next stance" in str(stepwise)
    assert main(["validate", "nguyen2016"]) == 0
    out = capsys.readouterr().out
    assert "latency" in out and "0.02 s" in out


def test_refusals_name_the_block_and_the_fix(walk):
    with pytest.raises(ConfigError, match=r"smoother 'rts' runs backwards over the whole recording: use smoother: "
                                          r"stepwise"):
        Stream(Pipeline.from_yaml("recommended"))
    with pytest.raises(ConfigError, match=r"detector 'oracle' reads the reference \(truth\)"):
        Stream(Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": "oracle"},
                                   "corrections": [{"type": "zupt"}]}))

    from footzoo.plugins.base import Detector
    from footzoo.plugins.registry import register

    @register
    class BatchOnly(Detector):
        """A detector that only has the batch method (not incremental)."""

        name = "test_batch_only_detector"
        paper = "none"

        def detect(self, t, acc, gyr):
            self.stance_ = np.linalg.norm(gyr, axis=1) < 0.6
            self.statistic_ = np.linalg.norm(gyr, axis=1)
            return self

    p = Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": BatchOnly.name},
                            "corrections": [{"type": "zupt"}]})
    assert np.isfinite(p.run(walk).pos).all()  # it runs in batch, with its own durations
    with pytest.raises(ConfigError, match=r"detector 'test_batch_only_detector' does not implement the incremental"):
        Stream(p)


# the warm-up of a straight simulated walk cannot give a hard-iron fit (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
def test_a_calibration_fits_online_on_the_warm_up_or_takes_a_given_fit(walk):
    loop = simulate(path="rectangle", n_strides=24, profile="physical", rate=50.0, noise=NoiseModel(seed=1))
    p = Pipeline.from_yaml("yun2012")  # hard_iron: fitted on a whole recording in batch
    online = Stream(p, rate=loop.rate, warmup=20.0)
    final = online.run(loop, chunk=CHUNKS)
    assert online.fits[0]["type"] == "hard_iron" and "offset" in online.fits[0]
    assert_final_equals_batch(final, p.with_fits(online.fits).run(loop), "yun2012, online fit")
    batch = p.run(loop)  # a batch run's fit, given to the stream: the stream gives that run's numbers
    given = Stream(p, rate=loop.rate, fits=batch)
    assert_final_equals_batch(given.run(loop, chunk=CHUNKS), batch, "yun2012, fit of the batch run")
    with pytest.raises(ConfigError, match="1 calibration"):
        Stream(p, fits=[{"applied": True}, {"applied": True}])


def test_bad_live_input_is_reported(walk):
    s = Stream(Pipeline.from_yaml("nguyen2016"))
    s.push(walk.t[0], walk.acc[0], walk.gyr[0])
    with pytest.raises(RecordingError, match="samples must arrive in order"):
        s.push(walk.t[0], walk.acc[0], walk.gyr[0])
    with pytest.raises(RecordingError, match="non-finite sample"):
        s.push(walk.t[1], [np.nan, 0, 0], walk.gyr[1])
    with pytest.raises(RecordingError, match=r"acc must have shape \(3, 3\)"):
        s.extend(walk.t[1:4], walk.acc[1:3], walk.gyr[1:4])
    spinning = Stream(Pipeline.from_yaml("nguyen2016"), rate=100.0, max_wait=3.0)
    with pytest.raises(RecordingError, match="found no still period.*first 3.0 s"):
        for k in range(400):  # turning at 1 rad/s: never still
            spinning.push(k / 100.0, [0.0, 0.0, -9.81], [0.0, 0.0, 1.0])
    closed = Stream(Pipeline.from_yaml("nguyen2016"), rate=100.0)
    closed.run(Recording(t=walk.t[:300], acc=walk.acc[:300], gyr=walk.gyr[:300]))
    with pytest.raises(RecordingError, match="the stream is closed"):
        closed.push(walk.t[300], walk.acc[300], walk.gyr[300])


def test_a_stream_that_starts_moving_waits_for_the_first_still_period_and_equals_the_batch(walk):
    p = Pipeline.from_yaml("nguyen2016")
    k0 = int(np.searchsorted(walk.t, 3.0))  # start mid-walk: the batch carries the attitude back
    rec = Recording(t=walk.t[k0:] - walk.t[k0], acc=walk.acc[k0:], gyr=walk.gyr[k0:], mag=walk.mag[k0:])
    s = Stream(p, rate=rec.rate, max_wait=60.0)  # this walk's only 0.5 s still period is at its end
    s.log = []
    with pytest.warns(SensorWarning, match="the recording starts in motion"):  # velocity unknown at its start
        final = s.run(rec)
    assert s.log[0] is None and s.log[-1] is not None
    first = next(k for k, o in enumerate(s.log) if o is not None)
    assert first > 0.5 * rec.rate  # it waited for the still period
    with pytest.warns(SensorWarning, match="the recording starts in motion"):
        batch = p.run(rec)
    assert_final_equals_batch(final, batch, "nguyen2016 starting mid-walk")


def test_distance_readings_missing_on_some_samples_count_as_no_reading(walk):
    p = Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": "dgp"},
                            "corrections": [{"type": "zupt"}, {"type": "height_distance"}]})
    s = Stream(p, rate=walk.rate)
    for k in range(200):
        s.push(walk.t[k], walk.acc[k], walk.gyr[k], dist=None if k % 3 == 1 else walk.dist[k])
    late = Stream(p, rate=walk.rate)
    late.push(walk.t[0], walk.acc[0], walk.gyr[0])
    with pytest.raises(RecordingError, match="distance readings started after the first sample"):
        late.push(walk.t[1], walk.acc[1], walk.gyr[1], dist=walk.dist[1])


def test_the_stream_keeps_only_what_is_pending(walk):
    """Memory is bounded by the latency: after every packet, only a few strides of samples wait; the
    step-wise smoother holds one stride at most (the samples after the last stance's end)."""
    from footzoo.filters.stepwise import segment_ends
    from footzoo.runtime.stages import KalmanStage

    long = simulate(n_strides=150, profile="physical", rate=100.0, noise=NoiseModel(seed=2))
    p = live_config("recommended")
    s = Stream(p, rate=long.rate, guess=False)
    held, smoother_held = [], []
    for k in range(0, long.n, 50):
        s.extend(long.t[k:k + 50], long.acc[k:k + 50], long.gyr[k:k + 50])
        s.final()
        held.append(s.pending())
        smoother_held += [st.held() for st in s._stages if isinstance(st, KalmanStage)]
    assert max(held[10:]) < 4 * long.rate  # seconds of samples held, however long the walk
    assert max(held[10:]) <= 2 * np.median(held[10:]) + long.rate
    ends = segment_ends(p.run(long).stance, long.t, closed=True)
    longest_stride = int(np.diff(ends).max())  # samples between two ends of stance
    assert 0 < max(smoother_held) <= longest_stride + 50  # a stride, and the packet that closed it


def test_a_kept_stream_gives_the_batch_result_with_its_strides(walk):
    p = Pipeline.from_yaml("nguyen2016")
    s = Stream(p, rate=walk.rate, keep=True, guess=False)
    s.run(walk, chunk=CHUNKS)
    res = s.result(meta={"name": "live walk"})
    batch = p.run(walk)
    np.testing.assert_allclose(res.pos, batch.pos, rtol=0, atol=1e-9)
    assert len(res.steps) == len(batch.steps) and res.recording["name"] == "live walk"
    np.testing.assert_allclose(res.steps["stride_length_m"], batch.steps["stride_length_m"], rtol=0, atol=1e-9)
    with pytest.raises(ConfigError, match="keep=True"):
        Stream(p).result()


def test_a_kept_stream_given_the_truth_has_the_batch_runs_metrics(walk):
    """``result(truth=rec.truth)``: the live result is scored against the reference as the batch run is; after
    ``run(rec)`` the recording's meta and truth are the defaults."""
    p = Pipeline.from_yaml("nguyen2016")
    batch = p.run(walk)
    assert "armse_3d_m" in batch.metrics

    def same_metrics(live):
        assert live.metrics.keys() == batch.metrics.keys()
        np.testing.assert_allclose(list(live.metrics.values()), list(batch.metrics.values()), rtol=0, atol=1e-9)

    ran = Stream(p, rate=walk.rate, keep=True, guess=False)
    ran.run(walk, chunk=CHUNKS)
    default = ran.result()
    assert default.reference is walk.truth and default.recording["name"] == walk.name
    same_metrics(default)
    pushed = Stream(p, rate=walk.rate, keep=True, guess=False)  # samples as a sensor delivers them
    for k in range(0, walk.n, 37):
        sl = slice(k, k + 37)
        pushed.extend(walk.t[sl], walk.acc[sl], walk.gyr[sl], walk.mag[sl], walk.dist[sl])
    pushed.close()
    assert "armse_3d_m" not in pushed.result(meta=walk.meta).metrics  # no truth, no errors against one
    same_metrics(pushed.result(meta=walk.meta, truth=walk.truth))
    with pytest.raises(ConfigError, match=r"truth=rec\.truth"):
        pushed.result(truth=walk)  # the recording instead of its reference
    short = footzoo.Truth(pos=walk.truth.pos[:-5])
    with pytest.raises(RecordingError, match=r"Stream\.result\(truth=\.\.\.\).*pos has .* rows"):
        pushed.result(truth=short)


def test_a_streamed_recording_is_warned_about_its_gaps_once():
    """The loader warned about the bridged gaps: the live result of the loaded recording does not warn again (they
    are in its ``recording["diagnostics"]``); samples pushed live are warned about once, at ``result()``, with the
    stream's fix."""
    walk = simulate(n_strides=4, rate=100.0, noise=NoiseModel(seed=3))
    keep = np.ones(walk.n, bool)
    keep[400:403] = False  # one gap of 0.04 s
    with pytest.warns(FootzooWarning, match="bridged 1 gap"):
        rec = Recording(t=walk.t[keep], acc=walk.acc[keep], gyr=walk.gyr[keep], meta={"name": "gappy"})
    pipe = Pipeline.from_yaml("nguyen2016")
    stream = Stream(pipe, rate=rec.rate, keep=True, guess=False)
    stream.run(rec, chunk=50)
    with warnings.catch_warnings():
        warnings.simplefilter("error", FootzooWarning)  # any footzoo warning fails the test
        res = stream.result(meta=rec.meta)
    assert res.recording["diagnostics"]["gaps"]["count"] == 1
    with pytest.warns(FootzooWarning, match=r"bridged 1 gap.*footzoo\.Stream\(pipeline, max_gap=SECONDS\)"):
        res = stream.result(meta={"name": "live"})  # samples that no loader saw
    assert res.recording["diagnostics"]["gaps"] == rec.meta["diagnostics"]["gaps"]


def test_stream_is_exported_at_the_top_level():
    from footzoo.runtime.stream import Stream as S

    assert footzoo.Stream is S and "Stream" in footzoo.__all__


def test_the_stepwise_smoother_closes_a_long_stance_after_max_segment_seconds():
    """Standing still: the stance is split every MAX_SEGMENT seconds, so the stream holds a few
    seconds of samples, not the whole stand, and still gives the batch run's numbers."""
    from footzoo.filters.stepwise import MAX_SEGMENT, segment_ends
    from footzoo.runtime.stages import KalmanStage

    rec = simulate(n_strides=6, profile="physical", rate=100.0, noise=NoiseModel(seed=4), stand_start=12.0,
                   stand_end=9.0)
    p = live_config("recommended")
    batch = p.run(rec)
    ends = segment_ends(batch.stance, rec.t, closed=True)
    assert np.diff(rec.t[ends]).max() <= MAX_SEGMENT + 1.5  # the stands are cut into segments
    s = Stream(p, rate=rec.rate, guess=False)
    held, parts = [], []
    for k in range(0, rec.n, 25):
        s.extend(rec.t[k:k + 25], rec.acc[k:k + 25], rec.gyr[k:k + 25], rec.mag[k:k + 25])
        parts.append(s.final())
        held += [st.held() for st in s._stages if isinstance(st, KalmanStage)]
    parts.append(s.close())
    final = {key: np.concatenate([q[key] for q in parts]) for key in parts[0]}
    assert max(held) <= (MAX_SEGMENT + 1.5) * rec.rate + 25
    assert_final_equals_batch(final, batch, "recommended (stepwise), standing")


def test_a_gap_that_a_batch_run_bridges_is_bridged_live_with_the_same_estimates():
    """A 0.2 s gap (a logger that dropped 20 samples) runs in batch and live, to the same numbers."""
    walk = simulate(n_strides=6, rate=100.0, noise=NoiseModel(seed=3))
    keep = np.ones(walk.n, bool)
    keep[400:419] = False  # 19 samples dropped: one gap of 0.2 s
    with pytest.warns(FootzooWarning, match="gap"):
        rec = Recording(t=walk.t[keep], acc=walk.acc[keep], gyr=walk.gyr[keep])
    pipe = Pipeline.from_yaml("recommended_live")
    batch = pipe.run(rec)
    stream = Stream(pipe, rate=rec.rate)  # the batch run's rate (its median), as every live == batch test
    assert stream.max_gap == 0.25  # the batch run's limit at 100 Hz
    live = stream.run(rec, chunk=np.array([7, 50]))
    np.testing.assert_allclose(live["pos"], batch.pos, rtol=0, atol=1e-9)


def test_the_gap_limit_follows_a_slow_rate_and_a_given_one():
    pipe = Pipeline.from_yaml("recommended_live")
    assert Stream(pipe, rate=10.0).max_gap == pytest.approx(0.5)  # 5 periods of 0.1 s
    assert Stream(pipe, rate=100.0, max_gap=0.05).max_gap == 0.05
