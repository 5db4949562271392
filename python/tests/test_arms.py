"""Fixed-base arms from Python: models, kinematics, single steps and tracked paths."""
import pickle

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES, updated


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


needs_urdf = pytest.mark.skipif(not hasattr(flexkin._flexkin, "arm_from_urdf"),
                                reason="the URDF component is not built")


def quaternion_product(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def rotate(q, v):
    return quaternion_product(quaternion_product(q, np.r_[0.0, v]), q * [1, -1, -1, -1])[1:]


def test_joint_quaternions_planar_are_rotations_about_z():
    model = flexkin.ArmModel.straight(2, 5, 1.0)
    angles = np.array([0.3, -0.2, 1.0, 0.0, -3.0])
    q = flexkin.joint_quaternions(model, angles)
    assert q.shape == (5, 4) and q.dtype == np.float64 and q.flags.c_contiguous
    import math
    assert q[:, 0].tolist() == [math.cos(0.5 * a) for a in angles]      # bit for bit, libm's
    assert q[:, 3].tolist() == [math.sin(0.5 * a) for a in angles]
    assert not q[:, 1:3].any()


@pytest.mark.parametrize("kind", ["spherical", "axes"])
def test_joint_quaternions_compose_to_the_link_directions(kind):
    if kind == "spherical":
        model = flexkin.ArmModel([1.0, 0.5, 0.75, 0.5], dim=3)
        angles, azimuths = np.array([0.3, 0.5, 1.0, 0.2]), np.array([0.1, -2.0, 1.0, 3.0])
        directions = np.tile([1.0, 0, 0], (4, 1))
    else:
        axes = np.array([[0.0, 1, 0], [0, 0, 1], [0, 1, 0], [0, 0, 1]])
        model = flexkin.ArmModel([1.0, 0.5, 0.75, 0.5], dim=3, joint_axes=axes)
        angles, azimuths, directions = np.array([0.3, -0.5, 1.0, 0.2]), None, np.tile([1.0, 0, 0],
                                                                                     (4, 1))
    q = flexkin.joint_quaternions(model, angles, azimuths)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
    points = flexkin.forward_kinematics(model, angles, azimuths)
    frame = np.array([1.0, 0, 0, 0])
    for j in range(model.num_links):
        frame = quaternion_product(frame, q[j])
        link = points[j + 1] - points[j]
        expected = rotate(frame, directions[j]) * model.link_lengths[j]
        assert np.allclose(link, expected, atol=1e-12), j


def test_within_limits():
    model = flexkin.ArmModel([1.0] * 3, joint_min=[-0.5] * 3, joint_max=[0.5] * 3)
    assert flexkin.within_limits(model, [0.1, -0.5, 0.5])
    assert not flexkin.within_limits(model, [0.1, -0.6, 0.5])
    assert flexkin.within_limits(model, [0.1, -0.6, 0.5], slack=0.2)
    assert flexkin.within_limits(flexkin.ArmModel.straight(2, 3, 1.0), [3.0, -3.0, 3.0])
    spherical = flexkin.ArmModel([1.0] * 2, dim=3, max_bend=[0.5, 0.5])
    assert not flexkin.within_limits(spherical, [0.6, 0.1], [0.0, 0.0])


def test_model_members_read_back():
    axes = [[0.0, 1, 0], [0, 0, 1]]
    model = flexkin.ArmModel([1.0, 2.0], dim=3, base=[1, 2, 3], joint_axes=axes,
                             joint_min=[-1, -2], joint_max=[1, 2], initial_angles=[0.5, -0.5])
    assert np.array_equal(model.joint_axes, axes) and model.link_directions is None
    assert model.joint_min.tolist() == [-1, -2] and model.max_bend is None
    assert model.base.tolist() == [1, 2, 3] and model.initial_azimuths is None
    assert model.has_limits and model.joint == "revolute"
    model.validate()


@needs_urdf
def test_urdf_text_path_and_round_trip(tmp_path):
    path = EXAMPLES / "robot_snake.urdf"
    model = flexkin.arm_from_urdf(path)
    assert model == flexkin.arm_from_urdf(str(path)) == flexkin.arm_from_urdf(path.read_text())
    assert model.num_links == 16 and model.joint_axes.shape == (16, 3)
    assert np.allclose(model.joint_min, -0.6) and np.allclose(model.joint_max, 0.6)
    text = flexkin.urdf_from_arm(model, robot_name="again")
    assert '<robot name="again">' in text and flexkin.arm_from_urdf(text) == model
    (tmp_path / "again.urdf").write_text(text)
    assert flexkin.arm_from_urdf(tmp_path / "again.urdf") == model
    part = flexkin.arm_from_urdf(path, base_link="link_2")
    assert part.num_links == 14
    planar = flexkin.ArmModel([1.0, 0.5, 0.25], joint_min=[-1] * 3, joint_max=[1] * 3)
    back = flexkin.arm_from_urdf(flexkin.urdf_from_arm(planar))
    assert back.dim == 2 and np.array_equal(back.link_lengths, planar.link_lengths)
    # the arm of a robot scenario's "urdf" is the same model
    assert flexkin.load_robot_scenario(EXAMPLES / "robot_snake_urdf.json").model == model


@needs_urdf
def test_urdf_errors(tmp_path):
    with pytest.raises(flexkin.InputError) as info:
        flexkin.arm_from_urdf("<robot name='r'><link name='a'/></robot>")
    assert info.value.field == "urdf"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.arm_from_urdf("<not a urdf")
    assert info.value.field == "urdf"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.arm_from_urdf(EXAMPLES / "robot_snake.urdf", tip_link="nowhere")
    assert "tip_link" in info.value.field and str(EXAMPLES / "robot_snake.urdf") in str(info.value)
    planar = (EXAMPLES / "robot_snake.urdf").read_text().replace(
        'name="joint_3" type="revolute"', 'name="joint_3" type="planar"')
    with pytest.raises(flexkin.InputError) as info:
        flexkin.arm_from_urdf(planar)
    assert info.value.field == 'joint "joint_3"' and "planar" in str(info.value)
    prismatic = (EXAMPLES / "robot_snake.urdf").read_text().replace(
        'name="joint_3" type="revolute"', 'name="joint_3" type="prismatic"')
    slide = flexkin.arm_from_urdf(prismatic)                  # read since prismatic joints are
    assert slide.joint_types[3] == "prismatic" and slide.joint_types.count("prismatic") == 1
    with pytest.raises(flexkin.InputError) as info:
        flexkin.urdf_from_arm(flexkin.ArmModel([1.0, 1.0], dim=3))
    assert info.value.field.startswith("model")
    with pytest.raises(flexkin.InputError) as info:
        flexkin.arm_from_urdf(3)
    assert info.value.field == "source"


def long_path():
    t = np.linspace(0, 2 * np.pi, 200000)
    return np.column_stack([150 + 20 * np.cos(t), 20 * np.sin(t)])


def test_track_path_progress_and_its_exception(tmp_path):
    model = flexkin.ArmModel.straight(2, 4, 1.0)
    calls = []
    path = [[3.0, y] for y in np.linspace(0, 1, 50)]
    traj = flexkin.track_path(model, path, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (50, 50) and all(total == 50 for _, total in calls)
    plain = flexkin.track_path(model, path)
    assert np.array_equal(traj.angles, plain.angles)

    def stop(done, total):
        raise RuntimeError("enough")

    out = tmp_path / "trajectory.json"
    with pytest.raises(RuntimeError, match="enough"):
        flexkin.track_path(flexkin.ArmModel.straight(2, 200, 1.0), long_path(), progress=stop,
                           output=out)
    assert list(tmp_path.iterdir()) == []                    # no partial file


def test_run_robot_progress_true_uses_tqdm(fake_tqdm):
    traj = flexkin.run_robot(EXAMPLES / "robot_planar_8link.json", progress=True)
    assert fake_tqdm[0] == ("total", traj.num_steps) and fake_tqdm[-1] == ("close",)
    assert updated(fake_tqdm) == traj.num_steps


def test_ctrl_c_stops_run_robot_without_partial_files(tmp_path):
    import _thread
    import threading
    import time
    scenario = flexkin.RobotScenario(flexkin.ArmModel.straight(2, 200, 1.0), long_path())
    existing = tmp_path / "old.json"
    existing.write_text("old")
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    start = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            flexkin.run_robot(scenario, output=existing, csv=tmp_path / "joints.csv")
    finally:
        timer.cancel()
    assert time.monotonic() - start < 5.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.json"]
    assert existing.read_text() == "old"                     # left untouched


def test_run_robot_writes_the_files(tmp_path):
    import json
    out, csv = tmp_path / "t.json", tmp_path / "j.csv"
    traj = flexkin.run_robot(EXAMPLES / "robot_planar_8link.json", output=out, csv=csv)
    doc = json.loads(out.read_text())
    assert len(doc["steps"]) == traj.num_steps
    assert np.array_equal(np.array([s["joint_angles"] for s in doc["steps"]]), traj.angles)
    rows = csv.read_text().splitlines()
    assert rows[0].startswith("step,joint_0") and len(rows) == traj.num_steps + 2
    with pytest.raises(FileNotFoundError):
        flexkin.run_robot(EXAMPLES / "robot_planar_8link.json", output=tmp_path / "no" / "t.json")


def test_robot_scenarios_load_change_and_run():
    scenario = flexkin.load_robot_scenario(EXAMPLES / "robot_ravi_circle.json")
    assert isinstance(scenario.model, flexkin.ArmModel) and scenario.path.shape[1] == 2
    assert "targets" in scenario.summary() and scenario.estimate_output()["json_bytes"] > 0
    plain = flexkin.run_robot(EXAMPLES / "robot_ravi_circle.json")
    assert np.array_equal(flexkin.run_robot(scenario).angles, plain.angles)
    scenario.options = flexkin.ArmOptions(method="fixed_point")
    scenario.path = scenario.path[:5]
    changed = flexkin.run_robot(scenario)
    assert changed.method == "fixed_point" and changed.num_steps == 5
    assert flexkin.run_robot(scenario, method="newton").method == "newton"
    assert flexkin.validate_scenario(EXAMPLES / "robot_ravi_circle.json") == []
    problems = flexkin.validate_scenario({"format": "flexkin-robot", "arm": {"links": 0}})
    assert problems and all(p["field"].startswith("/") for p in problems)
