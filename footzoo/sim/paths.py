"""Footstep sequences for the simulator: straight walks, closed loops, speed changes.

Each generator returns the positions (NED, m) where one foot is flat and the
walking heading there (rad, north = 0, east = +π/2). Closed paths are sampled
at equal arc-length spacing so that the last footstep returns to the first.
"""

from __future__ import annotations

import numpy as np

from .gait import Footstep


def straight(n_strides: int, stride_length: float | list[float] = 1.2, heading: float = 0.0) -> list[Footstep]:
    """``n_strides + 1`` footsteps along a straight line (stride lengths may vary per stride)."""
    lengths = np.broadcast_to(np.asarray(stride_length, float), (n_strides,))
    dist = np.concatenate([[0.0], np.cumsum(lengths)])
    u = np.array([np.cos(heading), np.sin(heading), 0.0])
    return [Footstep(pos=d * u, heading=heading) for d in dist]


def stairs(
    n_strides: int = 6, rise: float = 0.17, going: float = 0.28, landing_strides: int = 2,
    landing_stride: float = 1.2, heading: float = 0.0,
) -> list[Footstep]:
    """Up a straight flight of stairs, across a landing and down an equal flight (a footbridge).

    One foot's stride on stairs climbs two steps (step-over-step gait): each of the
    ``n_strides`` strides up moves ``2 · going`` forward and ``2 · rise`` up, the
    landing strides are ``landing_stride`` long and flat, and the same flight is
    walked down. Default steps are 0.17 m risers and 0.28 m treads (a typical
    public stair). Returns ``2 · n_strides + landing_strides + 1`` footsteps (NED,
    so up is −z).
    """
    u = np.array([np.cos(heading), np.sin(heading), 0.0])
    up = np.array([0.0, 0.0, -2.0 * rise])
    pos = [np.zeros(3)]
    for _ in range(n_strides):
        pos.append(pos[-1] + 2.0 * going * u + up)
    for _ in range(landing_strides):
        pos.append(pos[-1] + landing_stride * u)
    for _ in range(n_strides):
        pos.append(pos[-1] + 2.0 * going * u - up)
    return [Footstep(pos=p, heading=heading) for p in pos]


def repeat_laps(steps: list[Footstep], laps: int) -> list[Footstep]:
    """A closed path walked ``laps`` times: the footsteps repeated, the shared start/end kept once."""
    if laps < 1:
        raise ValueError(f"laps must be a positive integer, got {laps}")
    out = list(steps)
    for _ in range(laps - 1):
        out += [Footstep(pos=s.pos.copy(), heading=s.heading, fpa=s.fpa) for s in steps[1:]]
    return out


def _closed_curve(points: np.ndarray, stride_length: float) -> list[Footstep]:
    """Footsteps at equal arc length along a dense closed polyline (N, 2), starting at its first point."""
    pts = np.vstack([points, points[:1]])
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    total = s[-1]
    n = max(int(round(total / stride_length)), 3)
    targets = np.linspace(0.0, total, n + 1)
    north = np.interp(targets, s, pts[:, 0])
    east = np.interp(targets, s, pts[:, 1])
    steps = []
    for i in range(n + 1):
        j = min(i, n - 1)
        heading = np.arctan2(east[j + 1] - east[j], north[j + 1] - north[j])
        steps.append(Footstep(pos=np.array([north[i], east[i], 0.0]), heading=float(heading)))
    steps[-1].pos = steps[0].pos.copy()
    return steps


def rectangle(length: float = 40.0, width: float = 20.0, stride_length: float = 1.2) -> list[Footstep]:
    """A rectangular hallway loop (default 120 m), walked clockwise from the south-west corner heading north."""
    corners = np.array([[0.0, 0.0], [length, 0.0], [length, width], [0.0, width]])
    legs = []
    for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        n = max(int(round(np.linalg.norm(b - a) / stride_length)), 1)
        legs.append(a + np.linspace(0, 1, n, endpoint=False)[:, None] * (b - a))
    pts = np.vstack(legs)
    steps = [Footstep(pos=np.array([p[0], p[1], 0.0]), heading=0.0) for p in pts]
    steps.append(Footstep(pos=steps[0].pos.copy(), heading=0.0))
    for i in range(len(steps) - 1):
        d = steps[i + 1].pos - steps[i].pos
        steps[i].heading = float(np.arctan2(d[1], d[0]))
    steps[-1].heading = steps[-2].heading
    return steps


def track(lane_length: float = 437.5, straight_length: float = 84.39, stride_length: float = 1.2) -> list[Footstep]:
    """An athletic-track oval (Yun's lane 7: 437.5 m), walked counter-clockwise as in the paper."""
    r = (lane_length - 2 * straight_length) / (2 * np.pi)
    if r <= 0:
        raise ValueError("straight_length too long for the lane length")
    m = 4000
    th = np.linspace(0, np.pi, m // 4, endpoint=False)
    # start mid back-straight heading north; counter-clockwise seen from above = turning left (west)
    s1 = np.column_stack([np.linspace(-straight_length / 2, straight_length / 2, m // 4, endpoint=False),
                          np.zeros(m // 4)])
    c1 = np.column_stack([straight_length / 2 + r * np.sin(th), -r + r * np.cos(th)])
    s2 = np.column_stack([np.linspace(straight_length / 2, -straight_length / 2, m // 4, endpoint=False),
                          np.full(m // 4, -2 * r)])
    c2 = np.column_stack([-straight_length / 2 - r * np.sin(th), -r - r * np.cos(th)])
    pts = np.vstack([s1, c1, s2, c2])
    pts[:, 0] -= pts[0, 0]
    return _closed_curve(pts, stride_length)


def figure_eight(radius: float = 5.0, stride_length: float = 1.2) -> list[Footstep]:
    """Two tangent circles walked as an eight (one turning right, one turning left)."""
    th = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    right = np.column_stack([radius * np.sin(th), radius - radius * np.cos(th)])  # clockwise, east side
    left = np.column_stack([radius * np.sin(th), -radius + radius * np.cos(th)])  # counter-clockwise, west side
    return _closed_curve(np.vstack([right, left]), stride_length)
