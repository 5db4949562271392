"""Any serial robot from Python: URDF arms with joints at one point (universal joints), a twist
joint and a tip offset; joint groups, the tool frame, pointing and the options that ask for it."""
import pickle

import numpy as np
import pytest

import flexkin

needs_urdf = pytest.mark.skipif(not hasattr(flexkin._flexkin, "arm_from_urdf"),
                                reason="the URDF component is not built")

LINK = 0.1
MODULES = 6
TIP_OFFSET = (0.05, 0.0, 0.0)


def snake_urdf(modules=MODULES, floating=False):
    """A snake of `modules` universal joints (pitch about y, then yaw about z at the same
    origin), links of LINK along x, then a continuous roll joint along the last link; the tip
    link is the roll joint's child (a tip on its joint)."""
    links = ['<link name="base"/>']
    joints = []
    parent = "base"
    for k in range(modules):
        x = 0.0 if k == 0 else LINK
        for part, axis, origin in (("pitch", "0 1 0", f"{x} 0 0"), ("yaw", "0 0 1", "0 0 0")):
            child = f"m{k}_{part}_link"
            links.append(f'<link name="{child}"/>')
            joints.append(
                f'<joint name="m{k}_{part}" type="revolute"><parent link="{parent}"/>'
                f'<child link="{child}"/><origin xyz="{origin}" rpy="0 0 0"/>'
                f'<axis xyz="{axis}"/>'
                f'<limit lower="-1.2" upper="1.2" effort="1" velocity="2.5"/></joint>')
            parent = child
    links.append('<link name="tool"/>')
    joints.append(f'<joint name="roll" type="{"floating" if floating else "continuous"}">'
                  f'<parent link="{parent}"/><child link="tool"/>'
                  f'<origin xyz="{LINK} 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/></joint>')
    return '<robot name="snake">' + "".join(links + joints) + "</robot>"


@pytest.fixture(scope="module")
def snake():
    return flexkin.arm_from_urdf(snake_urdf(), tip_offset=TIP_OFFSET)


def circle(model, turn, samples):
    """A circle through the straight snake's end effector, its centre at 0.75 of the reach on
    the line toward the base, normal z; `turn` of it (radians) in `samples` points."""
    reach = model.reach
    centre = np.array([0.75 * reach, 0.0, 0.0])
    t = np.linspace(0.0, turn, samples)
    return centre + 0.25 * reach * np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])


def with_initial_angles(model, angles):
    return flexkin.ArmModel(
        model.link_lengths, dim=3, base=model.base, base_direction=model.base_direction,
        joint_min=model.joint_min, joint_max=model.joint_max, joint_axes=model.joint_axes,
        link_directions=model.link_directions, initial_angles=angles,
        joint_types=model.joint_types, max_velocity=model.max_velocity,
        tip_rotation=model.tip_rotation, joint_names=model.joint_names)


@needs_urdf
def test_universal_joints_read_and_grouped(snake):
    n = 2 * MODULES + 1
    assert snake.dim == 3 and snake.num_links == n
    assert snake.joint_types == ["revolute"] * n
    assert snake.joint_names[:3] == ["m0_pitch", "m0_yaw", "m1_pitch"]
    assert snake.joint_names[-1] == "roll"
    expected = [0.0, LINK] * MODULES + [TIP_OFFSET[0]]
    assert np.allclose(snake.link_lengths, expected, atol=1e-15)
    assert np.isclose(snake.reach, MODULES * LINK + TIP_OFFSET[0])
    # the roll joint turns about its own link, the continuous joint is unlimited
    assert np.allclose(snake.joint_axes[-1], [1, 0, 0])
    assert snake.joint_min[-1] == -np.inf and snake.joint_max[-1] == np.inf
    assert np.allclose(snake.joint_min[:-1], -1.2) and np.allclose(snake.joint_max[:-1], 1.2)
    assert snake.max_velocity.shape == (n,) and np.allclose(snake.max_velocity[:-1], 2.5)
    assert snake.max_velocity[-1] == np.inf
    assert np.array_equal(snake.tip_rotation, [1.0, 0.0, 0.0, 0.0])

    groups = flexkin.joint_groups(snake)
    assert groups == [[2 * k, 2 * k + 1] for k in range(MODULES)] + [[n - 1]]
    report = flexkin.joint_groups_report(snake)
    assert len(report.strip().splitlines()) == MODULES
    assert '"m0_pitch"' in report and '"m0_yaw"' in report and "universal" in report

    points = flexkin.forward_kinematics(snake, snake.initial_angles)
    assert points.shape == (n + 1, 3)
    drawn = flexkin.chain_points(snake, points)
    assert drawn.shape == (len(groups) + 1, 3)          # one per group, then the tip
    assert np.allclose(drawn[-1], points[-1]) and np.allclose(drawn[0], [0, 0, 0])

    # without a tip offset the tip sits on the roll joint
    on_joint = flexkin.arm_from_urdf(snake_urdf())
    assert on_joint.num_links == n and on_joint.link_lengths[-1] == 0.0
    on_points = flexkin.forward_kinematics(on_joint, on_joint.initial_angles)
    assert flexkin.chain_points(on_joint, on_points).shape == (len(groups), 3)


