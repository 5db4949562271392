"""Fixed-base arms from Python: models, kinematics, single steps and tracked paths."""
import pickle

import numpy as np
import pytest

import flexkin


def test_straight_arm_tracks_a_circle():
    model = flexkin.ArmModel.straight(2, 8, 1.0)
    assert model.joint == "revolute" and model.num_links == 8 and model.reach == 8
    t = np.linspace(0, 2 * np.pi, 40)
    path = np.column_stack([5 + np.cos(t), np.sin(t)])
    traj = flexkin.track_path(model, path)
    assert traj.angles.shape == (40, 8) and traj.points.shape == (40, 9, 2)
    assert traj.reached.all() and traj.unreached == 0
    assert np.allclose(traj.points[:, 0], 0.0, atol=1e-9)           # the base held
    assert np.max(np.linalg.norm(traj.points[:, -1] - path, axis=1)) < 1e-8
    links = np.linalg.norm(np.diff(traj.points, axis=1), axis=2)
    assert np.max(np.abs(links - 1.0)) < 1e-12
    fk = flexkin.forward_kinematics(model, traj.angles[-1])
    assert np.allclose(fk, traj.points[-1], atol=1e-12)
    angles, azimuths = flexkin.joint_angles_from_points(model, traj.points[-1])
    assert azimuths is None and np.allclose(angles, traj.angles[-1], atol=1e-12)
    again = pickle.loads(pickle.dumps(traj))
    assert np.array_equal(again.angles, traj.angles)


def test_arm_steps_continue_from_the_last():
    model = flexkin.ArmModel([1.0] * 6, dim=3, joint_min=None)
    assert model.joint == "spherical"
    first = flexkin.arm_step(model, [5.0, 1.0, 0.5])
    second = flexkin.arm_step(model, [5.0, 1.2, 0.6], state=first,
                              options=flexkin.ArmOptions(tolerance=1e-11))
    assert first.reached and second.reached
    assert second.points.shape == (7, 3) and second.azimuths.shape == (6,)
    assert np.linalg.norm(second.points[-1] - [5.0, 1.2, 0.6]) < 1e-9
    options = flexkin.ArmOptions(method="fixed_point", restarts=2)
    assert repr(pickle.loads(pickle.dumps(options))) == repr(options)
    assert "ArmModel" in repr(pickle.loads(pickle.dumps(model)))


def test_arm_arguments_checked():
    with pytest.raises(flexkin.InputError) as e:
        flexkin.ArmModel([1.0, -1.0])
    assert e.value.field.startswith("link_lengths")
    with pytest.raises(flexkin.InputError) as e:
        flexkin.ArmModel([1.0, 1.0], joint_min=[0.0])
    assert e.value.field == "joint_min"
    model = flexkin.ArmModel.straight(2, 3, 1.0)
    with pytest.raises(flexkin.InputError) as e:
        flexkin.arm_step(model, [1.0, np.nan])
    assert e.value.field == "target[1]"
    with pytest.raises(flexkin.InputError):
        flexkin.forward_kinematics(model, [0.0, 0.0])
    with pytest.raises(flexkin.InputError):
        flexkin.track_path(model, np.zeros((0, 2)))
    with pytest.raises(flexkin.InputError):
        flexkin.ArmOptions(method="newtn")


def test_ctrl_c_stops_a_tracked_path():
    import _thread
    import threading
    import time
    model = flexkin.ArmModel.straight(2, 200, 1.0)
    t = np.linspace(0, 2 * np.pi, 200000)
    path = np.column_stack([150 + 20 * np.cos(t), 20 * np.sin(t)])
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    start = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            flexkin.track_path(model, path)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 5.0


def test_streamed_steps_are_their_own_arrays():
    traj = flexkin.track_path(flexkin.ArmModel.straight(2, 4, 1.0), [[3.0, 0.5], [3.0, 1.0]])
    arrays = [traj.ee_error, traj.base_error, traj.iterations, traj.sweeps, traj.passes,
              traj.converged, traj.reached, traj.joint_space]
    assert len({id(a) for a in arrays}) == len(arrays)
    assert all(a.shape == (2,) for a in arrays) and traj.num_steps == 2
    assert traj.angles.shape == (2, 4) and traj.points.shape == (2, 5, 2)
