"""A process-noise term lives in two files: :mod:`footzoo.filters.process_noise` and the engine's settings.

The compiled loop, the closed-form smoother and the reference filter take the terms through
:class:`~footzoo.filters.process_noise.Noise` as a whole (:func:`~footzoo.filters.process_noise.unowned_noise`,
:func:`~footzoo.filters.process_noise.velocity_variance`), so adding one is a field and a line there and a
parameter of :class:`~footzoo.filters.engine.NavigationNoise`.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

import footzoo.filters
from footzoo.filters.engine import NavigationNoise
from footzoo.filters.process_noise import Noise, noise_of, unowned_noise

TERMS = Noise._fields[1:]
FILTERS = Path(footzoo.filters.__file__).parent


def test_every_term_is_a_navigation_parameter_copied_over():
    settings = NavigationNoise(**{f"{t}_noise": 0.001 * (i + 1) for i, t in enumerate(TERMS)})
    noise = noise_of(np.ones(9), settings)
    assert [getattr(noise, t) for t in TERMS] == [0.001 * (i + 1) for i in range(len(TERMS))]


def test_no_other_module_of_the_core_names_a_term():
    named = {p.name for p in FILTERS.glob("*.py")
             for t in TERMS if re.search(rf"\.{t}\b|\b{t}=", p.read_text(encoding="utf-8"))}
    assert named <= {"process_noise.py"}, named


def test_the_compiled_view_keeps_every_term():
    noise = Noise(np.arange(3.0), *(float(i + 2) for i in range(len(TERMS))))
    view = unowned_noise(noise)
    np.testing.assert_array_equal(view.q, noise.q)
    assert tuple(view[1:]) == tuple(noise[1:])