@needs_urdf
def test_model_fields_pickle_and_construct(snake):
    again = pickle.loads(pickle.dumps(snake))
    assert again == snake and again.joint_names == snake.joint_names
    built = with_initial_angles(snake, snake.initial_angles)
    assert built == snake
    with pytest.raises(flexkin.InputError) as info:
        flexkin.ArmModel(snake.link_lengths, dim=3, joint_axes=snake.joint_axes,
                         link_directions=snake.link_directions,
                         joint_types=["revolute"] * 12 + ["hinge"])
    assert info.value.field == "joint_types[12]"
    slide = flexkin.ArmModel([1.0, 1.0], dim=3, joint_axes=[[0, 0, 1], [1, 0, 0]],
                             joint_types=["revolute", "prismatic"], joint_min=[-1, -0.5],
                             joint_max=[1, 0.5])
    assert slide.joint_types == ["revolute", "prismatic"]
    points = flexkin.forward_kinematics(slide, [0.0, 0.25])
    assert np.allclose(points[-1], [2.25, 0, 0])
    assert flexkin.ArmModel.straight(2, 3, 1.0).joint_types == []


@needs_urdf
def test_tool_pose_is_the_end_of_forward_kinematics(snake):
    rng = np.random.default_rng(7)
    angles = rng.uniform(-0.5, 0.5, snake.num_links)
    position, rotation = flexkin.tool_pose(snake, angles)
    assert position.shape == (3,) and rotation.shape == (3, 3)
    points = flexkin.forward_kinematics(snake, angles)
    assert np.allclose(position, points[-1], atol=1e-14)
    assert np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-14)
    # the tool x axis runs along the last link (the tip offset is along x)
    last = points[-1] - points[-2]
    assert np.allclose(rotation[:, 0], last / np.linalg.norm(last), atol=1e-12)
    with pytest.raises(flexkin.InputError) as info:
        flexkin.tool_pose(flexkin.ArmModel.straight(2, 3, 1.0), [0.0] * 3)
    assert info.value.field == "model"


@needs_urdf
def test_snake_tracks_a_circle_inside_its_workspace(snake):
    path = circle(snake, 2 * np.pi, 48)
    traj = flexkin.track_path(snake, path)
    mean_link = snake.reach / snake.num_links
    assert traj.reached.all() and traj.unreached == 0
    assert np.max(traj.ee_error) <= 1e-10 * mean_link
    assert np.allclose(traj.points[:, 0], 0.0, atol=1e-12)
    assert np.all(traj.pointing_error == 0.0) and traj.max_pointing_error == 0.0
    assert np.all(traj.velocity_legs == 0) and traj.total_velocity_legs == 0
    # One point per joint group, as chain_points gives them; the chain's lengths are kept.
    fk = flexkin.forward_kinematics(snake, traj.angles[-1])
    assert np.max(np.abs(traj.points[-1] - flexkin.chain_points(snake, fk))) < 1e-12
    lengths = np.linalg.norm(np.diff(traj.points, axis=1), axis=2)
    rest = np.linalg.norm(np.diff(traj.initial_points, axis=0), axis=1)
    assert lengths.shape[1] == len(flexkin.joint_groups(snake))
    assert np.max(np.abs(lengths - rest)) < 1e-12
    assert (np.abs(traj.angles[:, :-1]) <= 1.2 + 1e-12).all()


