"""Plots of a pipeline's result (matplotlib, imported only when plotting)."""

from __future__ import annotations

from pathlib import Path

from .data import Recording, Result
from .metrics import rotate_about_vertical, yaw_alignment


def plot_trajectory(result: Result, path: str | Path, recording: Recording | None = None) -> Path:
    """Top view (east vs north) and height over time; the reference, yaw-aligned, when known."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pos = result.pos
    t = result.samples["t"].to_numpy()
    fig, (top, height) = plt.subplots(1, 2, figsize=(12, 5), gridspec_kw={"width_ratios": [1.2, 1]})
    top.plot(pos[:, 1], pos[:, 0], label=f"footzoo ({result.config.get('name', '')})")
    top.plot(pos[0, 1], pos[0, 0], "go", label="start")
    top.plot(pos[-1, 1], pos[-1, 0], "rs", label="end")
    height.plot(t, -pos[:, 2], label="estimate")
    ref = recording.truth.pos if recording is not None and recording.truth is not None else None
    if ref is not None:
        r = ref - ref[0]
        # show the reference in the estimate's frame
        r = rotate_about_vertical(r, -yaw_alignment(pos, ref)) + pos[0]
        top.plot(r[:, 1], r[:, 0], "k--", lw=1, label="reference")
        height.plot(t, -r[:, 2], "k--", lw=1, label="reference")
    top.set_xlabel("east (m)")
    top.set_ylabel("north (m)")
    top.set_aspect("equal", adjustable="datalim")
    top.legend(loc="best")
    top.set_title("top view")
    height.set_xlabel("time (s)")
    height.set_ylabel("height, up (m)")
    height.set_title("height")
    height.legend(loc="best")
    stance = result.stance
    if stance.any():
        ylim = height.get_ylim()
        height.fill_between(t, ylim[0], ylim[1], where=stance, color="0.9", step="mid", zorder=0)
        height.set_ylim(ylim)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out

