"""The machine code an installed footzoo wheel ships, for a source checkout run beside it (tests, docs build).

A checkout's footzoo (``python -m pytest`` or ``mkdocs build`` in the source tree imports it) has no
``_compiled`` folder, so numba would compile every kernel afresh (about a minute of CPU on a new
machine). A kernel's shipped code is used only where its source file has the same content
(:class:`footzoo.kernels.internals.KernelCache` checks a SHA-256 of the file and of the footzoo
modules it imports), so after ``pip install .`` of the
checkout its code can load what the wheel compiled, and compiles whatever differs.
"""

from __future__ import annotations

import importlib.metadata
import os
from pathlib import Path


def installed_kernels() -> Path | None:
    """The ``footzoo/_compiled`` folder of an installed footzoo distribution, if there is one."""
    for dist in importlib.metadata.distributions(name="footzoo"):  # a checkout's own egg-info may come first
        folder = Path(dist.locate_file("footzoo/_compiled"))
        if folder.is_dir():
            return folder
    return None


def use_installed_kernels() -> Path | None:
    """Point ``FOOTZOO_SHIPPED_KERNELS`` (inherited by subprocesses) at :func:`installed_kernels` unless it is set.

    Call before the first kernel runs. Returns the folder used, or None.
    """
    if "FOOTZOO_SHIPPED_KERNELS" in os.environ:
        return Path(os.environ["FOOTZOO_SHIPPED_KERNELS"])
    folder = installed_kernels()
    if folder is not None:
        os.environ["FOOTZOO_SHIPPED_KERNELS"] = str(folder)
    return folder