@needs_urdf
def test_pointing_along_a_feasible_direction(snake):
    quarter = circle(snake, np.pi / 2, 13)
    first = flexkin.track_path(snake, quarter)
    assert first.reached.all()
    _, rotation = flexkin.tool_pose(snake, first.angles[-1])
    direction = rotation[:, 0]
    bent = with_initial_angles(snake, first.angles[-1])
    t = np.linspace(np.pi / 2, np.pi, 13)
    reach = snake.reach
    path = np.array([0.75 * reach, 0, 0]) + 0.25 * reach * np.column_stack(
        [np.cos(t), np.sin(t), np.zeros_like(t)])
    options = flexkin.ArmOptions(pointing_direction=direction)
    assert np.array_equal(options.pointing_direction, direction) and options.look_at is None
    assert np.array_equal(options.pointing_axis, [1.0, 0.0, 0.0])
    traj = flexkin.track_path(bent, path, options=options)
    assert traj.reached.all()
    assert traj.max_pointing_error <= 1e-8 and np.max(traj.pointing_error) <= 1e-8
    assert np.max(traj.ee_error) <= 1e-10 * reach / snake.num_links
    for angles in traj.angles[::4]:
        _, r = flexkin.tool_pose(bent, angles)
        assert np.arccos(np.clip(r[:, 0] @ direction, -1, 1)) <= 1e-7
    # the same as a dict, and one step at a time
    again = flexkin.track_path(bent, path, options={"pointing_direction": direction})
    assert np.array_equal(again.angles, traj.angles)
    step = flexkin.arm_step(bent, path[1], options=options)
    assert step.reached and step.pointing_error <= 1e-8
    assert step.velocity_legs == 0 and step.velocity_ratio == 0.0


@needs_urdf
def test_velocity_limits_split_steps(snake):
    # from a bent pose: out of the straight (singular) pose the legs' motion is uneven
    bent = with_initial_angles(snake, flexkin.track_path(snake, circle(snake, np.pi / 2,
                                                                       13)).angles[-1])
    t = np.linspace(np.pi / 2, np.pi, 7)
    path = np.array([0.75 * snake.reach, 0, 0]) + 0.25 * snake.reach * np.column_stack(
        [np.cos(t), np.sin(t), np.zeros_like(t)])
    traj = flexkin.track_path(bent, path, options=flexkin.ArmOptions(time_step=0.01))
    assert traj.reached.all()
    assert (traj.velocity_legs >= 1).all() and traj.total_velocity_legs == traj.velocity_legs.sum()
    assert (traj.velocity_ratio <= 1.0 + 1e-9).all()
    assert traj.velocity_legs.max() > 1                   # fast: some step was split


def test_pointing_options_round_trip_and_validation():
    options = flexkin.ArmOptions(look_at=[1, 2, 3], pointing_axis=[0, 0, 1],
                                 pointing_weight=2.0, pointing_tolerance=1e-7, time_step=0.5)
    assert np.array_equal(options.look_at, [1, 2, 3]) and options.pointing_direction is None
    assert options.pointing_weight == 2.0 and options.pointing_tolerance == 1e-7
    assert options.time_step == 0.5
    back = pickle.loads(pickle.dumps(options))
    assert back == options and np.array_equal(back.look_at, [1, 2, 3])
    assert flexkin.ArmOptions().pointing_direction is None and flexkin.ArmOptions().look_at is None
    options.look_at = None
    assert options.look_at is None and options != back
    options.pointing_direction = [0, 1, 0]
    assert np.array_equal(options.pointing_direction, [0, 1, 0])

    with pytest.raises(flexkin.InputError) as info:
        flexkin.ArmOptions(pointing_direction=[0, 0, 0])
    assert info.value.field == "pointing_direction"
    with pytest.raises(ValueError) as info:
        flexkin.ArmOptions(pointing_direction=[1, 0, 0], look_at=[1, 1, 1])
    assert "pointing_direction" in str(info.value) and "look_at" in str(info.value)
    with pytest.raises(flexkin.InputError) as info:
        flexkin.ArmOptions(pointing_direction=[1, 0, 0], pointing_axis=[0, 0, 0])
    assert info.value.field == "pointing_axis"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.ArmOptions(look_at=[1, 0, 0], pointing_weight=0.0)
    assert info.value.field == "pointing_weight"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.ArmOptions(time_step=-1.0)
    assert info.value.field == "time_step"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.track_path(flexkin.ArmModel.straight(3, 4, 1.0), [[3.0, 1.0, 0.0]],
                           options={"pointing_direction": [1, 0, 0], "look_at": [0, 0, 1]})
    assert "look_at" in info.value.field
    with pytest.raises(flexkin.InputError) as info:
        flexkin.track_path(flexkin.ArmModel.straight(3, 4, 1.0), [[3.0, 1.0, 0.0]],
                           options={"pointing_direction": [0, 0, 0]})
    assert info.value.field == "options.pointing_direction" or \
        info.value.field == "pointing_direction"
    with pytest.raises(flexkin.InputError) as info:                # no tool frame
        flexkin.track_path(flexkin.ArmModel.straight(3, 4, 1.0), [[3.0, 1.0, 0.0]],
                           options={"pointing_direction": [1, 0, 0]})
    assert "pointing" in info.value.field


