"""Figures: produced for typical and edge cases, human labels, references drawn, files written."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pandas as pd
import pytest

import footzoo
from footzoo.evaluation.plots import (
    aligned_reference,
    broken_at_wraps,
    errors_figure,
    fpa_figure,
    plot_run,
    robust_limits,
    states_figure,
    step_column,
    strides_figure,
    trajectory_figure,
)
from footzoo.sim import NoiseModel, simulate
from footzoo.studies.report import level_labels, metric_figure, metric_label, plot_study, roc_figure, run_labels
from footzoo.studies.report import trajectories_figure as study_trajectories

from ..conftest import HARD_IRON_NOT_FITTED

# the figures are drawn from yun2012's run on a straight simulated walk, which gives no hard-iron fit (expected warning)
pytestmark = pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)


@pytest.fixture(scope="module")
def walk():
    """A short simulated walk with truth and the yun2012 pipeline's result on it."""
    rec = simulate(n_strides=8, rate=100.0, profile="physical", noise=NoiseModel(seed=0), seed=0,
                   fpa=np.radians(8.0))
    res = footzoo.Pipeline.from_yaml("yun2012").run(rec)
    return rec, res


def legend_texts(fig) -> list[str]:
    texts = [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    for ax in fig.axes:
        if ax.get_legend() is not None:
            texts += [t.get_text() for t in ax.get_legend().get_texts()]
    return texts


def close(fig) -> None:
    import matplotlib.pyplot as plt

    plt.close(fig)


# --------------------------------------------------------------------------- one run


def test_plot_run_writes_every_figure_with_truth(walk, tmp_path):
    rec, res = walk
    files = plot_run(res, tmp_path, rec, window=(2.0, 5.0))
    assert {f.name for f in files} == {"trajectory.png", "states.png", "errors.png", "strides.png"}
    for f in files:
        assert f.stat().st_size > 10_000
        assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_reference_is_aligned_onto_the_estimate(walk):
    rec, res = walk
    # an "estimate" that is the truth turned by 30° about the vertical and shifted: the aligned
    # reference must land exactly on it (hand-derived case, independent of any estimator)
    psi = np.radians(30.0)
    c, s = np.cos(psi), np.sin(psi)
    truth = rec.truth.pos
    turned = np.column_stack([c * truth[:, 0] - s * truth[:, 1], s * truth[:, 0] + c * truth[:, 1], truth[:, 2]])
    samples = res.samples.copy()
    samples[["pos_n", "pos_e", "pos_d"]] = turned + [5.0, -2.0, 0.3]
    fake = footzoo.evaluation.result.Result(samples=samples, steps=res.steps, config=res.config, versions=res.versions)
    assert np.allclose(aligned_reference(fake, rec), fake.pos, atol=1e-9)
    fig = trajectory_figure(res, rec)
    assert "reference (yaw-aligned)" in legend_texts(fig)
    assert f"stride ends, numbered ({len(res.steps)} strides)" in legend_texts(fig)
    close(fig)


def test_errors_figure_reports_the_rms_of_the_plotted_error(walk):
    rec, res = walk
    fig = errors_figure(res, rec)
    err = res.pos - aligned_reference(res, rec)
    rms = np.sqrt(np.mean(np.sum(err**2, axis=1)))
    assert f"3-D RMS {rms:.3f} m" in fig._suptitle.get_text()
    close(fig)


def test_no_truth_gives_no_error_figure_and_no_reference(walk, tmp_path):
    rec, res = walk
    bare = footzoo.core.data.Recording(t=rec.t, acc=rec.acc, gyr=rec.gyr, meta={"name": "bare"})
    assert errors_figure(res, bare) is None
    assert aligned_reference(res, bare) is None
    fig = trajectory_figure(res, bare)
    assert not any("reference" in t for t in legend_texts(fig))
    close(fig)
    files = plot_run(res, tmp_path, None)
    assert {f.name for f in files} == {"trajectory.png", "states.png", "strides.png"}


def test_states_window_outside_the_recording_is_a_clear_error(walk):
    rec, res = walk
    with pytest.raises(footzoo.ConfigError, match="outside the recording"):
        states_figure(res, rec, window=(1e4, 2e4))


def test_an_angle_line_breaks_where_it_wraps_and_never_climbs():
    # hand-derived: 170 -> 179 -> -179 (a wrap) -> -170; -90 -> 90 is a real turn of 180, kept
    got = broken_at_wraps(np.array([170.0, 179.0, -179.0, -170.0, -90.0, 89.0]))
    np.testing.assert_array_equal(np.isnan(got), [False, False, True, False, False, False])
    np.testing.assert_array_equal(got[~np.isnan(got)], [170.0, 179.0, -170.0, -90.0, 89.0])


def test_the_states_figure_keeps_roll_and_yaw_within_180_degrees(walk):
    # a pitched sensor whose pitch passes -90 deg at push-off flips roll and yaw by 180 deg every stride: ten such
    # flips, unwrapped, drew roll and yaw climbing to 1800 deg (IPOL's MTw: 3200 deg over 20 strides)
    import dataclasses

    _, res = walk
    smp = res.samples.copy()
    flips = np.pi * np.floor(np.linspace(0.0, 10.0, len(smp)))
    smp["roll"] = np.angle(np.exp(1j * (0.1 + flips)))
    smp["yaw"] = np.angle(np.exp(1j * (-0.2 + flips)))
    fig = states_figure(dataclasses.replace(res, samples=smp))
    lines = {line.get_label(): line.get_ydata() for line in fig.axes[0].get_lines()}
    for name in ("roll", "yaw"):
        assert np.nanmax(np.abs(lines[name])) <= 180.0
        assert np.isnan(lines[name]).any()  # the line breaks at the flips, no vertical stroke
    close(fig)


def test_a_recording_that_does_not_match_the_result_is_refused(walk):
    rec, res = walk
    other = simulate(n_strides=4, rate=100.0)
    for figure in (trajectory_figure, errors_figure, states_figure, strides_figure):
        with pytest.raises(footzoo.RecordingError, match="pass the recording the result was computed from"):
            figure(res, other)


def test_strides_figure_uses_gait_event_columns_and_reference(walk):
    rec, res = walk
    steps = res.steps.copy()
    steps["fpa_deg"] = 8.0  # as the huang_fpa analysis adds it
    res2 = footzoo.evaluation.result.Result(samples=res.samples, steps=steps, config=res.config, versions=res.versions,
                               diagnostics=res.diagnostics)
    fig = strides_figure(res2, rec)
    titles = [ax.get_title(loc="left") for ax in fig.axes if ax.get_visible()]
    assert any(t.startswith("stance time") for t in titles)
    assert any(t.startswith("swing time") for t in titles)
    assert any(t.startswith("foot progression angle: median 8 deg") for t in titles)
    assert "reference" in legend_texts(fig)  # the simulator's true strides, matched by time
    close(fig)
    fig = fpa_figure(res2, rec)
    assert "reference" in legend_texts(fig)
    ax = fig.axes[0]
    ref_y = next(line.get_ydata() for line in ax.lines if line.get_label() == "reference")
    assert np.allclose(ref_y, 8.0, atol=0.5)  # the simulator's true FPA (deg)
    lo, hi = ax.get_ylim()
    assert lo <= ref_y.min() and ref_y.max() <= hi  # kept in view
    close(fig)
    fig = states_figure(res2, rec, window=(2.0, 6.0))
    events = [t for ax in fig.axes if ax.get_legend() for t in [x.get_text() for x in ax.get_legend().get_texts()]]
    assert "initial contact" in events and "toe-off" in events
    close(fig)


def test_stride_table_without_units_in_its_names(walk):
    """An older stride table (``start``, ``end``, ``stride_length`` ..., angles in rad) draws the same panels."""
    rec, res = walk
    st = res.steps
    legacy = pd.DataFrame({"start": st["start_s"], "end": st["end_s"], "stride_time": st["stride_time_s"],
                           "stride_length": st["stride_length_m"], "speed": st["speed_m_s"],
                           "heading": st["heading_rad"], "max_clearance": st["max_clearance_m"], "fpa": 0.1})
    res2 = footzoo.evaluation.result.Result(samples=res.samples, steps=legacy, config=res.config, versions=res.versions,
                               diagnostics=res.diagnostics)
    fig = strides_figure(res2, rec)
    titles = {ax.get_title(loc="left").split(":")[0] for ax in fig.axes if ax.get_visible()}
    assert titles == {"stride length", "stride time", "speed", "max. foot clearance", "foot progression angle"}
    fpa_title = [ax.get_title(loc="left") for ax in fig.axes if ax.get_title(loc="left").startswith("foot")]
    assert fpa_title == [f"foot progression angle: median {np.degrees(0.1):.3g} deg"]
    close(fig)
    fig = trajectory_figure(res2, rec)
    assert f"stride ends, numbered ({len(legacy)} strides)" in legend_texts(fig)
    close(fig)


def test_step_column_units():
    steps = pd.DataFrame({"fpa": [np.radians(10.0)], "heading_deg": [5.0], "stride_length_m": [1.2],
                          "stride_time": [1.1]})
    v, unit = step_column(steps, "fpa")
    assert unit == "deg" and v[0] == pytest.approx(10.0)
    assert step_column(steps, "heading") == (pytest.approx([5.0]), "deg")
    assert step_column(steps, "stride_length")[1] == "m"
    assert step_column(steps, "stride_time")[1] == "s"
    assert step_column(steps, "swing_time") is None
    assert step_column(pd.DataFrame({"speed_m_s": [1.0]}), "speed")[1] == "m/s"


def test_robust_limits_keep_a_precise_series_and_drop_a_standing_stride():
    precise = 1.2 + 1e-4 * np.sin(np.arange(50))
    assert robust_limits(precise) is None
    times = np.array([16.4, 1.13, 1.07, 1.06, 1.13, 1.22, 1.2, 1.25, 1.31])
    lo, hi = robust_limits(times)
    assert hi < 16.4 and lo <= 1.06 and hi >= 1.31


def test_no_strides(walk):
    rec, res = walk
    empty = footzoo.evaluation.result.Result(samples=res.samples, steps=res.steps.iloc[:0], config=res.config,
                                versions=res.versions)
    assert strides_figure(empty, rec) is None
    assert fpa_figure(empty, rec) is None
    close(trajectory_figure(empty, rec))


# --------------------------------------------------------------------------- studies


def test_level_labels_are_human():
    labels = level_labels("corrections", [[{"type": "zvu_dedrift"}], [{"type": "zupt"}]])
    assert labels == {"[{'type': 'zvu_dedrift'}]": "zvu_dedrift", "[{'type': 'zupt'}]": "zupt"}
    labels = level_labels("corrections", [json.dumps([{"type": "ekf_zupt", "gyro_bias": False}]),
                                          json.dumps([{"type": "ekf_zupt", "gyro_bias": True}, {"type": "hdr"}])])
    assert sorted(labels.values()) == ["ekf_zupt (gyro_bias=off)", "ekf_zupt (gyro_bias=on) + hdr"]
    gains = level_labels("orientation.static_gain", [0.5, 1.05])
    assert gains == {"0.5": "static_gain=0.5", "1.05": "static_gain=1.05"}
    assert level_labels("detector.type", ["shoe"]) == {"shoe": "shoe"}
    assert metric_label("loop_closure_xy_pct") == "loop closure xy (%)"
    assert metric_label("armse_3d_m") == "armse 3d (m)"


def fake_runs(n_configs: int, n_recordings: int = 2, with_reference: bool = True, outlier: bool = False):
    """Study records as the runner stores them: a circle walked with a per-config heading error."""
    rng = np.random.default_rng(1)
    s = np.linspace(0, 2 * np.pi, 200)
    t = np.linspace(0, 60, 200)
    ref = np.column_stack([t, 10 * np.sin(s), 10 * (1 - np.cos(s)), 0 * s])
    runs = []
    for c in range(n_configs):
        for k in range(n_recordings):
            drift = 0.01 * (c + 1) * s
            est = np.column_stack([t, 10 * np.sin(s + drift), 10 * (1 - np.cos(s + drift)), 0.01 * s])
            fpr = np.linspace(0, 1, 11)
            roc = np.column_stack([np.linspace(0, 1, 11), fpr ** (0.1 + 0.05 * c), fpr])
            runs.append({"key": f"c{c}r{k}", "base": "yun2012.yaml", "recording": f"walk_{k}",
                         "levels": {"detector.threshold": 0.1 * (c + 1), "corrections": [{"type": "zupt"}]},
                         "error": None, "metrics": {"armse_3d_m": float(rng.uniform(0.1, 0.3))},
                         "trajectory": est.tolist(), "roc": roc.tolist(),
                         **({"reference": ref.tolist()} if with_reference else {})})
    if outlier:
        runs[0]["metrics"]["armse_3d_m"] = 55.0
    return runs


def table_of(runs, factors):
    rows = [{"run": r["key"], "base": r["base"], **{f: (json.dumps(r["levels"][f]) if not
             isinstance(r["levels"][f], (int, float, str)) else r["levels"][f]) for f in factors},
             "recording": r["recording"], "metric": m, "value": v, "error": None}
            for r in runs for m, v in r["metrics"].items()]
    return pd.DataFrame(rows)


FACTORS = ["detector.threshold", "corrections"]


def test_eight_configs_share_one_axis_with_the_legend_outside(tmp_path):
    runs = fake_runs(8)
    labels = run_labels(runs, FACTORS)
    assert labels["c0r0"] == "threshold=0.1, zupt"
    fig = study_trajectories([r for r in runs if r["recording"] == "walk_0"], labels, "walk_0")
    assert len(fig.axes) == 1
    texts = legend_texts(fig)
    assert texts[0] == "reference" and "threshold=0.8, zupt" in texts
    assert not any("type" in t or "{" in t for t in texts)
    # the legend is a figure legend outside the axes: it does not overlap the plotted area
    fig.canvas.draw()
    leg = fig.legends[0].get_window_extent()
    assert leg.y1 <= fig.axes[0].get_window_extent().y0
    close(fig)
    roc = roc_figure(runs, run_labels(runs, FACTORS, only=["detector.threshold"]))
    texts = legend_texts(roc)
    assert len(texts) == 8 and texts[0].startswith("threshold=0.1 (AUC ")
    fpr = np.linspace(0, 1, 11)  # the fake sweep of configuration 0: tpr = fpr^0.1, trapezoid rule
    assert texts[0] == f"threshold=0.1 (AUC {np.trapezoid(fpr ** 0.1, fpr):.3f})"
    assert roc.axes[0].get_xscale() == "linear"  # some AUCs are below 0.9
    close(roc)
    steep = fake_runs(1, n_recordings=1)
    steep[0]["roc"] = np.column_stack([fpr, fpr ** 0.02, fpr]).tolist()  # AUC 0.93: crowded top-left corner
    roc = roc_figure(steep, run_labels(steep, FACTORS))
    assert roc.axes[0].get_xscale() == "log"
    close(roc)



@pytest.mark.slow
def test_many_configs_get_small_multiples(tmp_path):
    runs = fake_runs(110, n_recordings=1)
    fig = roc_figure(runs, run_labels(runs, FACTORS, only=["detector.threshold"]))
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 110
    assert all(len(ax.lines) <= 3 for ax in visible)  # one recording, its mean, the diagonal
    assert visible[0].get_title().startswith("threshold=0.1\nAUC ")
    close(fig)
    fig = study_trajectories(runs, run_labels(runs, FACTORS), "walk_0")
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 110
    assert all(len(ax.lines) == 2 for ax in visible)  # the reference and one estimate per panel
    assert len({ax.get_xlim() for ax in visible}) == 1  # one scale for all
    close(fig)
    fig = metric_figure(table_of(runs, FACTORS), "detector.threshold", "armse_3d_m")
    assert len(fig.axes[0].get_yticklabels()) == 110  # one row per level
    close(fig)


@pytest.mark.slow
def test_plot_study_writes_its_files(tmp_path):
    runs = fake_runs(9, n_recordings=2)
    written = plot_study(table_of(runs, FACTORS), runs, FACTORS, tmp_path)
    names = {p.name for p in written}
    assert names == {"trajectories_walk_0.png", "trajectories_walk_1.png", "roc.png",
                     "metric_armse_3d_m_by_detector_threshold.png", "metric_armse_3d_m_by_corrections.png"}
    for p in written:
        assert p.read_bytes()[:4] == b"\x89PNG"


def test_a_diverging_run_does_not_shrink_the_other_panels():
    runs = fake_runs(10, n_recordings=1)
    tr = np.asarray(runs[3]["trajectory"])
    tr[:, 1:3] *= 50.0  # one configuration diverges to 1 km
    runs[3]["trajectory"] = tr.tolist()
    for with_reference in (True, False):
        rs = [dict(r) for r in runs]
        if not with_reference:
            for r in rs:
                r.pop("reference")
        fig = study_trajectories(rs, run_labels(rs, FACTORS), "walk_0")
        panels = [ax for ax in fig.axes if ax.get_visible()]
        lo, hi = panels[0].get_xlim()
        assert 20 < hi - lo < 40  # the 20 m circle fills the frame
        notes = [[t.get_text() for t in ax.texts] for ax in panels]
        assert notes[3] == ["leaves the frame"] and notes[0] == []
        close(fig)


def test_outlier_puts_the_box_plot_on_a_log_scale():
    runs = fake_runs(4, n_recordings=3, outlier=True)
    table = table_of(runs, FACTORS)
    fig = metric_figure(table, "detector.threshold", "armse_3d_m")
    assert fig.axes[0].get_yscale() == "log"
    assert [t.get_text() for t in fig.axes[0].get_xticklabels()][:2] == ["0.1", "0.2"]
    close(fig)
    fig = metric_figure(table_of(fake_runs(4, n_recordings=3), FACTORS), "detector.threshold", "armse_3d_m")
    assert fig.axes[0].get_yscale() == "linear"
    close(fig)


def test_one_config_without_reference(tmp_path):
    runs = fake_runs(1, n_recordings=1, with_reference=False)
    written = plot_study(table_of(runs, FACTORS), runs, FACTORS, tmp_path)
    assert (tmp_path / "trajectories_walk_0.png") in written
    labels = run_labels(runs, FACTORS)
    fig = study_trajectories(runs, labels, "walk_0")
    assert legend_texts(fig) == ["threshold=0.1, zupt"]
    close(fig)


def _reference_plot_study(table, runs, factors, out):
    """The previous plot_study, all figures in one call (the parallel report split it by factor only)."""
    from footzoo.evaluation.plots import save
    from footzoo.studies.report import _safe, trajectories_figure

    written = []
    labels = run_labels(runs, factors)
    for rec in sorted({r["recording"] for r in runs}):
        fig = trajectories_figure([r for r in runs if r["recording"] == rec], labels, rec)
        if fig is not None:
            written.append(save(fig, out / f"trajectories_{_safe(rec)}.png"))
    ok = table[table["metric"].notna()]
    for f in factors:
        for metric in sorted(ok["metric"].unique()):
            fig = metric_figure(ok[ok["metric"] == metric], f, metric)
            written.append(save(fig, out / f"metric_{_safe(metric)}_by_{_safe(f)}.png"))
    detector_factors = [f for f in factors if f == "detector" or f.startswith("detector.")]
    fig = roc_figure(runs, run_labels(runs, factors, only=detector_factors or None))
    if fig is not None:
        written.append(save(fig, out / "roc.png"))
    return written


@pytest.mark.slow
def test_one_figure_tasks_draw_the_files_of_the_whole_call(tmp_path):
    """The report's one-figure tasks (shared out to workers) give the previous plot_study's files, byte for byte."""
    from footzoo.studies.report import draw_figure, figure_tasks

    runs = fake_runs(4, n_recordings=3)
    table = table_of(runs, FACTORS)
    (tmp_path / "old").mkdir()
    old = _reference_plot_study(table, runs, FACTORS, tmp_path / "old")
    tasks = figure_tasks(table, runs, FACTORS)
    assert len(tasks) == 3 + len(FACTORS) + 1  # a trajectory per recording, a metric per factor, the ROC
    new = [p for p in (draw_figure(t, tmp_path / "new") for t in reversed(tasks)) if p is not None]
    assert sorted(p.name for p in new) == sorted(p.name for p in old)
    for p in old:
        assert (tmp_path / "new" / p.name).read_bytes() == p.read_bytes()
    assert [p.name for p in plot_study(table, runs, FACTORS, tmp_path / "again")] == [p.name for p in old]
    from footzoo.studies.report import render_figure

    drawn = [d for d in (render_figure(t) for t in tasks) if d is not None]  # in memory, as on a Dask worker
    assert [name for name, _ in drawn] == [p.name for p in old]
    assert all(data == (tmp_path / "old" / name).read_bytes() for name, data in drawn)


@pytest.mark.parametrize("layout", ["constrained", None])
def test_saved_figures_keep_a_legend_placed_below_the_axes(tmp_path, layout):
    """A constrained figure is saved as laid out (drawn once); others are fitted to what was drawn."""
    import matplotlib.pyplot as plt
    from PIL import Image

    from footzoo.evaluation.plots import STYLE, save

    fig, ax = plt.subplots(figsize=(4, 3), layout=layout)
    ax.plot([0, 1], [0, 1], label="a long legend entry that reaches far to the side")
    legend = ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.15))
    fig.canvas.draw()
    box, frame = legend.get_window_extent(), fig.bbox
    if layout == "constrained":  # the layout moved the legend inside the figure: nothing to fit
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0
    path = save(fig, tmp_path / "f.png")
    width, height = Image.open(path).size
    dpi = STYLE["savefig.dpi"]
    if layout == "constrained":
        assert (width, height) == (round(4 * dpi), round(3 * dpi))
    else:  # without a layout engine the legend hangs below the figure: the saved area grows to hold it
        assert height > 3 * dpi * 1.05


