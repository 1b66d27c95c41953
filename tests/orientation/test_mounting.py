"""Any sensor mounting: the initial alignment and every orientation filter start from gravity, not from "level".

A simulated walk is re-expressed in a sensor turned on the foot by a fixed rotation R
(``a' = Rᵀ a``, ``ω' = Rᵀ ω``, ``m' = Rᵀ m``, true attitude ``q ⊗ R``): upside down (PyShoe's
2018-02-22 trial, acc_z ≈ +g at rest), on its side, toe pointing down, and an arbitrary turn.
"""

import numpy as np
import pytest

from footzoo.core.conventions import GRAVITY, quat_conj, quat_from_euler, quat_mul, quat_rotate, quat_to_euler
from footzoo.core.data import Recording, Truth
from footzoo.runtime.alignment import initial_attitude
from footzoo.runtime.pipeline import Pipeline
from footzoo.sim import simulate

from ..conftest import FPA_OF_THE_SENSOR

#: The mounting report of a sensor turned on purpose (this module's subject).
TURNED = "ignore:recording .sim_rectangle.. the sensor's y axis points left:footzoo.core.errors.SensorWarning"

MOUNTINGS = {
    "upright": (0.0, 0.0, 0.0),
    "inverted": (np.pi, 0.0, 0.0),
    "on_its_side": (np.pi / 2, 0.0, 0.0),
    "toe_down": (0.0, -np.pi / 2, 0.0),
    "nearly_toe_down": (0.0, -np.pi / 2 + 0.01, 0.0),
    "arbitrary": (2.0, -1.1, 0.7),
}


def remount(rec: Recording, roll: float, pitch: float, yaw: float) -> Recording:
    """The same walk seen by a sensor turned by R = q(roll, pitch, yaw) with respect to the original one."""
    qm = quat_from_euler(np.array(roll), np.array(pitch), np.array(yaw))

    def body(v):
        return None if v is None else quat_rotate(quat_conj(np.broadcast_to(qm, (len(v), 4))), v)

    tr = rec.truth
    truth = Truth(pos=tr.pos, vel=tr.vel, quat=quat_mul(tr.quat, np.broadcast_to(qm, tr.quat.shape)),
                  stance=tr.stance, steps=tr.steps, closed_loop=tr.closed_loop)
    return Recording(t=rec.t, acc=body(rec.acc), gyr=body(rec.gyr), mag=body(rec.mag), meta=dict(rec.meta),
                     truth=truth)


@pytest.fixture(scope="module")
def walk():
    return simulate(path="rectangle", length=10.0, width=5.0, rate=100.0, profile="paper")


def angle_between(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Rotation angle (rad) between attitudes (N, 4)."""
    return 2 * np.arccos(np.clip(np.abs(np.sum(q1 * q2, axis=-1)), 0.0, 1.0))


@pytest.mark.parametrize("mounting", MOUNTINGS)
def test_initial_alignment_maps_gravity_down_for_any_mounting(walk, mounting):
    rec = remount(walk, *MOUNTINGS[mounting])
    # without a magnetometer: the measured specific force, rotated to NED, points up (−z) with magnitude g
    q0 = initial_attitude(rec.t, rec.acc, rec.gyr, None)
    f_n = quat_rotate(q0, rec.acc[:10].mean(axis=0))
    # (1e-6 m/s² = 1e-7 rad: the half-angle formulas lose digits next to pitch ±90°)
    np.testing.assert_allclose(f_n, [0.0, 0.0, -GRAVITY], atol=1e-6)
    # with the magnetometer the whole attitude is the true one
    q0m = initial_attitude(rec.t, rec.acc, rec.gyr, rec.mag)
    assert angle_between(q0m, rec.truth.quat[0]) < 1e-6


def test_the_inverted_sensor_reads_plus_g_at_rest(walk):
    rec = remount(walk, *MOUNTINGS["inverted"])
    assert rec.acc[0, 2] == pytest.approx(GRAVITY)


# the sensor is turned on purpose: the mounting report names it, and huang2016's FPA too (expected warnings)
@pytest.mark.filterwarnings(TURNED)
@pytest.mark.filterwarnings(FPA_OF_THE_SENSOR)
@pytest.mark.parametrize("config", ["yun2012", "huang2016", "nguyen2016", "duong2015_zupt"])
@pytest.mark.parametrize("mounting", ["inverted", "on_its_side", "arbitrary"])
def test_every_orientation_filter_starts_right_on_a_turned_sensor(walk, config, mounting):
    rec = remount(walk, *MOUNTINGS[mounting])
    res = Pipeline.from_yaml(config).run(rec)
    quat = res.samples[["qw", "qx", "qy", "qz"]].to_numpy()
    still = rec.t < 1.5  # the walk starts with 2 s of standing
    tilt_est = quat_to_euler(quat[still])[:, :2]
    tilt_true = quat_to_euler(rec.truth.quat[still])[:, :2]
    # roll and pitch of the turned sensor, compared as angles so that ±π is one value; the mean over the
    # still start, because Madgwick's normalised gradient step (eq. 2) chatters by about β·dt around the optimum
    err = np.angle(np.exp(1j * (tilt_est - tilt_true)))
    assert np.max(np.abs(err[0])) < 1e-6
    assert np.max(np.abs(err.mean(axis=0))) < np.radians(0.05)


# the sensor is turned on purpose: the mounting report names it (expected warning)
@pytest.mark.filterwarnings(TURNED)
@pytest.mark.parametrize("config", ["nguyen2016", "nguyen2016_ins_zvu", "duong2015_zupt", "yun2012"])
def test_trajectory_does_not_depend_on_the_mounting(walk, config):
    """INS and FQA-based pipelines are equivariant: an upside-down sensor gives the same track."""
    up = Pipeline.from_yaml(config).run(walk)
    down = Pipeline.from_yaml(config).run(remount(walk, *MOUNTINGS["inverted"]))
    np.testing.assert_allclose(down.pos, up.pos, atol=1e-6)
