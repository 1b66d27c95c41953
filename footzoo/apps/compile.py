"""Compile the kernels of pipeline configs now, so their first real run loads them instead.

numba compiles each kernel at its first call (about 5 s for a Kalman pipeline) and caches the
machine code on disk. :func:`compile_kernels` runs each config once on two short simulated walks
(with magnetometer and distance sensors, and without), in a batch run and, where the config can run
live, in a :class:`~footzoo.runtime.stream.Stream` (whose step-wise smoother keeps a record of each open
stride: another compile of the loop). That compiles and caches every kernel the config uses: run it
once on a new machine, or before a study starts its workers (``footzoo compile configs/*.yaml``;
a study file stands for every config of its grid). With ``ship`` it writes the code into a folder
instead: ``setup.py`` does so when it builds a wheel, which then carries the compiled kernels of the
shipped configs (see :class:`footzoo.kernels.internals.KernelCache`).
"""

from __future__ import annotations

import json
import os
import time
import warnings
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ..config.schema import load_yaml
from ..core.errors import ConfigError, RecordingError
from ..kernels import jit as _jit
from ..runtime.pipeline import Pipeline
from ..runtime.stream import Stream
from ..sim import simulate
from ..studies.study import Study


def _pipelines(path: str | os.PathLike) -> list[tuple[str, Pipeline]]:
    """The pipeline of a config file, or one per distinct config of a study file's grid, with names."""
    data = load_yaml(path)
    base_dir = Path(path).parent  # a config's plug-in paths are relative to its file, as in Pipeline.from_yaml
    if "base" not in data and "factors" not in data:
        configs = [(str(path), data)]
    else:  # a study's plug-in paths are made absolute when it is read
        unique: dict[str, tuple[str, dict[str, Any]]] = {}
        for cell in Study.from_yaml(path).cells():
            name = f"{path} [{', '.join(f'{k}={v}' for k, v in cell.levels.items())}]"
            unique.setdefault(json.dumps(cell.config, sort_keys=True, default=str), (name, cell.config))
        configs = list(unique.values())
    pipelines = []
    for name, config in configs:
        try:
            pipelines.append((name, Pipeline.from_dict(config, base_dir=base_dir)))
        except ConfigError as err:
            raise ConfigError(f"{name}: {err}") from None
    return pipelines


def compile_kernels(configs: Iterable[str | os.PathLike], ship: str | os.PathLike | None = None,
                    smoothed_live: bool = True) -> list[tuple[str, float]]:
    """Run every pipeline config once on a short simulated walk; return ``(config, seconds)`` per config.

    Parameters
    ----------
    configs : iterable of path
        Pipeline YAML files, or study files (every distinct config of the grid).
    ship : path, optional
        Write the machine code into this folder (a wheel's ``footzoo/_compiled``) instead of numba's
        cache. Must be given before any kernel has run in this process.
    smoothed_live : bool
        Also run the step-wise smoothed configs (``recommended_live``) live; the other configs that can run
        live always are. Live, the step-wise smoother keeps a record of each open stride: one more compile of
        the loop (about 14 s). A wheel's build leaves it out (``--no-smoothed-live``) to keep the install
        short, so the first live run of such a config compiles it.

    Raises
    ------
    RuntimeError
        ``ship`` was given after a kernel had already been compiled or loaded here, or numba is not installed.
    """
    if ship is not None and _jit.materialised():
        raise RuntimeError("footzoo compile --ship must run in a new process: kernels were already compiled or "
                           "loaded here, and would be missing from the shipped folder")
    numba = _jit.load_numba()
    if numba is None:
        raise RuntimeError("footzoo compile needs numba (pip install numba): without it the kernels run as Python")
    if ship is not None:
        # deferred: numba, loaded only when kernels are shipped
        from ..kernels import internals

        internals.ship(ship)
    # 8 strides at 100 Hz, with every sensor a config may read (magnetometer, distance sensors) and
    # with none (most recordings: the kernels that take an optional channel get None); the kernels'
    # argument types depend on neither the length nor the rate
    recordings = [simulate(n_strides=8, rate=100.0, profile="physical", distance_sensors=True),
                  simulate(n_strides=8, rate=100.0, profile="physical", magnetometer=False)]
    times = []
    pipelines = [p for config in configs for p in _pipelines(config)]  # every file checked before any compiles
    for name, pipeline in pipelines:
        start = time.perf_counter()
        for recording in recordings:
            with warnings.catch_warnings():  # a short walk: calibration and guards may warn; irrelevant here
                warnings.simplefilter("ignore")
                try:
                    pipeline.run(recording)
                    live = not pipeline.live_problems() and (smoothed_live or pipeline.smoother == "none")
                    if live:  # in packets and sample by sample
                        Stream(pipeline, rate=recording.rate).run(recording, chunk=[50, 1, 1])
                except RecordingError:  # a config that needs a channel the second walk lacks
                    if recording is recordings[0]:
                        raise
        times.append((name, time.perf_counter() - start))
    return times