def test_a_figure_save_that_fails_midway_leaves_the_previous_figure(tmp_path):
    """Figures are written under a temporary name and renamed: a save cut short (Ctrl-C, a full disk) keeps
    the old file whole, and no temporary file is left behind."""
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from footzoo.evaluation.plots import save

    target = tmp_path / "trajectory.png"
    fig, _ = plt.subplots()
    save(fig, target)
    before = target.read_bytes()
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])

    def cut_short(fname, **kwargs):
        Path(fname).write_bytes(b"\x89PNG half a figure")
        raise KeyboardInterrupt

    fig.savefig = cut_short
    with pytest.raises(KeyboardInterrupt):
        save(fig, target)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["trajectory.png"]


@pytest.mark.parametrize("name", ["figure.xyz", "figure.PNGX"])
def test_a_figure_name_whose_format_matplotlib_lacks_is_an_output_error_naming_the_formats(tmp_path, name):
    import matplotlib.pyplot as plt

    from footzoo.core.atomic import OutputError
    from footzoo.evaluation.plots import save

    fig = plt.figure()
    suffix = name.split(".")[1].lower()
    with pytest.raises(OutputError, match=rf"figure '.*{name}': matplotlib writes no '\.{suffix}' files; end the "
                                          r"name with one of .*\.pdf, .*\.png.*\(e\.g\. '.*figure\.png'\)"):
        save(fig, tmp_path / "sub" / name)
    assert not plt.fignum_exists(fig.number) and not (tmp_path / "sub").exists()


