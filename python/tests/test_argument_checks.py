"""Every binding's argument checking, from one table of the array arguments.

Each array argument is given every kind of bad value (wrong dimensions, sizes, dtypes that
cannot be real numbers, NaN and infinities, empty arrays, None where it is required): each must
be refused with flexkin.InputError naming the argument, without a crash. And every form of a
good value (lists, tuples, strided views, Fortran order, read-only arrays) must give the result
of the plain C-contiguous float64 array bit for bit, leaving the input unchanged.
"""
import math

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES

P2 = flexkin.parabola(a=1.0, links=5, link_length=0.25)
P3 = flexkin.helix(links=4, link_length=1.0)
L2 = np.linalg.norm(np.diff(P2, axis=0), axis=1)
STEPS2 = flexkin.split_pull(P2[0], [0.3, 0.1], 3)
ARM2 = flexkin.ArmModel.straight(2, 4, 1.0)
ARM3 = flexkin.ArmModel([1.0] * 4, dim=3)
AXES = np.array([[0.0, 1, 0], [0, 0, 1], [0, 1, 0], [0, 0, 1]])
ARM_AXES = flexkin.ArmModel([0.5] * 4, dim=3, joint_axes=AXES)
ANGLES = np.array([0.1, -0.2, 0.3, -0.1])
AZIMUTHS = np.array([0.5, 1.0, -1.0, 2.0])
MOVED = flexkin.overall_step(P2, [0.1, 0.05])[0]


def chain_moved(target):
    chain = flexkin.Chain(P2)
    chain.move_leader(target, substeps=2)
    return chain.points


def chain_overall(head):
    chain = flexkin.Chain(P2)
    chain.overall_step(head)
    return chain.points


def scenario_steps(steps):
    scenario = flexkin.load_scenario(EXAMPLES / "fig10_planar_curve.json")
    scenario.leader_steps = steps
    return scenario.leader_steps


def robot_path(path):
    return flexkin.RobotScenario(ARM2, path).path


def points_of(model):
    return flexkin.forward_kinematics(model, ANGLES)