@needs_urdf
def test_a_floating_joint_is_refused_by_name():
    with pytest.raises(flexkin.InputError) as info:
        flexkin.arm_from_urdf(snake_urdf(floating=True))
    assert info.value.field == 'joint "roll"' and "floating" in str(info.value)
    with pytest.raises(flexkin.InputError) as info:
        flexkin.arm_from_urdf(snake_urdf(), tip_offset=[0.0, np.nan, 0.0])
    assert "tip_offset" in info.value.field


@needs_urdf
def test_a_scenario_dict_passes_tip_offset_pointing_and_time_step(tmp_path):
    (tmp_path / "snake.urdf").write_text(snake_urdf())
    scenario = {
        "format": "flexkin-robot", "urdf": "snake.urdf", "tip_offset": list(TIP_OFFSET),
        "pointing": {"direction": [1, 0, 0], "tolerance": 1e-9},
        "solver": {"time_step": 0.05},
        "path": {"type": "line", "to": [0.6, 0.05, 0.02], "steps": 10},
    }
    loaded = flexkin.load_robot_scenario(scenario, directory=tmp_path)
    assert np.array_equal(loaded.options.pointing_direction, [1, 0, 0])
    assert loaded.options.time_step == 0.05
    assert np.isclose(loaded.model.reach, MODULES * LINK + TIP_OFFSET[0])
    traj = flexkin.run_robot(scenario, directory=tmp_path, output=tmp_path / "t.json")
    assert traj.reached.all() and traj.max_pointing_error <= 1e-8
    assert traj.pointing_error.shape == (10,) and (traj.velocity_legs >= 1).all()
    assert traj.total_velocity_legs == traj.velocity_legs.sum()
    assert (traj.velocity_ratio <= 1.0 + 1e-9).all()
    import json
    steps = json.loads((tmp_path / "t.json").read_text())["steps"]
    assert [s["pointing_error"] for s in steps] == traj.pointing_error.tolist()
    assert [s["velocity_legs"] for s in steps] == traj.velocity_legs.tolist()
    assert [s["velocity_ratio"] for s in steps] == traj.velocity_ratio.tolist()


@needs_urdf
def test_the_joint_csv_is_headed_by_the_urdfs_joint_names(snake, tmp_path):
    path = circle(snake, 0.5, 4)
    flexkin.track_path(snake, path, csv=tmp_path / "j.csv")
    header = (tmp_path / "j.csv").read_text().splitlines()[0]
    assert header == "step," + ",".join(snake.joint_names)
    assert header.startswith("step,m0_pitch,m0_yaw,m1_pitch") and header.endswith(",roll")
    # An arm without names keeps joint_0, joint_1, ...
    plain = flexkin.ArmModel([0.1] * 3)
    flexkin.track_path(plain, [[0.25, 0.05]], csv=tmp_path / "p.csv")
    assert (tmp_path / "p.csv").read_text().splitlines()[0] == "step,joint_0,joint_1,joint_2"


@needs_urdf
def test_fixed_point_on_a_urdf_arm_fails_fast_and_warns(tmp_path):
    from conftest import EXAMPLES
    scenario = EXAMPLES / "robot_snake_urdf.json"
    with pytest.warns(RuntimeWarning, match=r"of 50 targets were not reached") as caught:
        traj = flexkin.run_robot(scenario, method="fixed_point")
    text = str(caught[0].message)
    assert "method fixed_point is the predecessors' baseline" in text
    assert "method newton (the default) is the one to use" in text
    assert traj.unreached > 0 and traj.unreached == (~traj.reached).sum()
    assert f"{traj.unreached} not reached" in repr(traj)
    # each stalled step stops after a few thousand sweeps, not 100000 (5.8 s before)
    assert traj.max_iterations <= 10000 and traj.total_sweeps < 100000
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert flexkin.run_robot(scenario).unreached == 0  # newton: no warning
