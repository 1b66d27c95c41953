"""Training of the learned zero-velocity detector (``learned_zv``) on PyShoe's VICON trials.

``python -m footzoo.detectors.learned_zv_train --all`` rewrites the shipped weights from every
trial in ``../shared/data/pyshoe_vicon`` (``--data DIR`` for another folder of PyShoe ``.mat``
files, ``--out FILE.npz`` for another file). Only numpy and scipy are needed.

Labels: for each trial, the zero-velocity labels (``zv_shoe_opt``, ``zv_ared_opt``, ``zv_amvd_opt``,
``zv_mbgtd_opt``, ``zv_vicon_opt``) of the detector whose per-trial optimal threshold gave PyShoe
its lowest error on that trial (``trial_error``): the labels that navigate best, as PyShoe's
learned detector is trained on. Every trial weighs the same whatever its length (each sample's
weight is 1 / its trial's sample count), and each class is weighted to an even share, so the
output probability is calibrated for an even prior. The loss is the weighted cross-entropy plus
``l2`` times the sum of squared weights, minimised by L-BFGS (scipy) from a seeded start, so the
same data give the same weights.
"""

from __future__ import annotations

import argparse
import io
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..core.atomic import write_bytes
from .learned_zv import HIDDEN, SHIPPED_WEIGHTS, features, probability

#: PyShoe's zero-velocity labels, in the order of its ``trial_error``.
LABELS = ("zv_shoe_opt", "zv_ared_opt", "zv_amvd_opt", "zv_mbgtd_opt", "zv_vicon_opt")
#: The shared PyShoe trials, from this file (``../shared/data`` beside the checkout).
DEFAULT_DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "pyshoe_vicon"


def trial_data(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """``(features (N, 16), labels (N,) bool)`` of one PyShoe trial, the labels of its best detector."""
    # deferred: scipy and the readers, for training only: the plug-in registry imports this module
    from scipy.io import loadmat

    from ..io import load

    rec = load(path)
    mat = loadmat(str(path))
    best = LABELS[int(np.argmin(np.asarray(mat["trial_error"], dtype=float).ravel()[: len(LABELS)]))]
    labels = np.asarray(mat[best]).ravel().astype(bool)
    if len(labels) != len(rec.t):
        raise ValueError(f"{path}: {len(labels)} labels for {len(rec.t)} samples; is it a PyShoe VICON trial?")
    return features(rec.acc, rec.gyr, rec.rate), labels


def _unpack(theta: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    w1 = theta[: n * HIDDEN].reshape(n, HIDDEN)
    b1 = theta[n * HIDDEN: n * HIDDEN + HIDDEN]
    w2 = theta[n * HIDDEN + HIDDEN: n * HIDDEN + 2 * HIDDEN]
    return w1, b1, w2, float(theta[-1])


def _loss(theta: np.ndarray, z: np.ndarray, y: np.ndarray, weight: np.ndarray, l2: float) -> tuple[float, np.ndarray]:
    """Weighted cross-entropy + L2 of the network over standardised features ``z``, and its gradient."""
    n = z.shape[1]
    w1, b1, w2, b2 = _unpack(theta, n)
    hidden = np.tanh(z @ w1 + b1)
    logit = hidden @ w2 + b2
    # log(1 + e^x) stably; the cross-entropy of label y in {0, 1} is softplus(logit) - y·logit
    loss = np.sum(weight * (np.logaddexp(0.0, logit) - y * logit))
    loss += l2 * (np.sum(w1**2) + np.sum(w2**2))
    d_logit = weight * (0.5 * (1.0 + np.tanh(0.5 * logit)) - y)
    g_w2 = hidden.T @ d_logit + 2 * l2 * w2
    g_b2 = np.sum(d_logit)
    d_hidden = np.outer(d_logit, w2) * (1.0 - hidden**2)
    g_w1 = z.T @ d_hidden + 2 * l2 * w1
    g_b1 = d_hidden.sum(axis=0)
    return float(loss), np.concatenate([g_w1.ravel(), g_b1, g_w2, [g_b2]])


def train(trials: Sequence[tuple[np.ndarray, np.ndarray]], l2: float = 1e-4, seed: int = 0,
          max_iter: int = 400) -> dict[str, np.ndarray]:
    """Fit the network to ``(features, labels)`` of several trials; returns the weights (see ``learned_zv``)."""
    from scipy.optimize import minimize  # here: the plug-in registry imports this module, runs need no scipy
    x = np.concatenate([f for f, _ in trials])
    y = np.concatenate([lab for _, lab in trials]).astype(float)
    per_trial = np.concatenate([np.full(len(lab), 1.0 / len(lab)) for _, lab in trials])
    share = np.where(y > 0.5, 0.5 / max(np.sum(per_trial * y), 1e-12), 0.5 / max(np.sum(per_trial * (1 - y)), 1e-12))
    weight = per_trial * share
    weight /= weight.sum()
    mean, std = x.mean(axis=0), x.std(axis=0)
    std = np.where(std > 0, std, 1.0)
    z = (x - mean) / std
    n = z.shape[1]
    rng = np.random.default_rng(seed)
    theta0 = np.concatenate([rng.normal(0.0, 1.0 / np.sqrt(n), n * HIDDEN), np.zeros(HIDDEN),
                             rng.normal(0.0, 1.0 / np.sqrt(HIDDEN), HIDDEN), [0.0]])
    fit = minimize(_loss, theta0, args=(z, y, weight, l2), jac=True, method="L-BFGS-B",
                   options={"maxiter": max_iter})
    w1, b1, w2, b2 = _unpack(fit.x, n)
    return {"mean": mean, "std": std, "w1": w1, "b1": b1, "w2": w2, "b2": np.asarray(b2)}


def accuracy(weights: dict[str, np.ndarray], trial: tuple[np.ndarray, np.ndarray], threshold: float = 0.5) -> float:
    """Fraction of a trial's samples whose decision agrees with its labels."""
    x, labels = trial
    return float(np.mean((probability(x, weights) >= threshold) == labels))


def save(weights: dict[str, np.ndarray], path: str | Path) -> Path:
    """Write the weights as ``.npz`` (atomically)."""

    buf = io.BytesIO()
    np.savez(buf, **weights)
    return write_bytes(path, buf.getvalue(), what="weights file")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m footzoo.detectors.learned_zv_train",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--all", action="store_true", help="train on every trial of the data folder")
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA, help="folder of PyShoe .mat trials")
    parser.add_argument("--out", type=Path, default=SHIPPED_WEIGHTS, help="weights file to write (.npz)")
    parser.add_argument("--l2", type=float, default=1e-4, help="L2 penalty on the weights")
    args = parser.parse_args(argv)
    files = sorted(args.data.glob("*.mat"))
    if not args.all or not files:
        parser.error(f"give --all to train on every trial of {args.data} ({len(files)} .mat files there)")
    trials = [trial_data(f) for f in files]
    weights = train(trials, l2=args.l2)
    save(weights, args.out)
    agree = [accuracy(weights, tr) for tr in trials]
    print(f"trained on {len(files)} trials ({sum(len(lab) for _, lab in trials)} samples); "
          f"agreement with the labels: median {np.median(agree):.3f}, worst {min(agree):.3f}; wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