# (id, call(value), good value, argument name, flags): flags "optional" (None is valid),
# "any size" (a 1-D argument of any length >= 1), "any rows" (2-D with any number of rows >= 1).
ARRAYS = [
    ("Chain.points", lambda v: flexkin.Chain(v).points, P2, "points", "any rows"),
    ("Chain.lengths", lambda v: flexkin.Chain(P2, lengths=v).lengths, L2, "lengths", "optional"),
    ("line.start", lambda v: flexkin.line(start=v, direction=[1, 2]), [0.5, 0.25], "start",
     "optional"),
    ("line.direction", lambda v: flexkin.line(start=[0, 0], direction=v), [1.0, 2.0],
     "direction", "optional"),
    ("arc.center", lambda v: flexkin.arc(center=v), [0.5, 0.25], "center", ""),
    ("helix.center", lambda v: flexkin.helix(center=v), [0.5, 0.25, 1.0], "center", ""),
    ("split_pull.start", lambda v: flexkin.split_pull(v, [1, 0.5], 3), [0.5, 0.25], "start", ""),
    ("split_pull.pull", lambda v: flexkin.split_pull([0, 0], v, 3), [1.0, 0.5], "pull", ""),
    ("resample_path.start", lambda v: flexkin.resample_path(v, [[1, 1]], 0.3), [0.5, 0.25],
     "start", ""),
    ("resample_path.path", lambda v: flexkin.resample_path([0, 0], v, 0.3),
     np.array([[1.0, 1.0], [2.0, 0.5], [2.5, 0.0]]), "path", "any rows"),
    ("tractrix_step.head_old", lambda v: flexkin.tractrix_step(v, [1, 0.5], [0, 1], 1.0),
     [0.1, 0.2], "head_old", ""),
    ("tractrix_step.head_new", lambda v: flexkin.tractrix_step([0, 0], v, [0, 1], 1.0),
     [1.0, 0.5], "head_new", ""),
    ("tractrix_step.tail", lambda v: flexkin.tractrix_step([0, 0], [1, 0.5], v, 1.0),
     [0.0, 1.0], "tail", ""),
    ("follow_the_leader_step.head_new",
     lambda v: flexkin.follow_the_leader_step([0, 0], v, [0, 1], 1.0), [1.0, 0.5], "head_new", ""),
    ("follow_the_leader_step.tail",
     lambda v: flexkin.follow_the_leader_step([0, 0], [1, 0.5], v, 1.0), [0.0, 1.0], "tail", ""),
    ("move_leader.points", lambda v: flexkin.move_leader(v, [0.2, 0.1]), P2, "points", "any rows"),
    ("move_leader.target", lambda v: flexkin.move_leader(P2, v, method="min_joint_angle"),
     [0.2, 0.1], "target", ""),
    ("Chain.move_leader.target", chain_moved, [0.2, 0.1], "target", ""),
    ("overall_step.points", lambda v: flexkin.overall_step(v, [0.1, 0.05])[0], P2, "points",
     "any rows"),
    ("overall_step.head", lambda v: flexkin.overall_step(P2, v)[0], [0.1, 0.05], "head", ""),
    ("Chain.overall_step.head", chain_overall, [0.1, 0.05], "head", ""),
    ("run.points", lambda v: flexkin.run(v, STEPS2).frames, P2, "points", "any rows"),
    ("run.leader_steps", lambda v: flexkin.run(P2, v, method="ftl").frames, STEPS2,
     "leader_steps", "any rows"),
    ("Scenario.leader_steps", scenario_steps, STEPS2, "leader_steps", "any rows"),
    ("ArmModel.link_lengths", lambda v: flexkin.ArmModel(v), [1.0, 0.5, 0.25], "link_lengths",
     "any size"),
    ("ArmModel.base", lambda v: flexkin.ArmModel([1.0, 1.0], base=v), [0.5, 0.25], "base",
     "optional"),
    ("ArmModel.base_direction", lambda v: flexkin.ArmModel([1.0, 1.0], base_direction=v),
     [0.0, 1.0], "base_direction", "optional"),
    ("ArmModel.joint_min",
     lambda v: flexkin.ArmModel([1.0, 1.0], joint_min=v, joint_max=[1.0, 1.0]), [-1.0, -0.5],
     "joint_min", "optional"),
    ("ArmModel.joint_max",
     lambda v: flexkin.ArmModel([1.0, 1.0], joint_min=[-1.0, -1.0], joint_max=v), [1.0, 0.5],
     "joint_max", "optional"),
    ("ArmModel.max_bend", lambda v: flexkin.ArmModel([1.0, 1.0], dim=3, max_bend=v), [1.0, 0.5],
     "max_bend", "optional"),
    ("ArmModel.joint_axes", lambda v: flexkin.ArmModel([0.5] * 4, dim=3, joint_axes=v), AXES,
     "joint_axes", "optional"),
    ("ArmModel.link_directions",
     lambda v: flexkin.ArmModel([0.5] * 4, dim=3, joint_axes=AXES, link_directions=v),
     np.tile([1.0, 0.0, 0.0], (4, 1)), "link_directions", "optional"),
    ("ArmModel.initial_angles", lambda v: flexkin.ArmModel([1.0] * 4, initial_angles=v), ANGLES,
     "initial_angles", "optional"),
    ("ArmModel.initial_azimuths",
     lambda v: flexkin.ArmModel([1.0] * 4, dim=3, initial_angles=np.abs(ANGLES),
                                initial_azimuths=v), AZIMUTHS, "initial_azimuths", "optional"),
    ("forward_kinematics.angles", lambda v: flexkin.forward_kinematics(ARM2, v), ANGLES,
     "angles", ""),
    ("forward_kinematics.azimuths",
     lambda v: flexkin.forward_kinematics(ARM3, np.abs(ANGLES), v), AZIMUTHS, "azimuths", ""),
    ("joint_angles_from_points.points", lambda v: flexkin.joint_angles_from_points(ARM2, v),
     points_of(ARM2), "points", ""),
    ("joint_quaternions.angles", lambda v: flexkin.joint_quaternions(ARM_AXES, v), ANGLES,
     "angles", ""),
    ("joint_quaternions.azimuths",
     lambda v: flexkin.joint_quaternions(ARM3, np.abs(ANGLES), v), AZIMUTHS, "azimuths", ""),
    ("within_limits.angles",
     lambda v: flexkin.within_limits(flexkin.ArmModel([1.0] * 4, joint_min=[-0.2] * 4,
                                                      joint_max=[0.2] * 4), v),
     ANGLES, "angles", ""),
    ("arm_step.target", lambda v: flexkin.arm_step(ARM2, v).points, [3.0, 1.0], "target", ""),
    ("track_path.path", lambda v: flexkin.track_path(ARM2, v).angles,
     np.array([[3.0, 1.0], [3.0, 1.5]]), "path", "any rows"),
    ("RobotScenario.path", robot_path, np.array([[3.0, 1.0], [3.0, 1.5]]), "path", "any rows"),
    ("overall_objective.lengths",
     lambda v: flexkin.overall_objective({"squared": 1, "rotation": 1}, v, P2, MOVED,
                                         gradient=True), L2, "lengths", "any size"),
    ("overall_objective.old_points",
     lambda v: flexkin.overall_objective({"squared": 1}, L2, v, MOVED, hessian=True), P2,
     "old_points", "any rows"),
    ("overall_objective.new_points",
     lambda v: flexkin.overall_objective({"l2_weighted": 1}, L2, P2, v), MOVED, "new_points", ""),
]
IDS = [entry[0] for entry in ARRAYS]