def test_measured_footprints_are_drawn_aligned_onto_the_estimated_ones(walk):
    """Footprints in a dataset's own axes (mirrored, turned, moved, as Köroğlu's) land on the estimated footprints."""
    import dataclasses

    from footzoo.evaluation.metrics import estimated_footprints
    from footzoo.evaluation.plots import aligned_footprints

    rec, res = walk
    est = estimated_footprints(res.steps)
    assert len(est) == len(res.steps) + 1 >= 8
    turn = np.radians(70.0)
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    measured = (est * [1.0, -1.0]) @ rot.T + [12.0, -3.0]  # another handedness, heading and origin
    truth = dataclasses.replace(rec.truth, footprints=measured)
    mine = dataclasses.replace(rec, truth=truth)
    np.testing.assert_allclose(aligned_footprints(res, mine), est, atol=1e-9)
    fig = trajectory_figure(res, mine)
    assert "measured footprints (aligned)" in legend_texts(fig)
    close(fig)
    # a count that differs from the estimate's: nothing to align (the metric compares nothing either)
    fewer = dataclasses.replace(rec, truth=dataclasses.replace(rec.truth, footprints=measured[:-1]))
    assert aligned_footprints(res, fewer) is None
    assert aligned_footprints(res, rec) is None  # no measured footprints
    holed = measured.copy()
    holed[2] = np.nan  # a footprint not measured: no alignment (it failed in the SVD before), the figure still drawn
    holey = dataclasses.replace(rec, truth=dataclasses.replace(rec.truth, footprints=holed))
    assert aligned_footprints(res, holey) is None
    close(trajectory_figure(res, holey))
