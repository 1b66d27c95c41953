"""Which plug-in combinations work together: enumerated from the registry and the pipeline's rules."""

from __future__ import annotations

import itertools
from typing import Any

from ..core.errors import ConfigError
from ..plugins.registry import available
from ..runtime.pipeline import Pipeline

#: Parameters that make a correction usable without the INS attitude (the variants worth listing).
VARIANTS: dict[str, list[dict[str, Any]]] = {
    "ekf_zupt": [{}, {"gyro_bias": False, "zero_rate": False}],
}


def combinations(max_corrections: int = 2) -> list[dict[str, Any]]:
    """Every orientation × detector × set of up to ``max_corrections`` corrections (with listed variants)."""
    corr_specs = []
    for name in sorted(available("correction")):
        for extra in VARIANTS.get(name, [{}]):
            corr_specs.append({"type": name, **extra})
    sets: list[list[dict[str, Any]]] = [[]]
    for k in range(1, max_corrections + 1):
        sets += [list(c) for c in itertools.combinations(corr_specs, k)]
    out = []
    for o, d, cs in itertools.product(sorted(available("orientation")), sorted(available("detector")), sets):
        out.append({"orientation": {"type": o}, "detector": {"type": d}, "corrections": cs})
    return out


def check(config: dict[str, Any]) -> str | None:
    """None when the config validates, else the reason."""

    try:
        Pipeline.from_dict(config)
    except ConfigError as err:
        return str(err)
    return None


def compatibility_matrix() -> str:
    """Orientation × correction (alone) table, then the rules that reject pairs."""
    orientations = sorted(available("orientation"))
    corr_specs = [{"type": n, **v} for n in sorted(available("correction")) for v in VARIANTS.get(n, [{}])]
    names = [",".join([s["type"]] + [f"{k}={v}" for k, v in s.items() if k != "type"]) for s in corr_specs]
    lines = ["Orientation x correction (any detector works with any of these):", ""]
    lines.append("| correction | " + " | ".join(orientations) + " |")
    lines.append("|---|" + "---|" * len(orientations))
    reasons: dict[str, str] = {}
    for spec, name in zip(corr_specs, names, strict=True):
        cells = []
        for o in orientations:
            why = check({"orientation": {"type": o}, "detector": {"type": "angular_rate_fsm"}, "corrections": [spec]})
            cells.append("yes" if why is None else "no")
            if why:
                reasons.setdefault(why.split(":", 1)[-1].strip(), name)
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines += ["", "Pairs of corrections are rejected when:"]
    pair_reasons = set()
    for a, b in itertools.combinations(corr_specs, 2):
        for o in orientations:
            why = check({"orientation": {"type": o}, "detector": {"type": "angular_rate_fsm"}, "corrections": [a, b]})
            if why:
                pair_reasons.add(why.split(":", 1)[-1].strip())
    lines += [f"- {r}" for r in sorted(pair_reasons)]
    if reasons:
        lines += ["", "Single corrections are rejected when:"] + [f"- {r}" for r in sorted(reasons)]
    return "\n".join(lines) + "\n"