def same(a, b):
    """Bit for bit: arrays by dtype, shape and bytes; tuples item by item; others by ==."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()
    if isinstance(a, tuple):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, float):
        return a.hex() == b.hex()
    return a == b


def bad_values(good, flags):
    """(kind, value, field) for every kind of bad value of an argument whose good value is
    `good`; field is the name suffix the refusal must carry ('' the argument, '[0]' ...)."""
    good = np.asarray(good, dtype=float)
    first = "[0]" * good.ndim
    out = [
        ("one more dimension", good[..., np.newaxis], ""),
        ("strings", np.full(good.shape, "a"), ""),
        ("bytes", np.full(good.shape, b"1"), ""),
        ("objects", good.astype(object), ""),
        ("complex", good.astype(complex), ""),
        ("bool", good.astype(bool), ""),
        ("a string", "1, 2", ""),
        ("a dict", {"x": 1.0}, ""),
        ("empty", np.zeros((0,) + good.shape[1:]), ""),
        ("empty list", [], ""),
    ]
    for kind, value in (("nan", np.nan), ("inf", np.inf), ("-inf", -np.inf)):
        array = good.copy()
        array[(0,) * good.ndim] = value
        out.append((kind, array, first))
    if "optional" not in flags:
        out.append(("None", None, ""))
    if good.ndim == 2:
        out.append(("four columns", np.zeros((good.shape[0], 4)), ""))
        out.append(("ragged", [[0.0, 0.0], [1.0]], ""))
        if "any rows" not in flags:
            out.append(("one row more", np.vstack([good, good[-1:]]), ""))
    elif "any size" not in flags:
        out.append(("two values more", np.ones(good.size + 2), ""))
    return out


BAD = [(entry, kind, value, suffix) for entry in ARRAYS
       for kind, value, suffix in bad_values(entry[2], entry[4])]


@pytest.mark.parametrize("entry, kind, value, suffix", BAD,
                         ids=[f"{e[0]}-{kind}" for e, kind, _, _ in BAD])
def test_bad_array_refused_naming_the_argument(entry, kind, value, suffix):
    _, call, _, name, _ = entry
    with pytest.raises(flexkin.InputError) as info:
        call(value)
    e = info.value
    assert isinstance(e, ValueError) and str(e).startswith(e.field) and e.message
    if suffix:
        assert e.field == name + suffix, (e.field, str(e))
    else:
        assert e.field == name or e.field.startswith(name + "["), (e.field, str(e))


def good_forms(good):
    """Every form of a good value: list, tuple, strided view, Fortran order, read-only."""
    good = np.asarray(good, dtype=float)
    wide = np.zeros(good.shape[:-1] + (2 * good.shape[-1],))
    wide[..., ::2] = good
    strided = wide[..., ::2]
    assert not strided.flags.c_contiguous
    readonly = good.copy()
    readonly.flags.writeable = False
    forms = [("list", good.tolist()), ("strided", strided),
             ("fortran", np.asfortranarray(good)), ("readonly", readonly),
             ("reversed twice", good[::-1][::-1])]
    if good.ndim == 2:
        forms.append(("tuple", tuple(map(tuple, good))))
        forms.append(("transposed view", np.ascontiguousarray(good.T).T))
    else:
        forms.append(("tuple", tuple(good)))
    return forms


@pytest.mark.parametrize("entry", ARRAYS, ids=IDS)
def test_every_form_of_a_good_array_gives_the_same_result(entry):
    _, call, good, _, _ = entry
    reference = call(np.ascontiguousarray(good, dtype=float))
    for kind, value in good_forms(good):
        before = np.array(value, dtype=float, copy=True)
        assert same(call(value), reference), kind
        assert np.array_equal(np.asarray(value, dtype=float), before), kind   # not modified


@pytest.mark.parametrize("call, field", [
    (lambda: flexkin.tractrix_step([0, 0], [1, 0], [0, 1], math.nan), "length"),
    (lambda: flexkin.follow_the_leader_step([0, 0], [1, 0], [0, 1], math.inf), "length"),
    (lambda: flexkin.parabola(a=math.nan), "a"),
    (lambda: flexkin.parabola(link_length=math.inf), "link_length"),
    (lambda: flexkin.arc(radius=math.nan), "radius"),
    (lambda: flexkin.helix(pitch=math.inf), "pitch"),
    (lambda: flexkin.line(link_length=math.nan), "link_length"),
    (lambda: flexkin.resample_path([0, 0], [[1, 1]], math.nan), "max_step"),
    (lambda: flexkin.Chain(P2, link_length=math.nan), "link_length"),
    (lambda: flexkin.run(P2, STEPS2, tolerance=math.inf), "tolerance"),
    (lambda: flexkin.run(P2, STEPS2, method="overall", overall={"squared": math.nan}),
     "squared"),
    (lambda: flexkin.within_limits(ARM2, ANGLES, slack=math.nan), "slack"),
    (lambda: flexkin.ArmOptions(tolerance=math.nan), "tolerance"),
    (lambda: flexkin.ArmOptions(edge_margin=-1.0), "edge_margin"),
    (lambda: flexkin.ArmModel.straight(2, 3, math.nan), "link_lengths[0]"),
    (lambda: flexkin.ArmModel.straight(2, -1, 1.0), "links"),
    (lambda: flexkin.ArmModel.straight(2, 0, 1.0), "links"),
    (lambda: flexkin.ArmModel.straight(4, 3, 1.0), "dim"),
    (lambda: flexkin.ArmModel([1.0], dim=1), "dim"),
    (lambda: flexkin.overall_objective({"rotation": math.inf}, L2, P2, MOVED), "rotation"),
    (lambda: flexkin.overall_objective(flexkin.ObjectiveWeights(l2=math.inf), L2, P2, MOVED),
     "l2"),
    (lambda: flexkin.estimate_output(0, 2, 10), "num_links"),
    (lambda: flexkin.estimate_output(5, 4, 10), "dim"),
    (lambda: flexkin.estimate_output(5, 2, -1), "num_steps"),
    (lambda: flexkin.estimate_output(5, 2, 10, record_every=0), "record_every"),
])
def test_bad_numbers_refused(call, field):
    with pytest.raises(flexkin.InputError) as info:
        call()
    assert info.value.field == field or info.value.field.endswith("." + field), str(info.value)


def weights_object_with_nan():
    weights = flexkin.ObjectiveWeights()
    weights.rotation = math.nan
    return weights


@pytest.mark.parametrize("call, field", [
    (lambda: flexkin.forward_kinematics("arm", ANGLES), "model"),
    (lambda: flexkin.joint_quaternions(None, ANGLES), "model"),
    (lambda: flexkin.track_path(P2, [[1, 1]]), "model"),
    (lambda: flexkin.arm_step(ARM2, [3, 1], state=P2), "state"),
    (lambda: flexkin.arm_step(ARM2, [3, 1], options="newton"), "options"),
    (lambda: flexkin.arm_step(ARM2, [3, 1], options={"tolerance": "tight"}), "options.tolerance"),
    (lambda: flexkin.arm_step(ARM2, [3, 1], options={"method": "newtn"}), "options.method"),
    (lambda: flexkin.track_path(ARM2, [[3, 1]], options={"bogus": 1}), "options.bogus"),
    (lambda: flexkin.track_path(ARM2, [[3, 1]], output=3), "output"),
    (lambda: flexkin.run_robot(EXAMPLES / "robot_planar_8link.json", csv=[1]), "csv"),
    (lambda: flexkin.run_robot({"arm": {}}, directory=3), "directory"),
    (lambda: flexkin.run_robot(3.5), "scenario"),
    (lambda: flexkin.load_robot_scenario([1, 2]), "scenario"),
    (lambda: flexkin.RobotScenario("arm", [[1, 1]]), "model"),
    (lambda: flexkin.overall_objective(3, L2, P2, MOVED), "weights"),
    (lambda: flexkin.overall_objective(weights_object_with_nan(), L2, P2, MOVED),
     "weights.rotation"),
    (lambda: flexkin.overall_objective({"bogus": 1}, L2, P2, MOVED), "bogus"),
    (lambda: flexkin.overall_objective({"squared": 1}, -L2, P2, MOVED), "lengths[0]"),
    (lambda: flexkin.overall_step(P2, [0.1, 0.1], options=[1]), "overall"),
    (lambda: flexkin.OverallOptions(weights=flexkin.OverallOptions()), "weights"),
    (lambda: flexkin.write_result(flexkin.run(P2, STEPS2), 3), "path"),
    (lambda: flexkin.read_result(None), "path"),
    (lambda: flexkin.validate_scenario(3), "scenario"),
    (lambda: flexkin.Chain(P2, link_length=0.25, lengths=L2), "lengths"),
    (lambda: flexkin.forward_kinematics(ARM2, ANGLES, AZIMUTHS), "azimuths"),
    (lambda: flexkin.forward_kinematics(ARM3, ANGLES), "azimuths"),
    (lambda: flexkin.joint_quaternions(ARM_AXES, ANGLES, AZIMUTHS), "azimuths"),
    (lambda: flexkin.within_limits(ARM2, ANGLES, AZIMUTHS), "azimuths"),
    # overall_objective: old_points sets n; lengths and new_points must agree with it
    (lambda: flexkin.overall_objective({"squared": 1}, L2[:-1], P2, MOVED), "lengths"),
    (lambda: flexkin.overall_objective({"squared": 1}, L2, P2, MOVED[:-1]), "new_points"),
    (lambda: flexkin.overall_objective({"squared": 1}, L2, P2, P3), "new_points"),
])
def test_bad_objects_refused(call, field):
    with pytest.raises(flexkin.InputError) as info:
        call()
    assert info.value.field == field, str(info.value)


def test_scenario_dicts_take_numpy_arrays_and_refuse_what_json_cannot_hold():
    as_lists = {"curve": {"points": P2.tolist()},
                "leader": {"path": STEPS2.tolist()}}
    as_arrays = {"curve": {"points": P2},
                 "leader": {"path": STEPS2}}
    assert same(flexkin.run_scenario(as_arrays).frames, flexkin.run_scenario(as_lists).frames)
    with pytest.raises(flexkin.InputError) as info:
        flexkin.run_scenario({"curve": {"points": P2}, "leader": object()})
    assert info.value.field == "scenario"
    bad = {"curve": {"points": np.full((3, 2), np.nan)},
           "leader": {"path": STEPS2}}
    with pytest.raises(flexkin.InputError):
        flexkin.run_scenario(bad)
