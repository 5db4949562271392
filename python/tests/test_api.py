"""The module's surface: every public name documented, every class printed, compared, copied and
pickled field for field (so that it travels to worker processes)."""
import concurrent.futures
import copy
import math
import multiprocessing
import os
import pickle
import re
import tempfile

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES, SOURCE_DIR

CLASSES = sorted(name for name in flexkin.__all__
                 if isinstance(getattr(flexkin, name), type)
                 and not issubclass(getattr(flexkin, name), Exception))
# Engines with state, not values: they neither pickle nor copy (a StrandBatch owns its threads).
ENGINES = {"StrandBatch"}
RENDER_CLASSES = {"AnimationOptions", "FigureOptions", "GltfOptions", "PlotOptions",
                  "ViewerOptions"}


def described(doc, name):
    """Whether `doc` says more than pybind11's signature lines."""
    lines = [line.strip() for line in (doc or "").splitlines() if line.strip()]
    signature = re.compile(r"^(\d+\. )?" + re.escape(name) + r"\(")
    return any(not signature.match(line) and line != "Overloaded function." for line in lines)


def public_members(cls):
    for klass in reversed(cls.__mro__[:-1]):        # the class and its bases, not object
        for name, value in vars(klass).items():
            if not name.startswith("_"):
                yield name, value


def test_all_lists_every_public_name_of_the_extension():
    exported = set(flexkin.__all__)
    assert len(exported) == len(flexkin.__all__)
    for name in dir(flexkin._flexkin):
        if not name.startswith("_"):
            assert name in exported, name
    for name in flexkin.__all__:
        assert hasattr(flexkin, name), name


@pytest.mark.parametrize("name", flexkin.__all__)
def test_every_public_name_is_documented(name):
    obj = getattr(flexkin, name)
    assert described(obj.__doc__, name), name
    if not isinstance(obj, type) or issubclass(obj, Exception):
        return
    for member, value in public_members(obj):
        doc = value.__doc__ if isinstance(value, property) else getattr(value, "__doc__", None)
        assert described(doc, member), f"{name}.{member} has no doc string"


def test_help_shows_parameters_shapes_and_defaults():
    assert "(T, dim)" in flexkin.track_path.__doc__ and "progress" in flexkin.track_path.__doc__
    assert "(n, 4)" in flexkin.joint_quaternions.__doc__
    assert "w, x, y, z" in flexkin.joint_quaternions.__doc__
    assert "(n*dim,)" in flexkin.overall_objective.__doc__
    assert "default 1e-12" in flexkin.OverallOptions.constraint_tolerance.__doc__
    assert "radians" in flexkin.ArmModel.joint_min.__doc__
    # the signatures name what each argument takes, not pybind11's "handle"
    for name in flexkin.__all__:
        obj = getattr(flexkin._flexkin, name, None)
        members = vars(obj).values() if isinstance(obj, type) else [obj]
        for member in members:
            if callable(member) and getattr(member, "__doc__", None):
                assert ": handle" not in member.__doc__.splitlines()[0], (name, member)
    assert "points: Union[ArrayLike, Chain]" in flexkin._flexkin.run.__doc__


def samples():
    """At least one instance of every class, with non-default values where it matters."""
    p = flexkin.parabola(links=8, link_length=0.25)
    controlled = flexkin.run(p, flexkin.split_pull(p[0], [0.5, 0.5], 4), tolerance=1e-3,
                             record_every=2)
    overall = flexkin.run_scenario(EXAMPLES / "fig11_parabola_overall.json")
    no_angles = flexkin.run(p, [[0.1, 0.0]], link_angles=False)
    _, report = flexkin.overall_step(p, [0.1, 0.1], options={"l2": 1})
    limited = flexkin.ArmModel([1.0] * 4, base=[0.5, -0.5], base_direction=[0, 1],
                               joint_min=[-1.0] * 4, joint_max=[1.0] * 4,
                               initial_angles=[0.1, 0.2, 0.3, 0.4])
    spherical = flexkin.ArmModel([1.0] * 5, dim=3, max_bend=[1.0] * 5,
                                 initial_angles=[0.1] * 5, initial_azimuths=[0.3] * 5)
    axes = flexkin.ArmModel([0.5] * 4, dim=3, joint_axes=[[0, 1, 0], [0, 0, 1]] * 2,
                            link_directions=[[1, 0, 0]] * 4)
    slide = flexkin.ArmModel([0.5, 0.0, 0.5], dim=3, joint_axes=[[0, 1, 0], [0, 0, 1], [1, 0, 0]],
                             joint_types=["revolute", "revolute", "prismatic"],
                             joint_min=[-1, -np.inf, -0.2], joint_max=[1, np.inf, 0.2],
                             max_velocity=[1.0, np.inf, 0.5], tip_rotation=[0, 0, 1, 0],
                             joint_names=["a", "b", "c"])
    first = flexkin.arm_step(spherical, [3.0, 1.0, 0.5])
    second = flexkin.arm_step(spherical, [3.0, 1.1, 0.6], state=first)
    robot = flexkin.run_robot(EXAMPLES / "robot_spatial_limits.json")
    with tempfile.TemporaryDirectory() as directory:
        groom_report = flexkin.run_groom(
            {"strands": [{"points": [[0, 0], [0, 1], [0, 2]]}],
             "motion": {"keyframes": [{"time": 0}, {"time": 1, "translation": [1, 0]}]}},
            os.path.join(directory, "h.npz"), threads=2)
    rope = flexkin.run_scenario(EXAMPLES / "rope_round_post.json")
    snake = flexkin.run_scenario(EXAMPLES / "snake_pegs.json")
    out = {
        "AccuracyReport": [controlled.accuracy],
        "ArmModel": [limited, spherical, axes, slide],
        "ArmOptions": [flexkin.ArmOptions(method="fixed_point", tolerance=1e-9, restarts=2,
                                          substeps=3, edge_margin=1e-6),
                       flexkin.ArmOptions(time_step=0.1, pointing_axis=[0, 0, 1],
                                          look_at=[1.0, 2.0, 3.0], pointing_weight=2.0),
                       flexkin.ArmOptions(pointing_direction=[0, 1, 0],
                                          pointing_tolerance=1e-7)],
        "ArmStepReport": [first, second],
        "Chain": [flexkin.Chain(p, link_length=0.25), flexkin.Chain(flexkin.helix(links=4))],
        "ContactReport": [rope.contacts],
        "Metrics": [controlled.metrics, overall.metrics],
        "ObjectiveWeights": [flexkin.ObjectiveWeights(rotation=0.5, l2_weighted=2)],
        "OverallOptions": [flexkin.OverallOptions(weights={"squared": 1, "joint_angle": 0.5},
                                                  max_iterations=7)],
        "OverallReport": [report],
        "OverallRunReport": [overall.overall],
        "PathReport": [snake.path],
        "Result": [controlled, overall, no_angles, rope, snake],
        "RobotResult": [robot, flexkin.run_robot(EXAMPLES / "robot_planar_8link.json")],
        "RobotScenario": [flexkin.load_robot_scenario(EXAMPLES / "robot_ravi_circle.json"),
                          flexkin.RobotScenario(limited, [[2.0, 2.0]], name="one target")],
        "RunOptions": [flexkin.RunOptions(method="overall", substeps=3, record_every=4,
                                          tolerance=0.0, max_substeps=8, link_angles=False,
                                          overall={"rotation": 0.5})],
        "Scenario": [flexkin.load_scenario(EXAMPLES / "fig12_spatial_curve.json")],
        "StrandOptions": [flexkin.StrandOptions(method="ftl", substeps=3, pinned=2, threads=0)],
        "StrandRunReport": [groom_report],
        "BodyPose": [flexkin.BodyPose.from_quaternion(0.9, 0.1, -0.3, 0.2, [1.0, 2.0, 3.0]),
                     flexkin.BodyPose.planar(0.25, -1.0, 0.5)],
    }
    if hasattr(flexkin._flexkin, "render"):
        out.update({
            "AnimationOptions": [flexkin.AnimationOptions(fps=12, crf=30, title="t")],
            "FigureOptions": [flexkin.FigureOptions(width=300, show_legend=False)],
            "GltfOptions": [flexkin.GltfOptions(tube_radius=0.1, tube_sides=5, up_axis="z")],
            "PlotOptions": [flexkin.PlotOptions(height=200)],
            "ViewerOptions": [flexkin.ViewerOptions(trail_points=[0, 3], digits=17,
                                                    autoplay=False)],
        })
    if hasattr(flexkin._flexkin, "arm_from_urdf"):
        out["ArmModel"].append(flexkin.arm_from_urdf(EXAMPLES / "robot_snake.urdf"))
    return out


SAMPLES = samples()


def assert_same_fields(a, b, where):
    """Every public attribute of a and b the same, bit for bit, recursively."""
    assert type(a) is type(b), where
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), where
    elif isinstance(a, float):
        assert a.hex() == b.hex() or (math.isnan(a) and math.isnan(b)), where
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same_fields(x, y, f"{where}[{i}]")
    elif type(a).__module__ == "flexkin":
        names = [n for n, v in public_members(type(a)) if isinstance(v, property)]
        assert names, where
        for name in names:
            assert_same_fields(getattr(a, name), getattr(b, name), f"{where}.{name}")
    else:
        assert a == b, where


def test_every_class_has_samples():
    assert sorted(SAMPLES) == [c for c in CLASSES if c not in ENGINES and (
        c not in RENDER_CLASSES or hasattr(flexkin._flexkin, "render"))]


def test_engines_refuse_pickling_and_copying():
    batch = flexkin.StrandBatch([flexkin.line(links=3)])
    for attempt in (pickle.dumps, copy.copy, copy.deepcopy):
        with pytest.raises(TypeError, match="cannot be pickled"):
            attempt(batch)
    text = repr(batch)
    assert text.startswith("StrandBatch(") and text.endswith(")") and "\n" not in text


@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_pickle_copy_repr_and_equality(name):
    for obj in SAMPLES[name]:
        for protocol in range(2, pickle.HIGHEST_PROTOCOL + 1):
            back = pickle.loads(pickle.dumps(obj, protocol=protocol))
            assert type(back) is type(obj) is getattr(flexkin, name)
            assert_same_fields(obj, back, name)
            assert back == obj and not (back != obj)
        assert_same_fields(obj, copy.deepcopy(obj), name)
        assert copy.copy(obj) == obj
        text = repr(obj)
        assert text.startswith(name + "(") and text.endswith(")") and "\n" not in text
        assert repr(pickle.loads(pickle.dumps(obj))) == text
        assert obj != 42 and obj != "x"


def test_equality_sees_every_field():
    options = flexkin.RunOptions(method="overall", overall={"rotation": 0.5})
    for field, value in (("substeps", 2), ("record_every", 3), ("tolerance", 1e-3),
                         ("max_substeps", 4), ("link_angles", False), ("method", "ftl"),
                         ("overall", {"rotation": 0.25})):
        other = copy.deepcopy(options)
        setattr(other, field, value)
        assert other != options, field
    first, second = SAMPLES["ArmStepReport"]
    assert first != second
    a, b = SAMPLES["Result"][:2]
    assert a != b


def test_an_unpickled_arm_step_continues_bit_for_bit():
    model = SAMPLES["ArmModel"][1]
    first = flexkin.arm_step(model, [3.0, 1.0, 0.5])
    second = flexkin.arm_step(model, [3.0, 1.1, 0.6], state=first)
    again = flexkin.arm_step(model, [3.0, 1.1, 0.6], state=pickle.loads(pickle.dumps(first)))
    assert_same_fields(second, again, "ArmStepReport")
    assert second == again


def test_bad_pickled_states_are_refused():
    for name, state in (("RunOptions", ("tractrix",)), ("Chain", (np.zeros((3, 2)), [1.0])),
                        ("ArmModel", (2, [1.0], [0.0, 0.0], [0.0, 0.0], None, None, None, None,
                                      None, [0.0], None)),
                        ("Result", SAMPLES["Result"][0].__getstate__()[:3] + (
                            np.zeros((2, 3, 2)),) + SAMPLES["Result"][0].__getstate__()[4:])):
        cls = getattr(flexkin, name)
        obj = cls.__new__(cls)
        with pytest.raises((flexkin.InputError, TypeError, RuntimeError)):
            obj.__setstate__(state)


def work_in_another_process(options, model, scenario):
    """Runs in a worker process: the options and models arrive pickled, the results go back."""
    return (flexkin.run_scenario(scenario), flexkin.track_path(model, [[2.0, 2.0], [2.5, 1.0]],
                                                               options=options))


def test_objects_travel_to_worker_processes():
    options = flexkin.ArmOptions(tolerance=1e-11)
    model = SAMPLES["ArmModel"][0]
    scenario = flexkin.load_scenario(EXAMPLES / "fig06_parabola_multi_step.json")
    scenario.options.substeps = 3
    here = work_in_another_process(options, model, scenario)
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=context) as pool:
        there = pool.submit(work_in_another_process, options, model, scenario).result(timeout=60)
    for a, b in zip(here, there):
        assert type(a) is type(b)
        for key in ("frames", "angles", "points"):
            if hasattr(a, key):
                assert getattr(a, key).tobytes() == getattr(b, key).tobytes()


def stub_tree():
    import ast
    return ast.parse((SOURCE_DIR / "python" / "flexkin" / "__init__.pyi").read_text())


def stub_classes():
    import ast
    classes = {}
    for node in stub_tree().body:
        if isinstance(node, ast.ClassDef):
            names = set()
            for item in node.body:
                if isinstance(item, ast.AnnAssign):
                    names.add(item.target.id)
                elif isinstance(item, ast.FunctionDef) and not item.name.startswith("_"):
                    names.add(item.name)
            classes[node.name] = names
    return classes


def pybind_parameters(function):
    """The parameter names of a pybind11 function, from the signature line of its doc."""
    first = function.__doc__.splitlines()[0]
    inside = first[first.index("(") + 1:first.rindex(")")]
    parts, depth, current = [], 0, ""
    for char in inside:                              # split at the commas outside brackets
        depth += {"[": 1, "]": -1}.get(char, 0)
        if char == "," and depth == 0:
            parts.append(current)
            current = ""
        else:
            current += char
    parts.append(current)
    names = []
    for part in parts:
        name = part.split(":")[0].split("=")[0].strip()
        if name and name not in ("*", "self"):
            names.append(name)
    return names


def test_the_stubs_have_every_class_member():
    classes = stub_classes()
    for name in CLASSES:
        cls = getattr(flexkin, name)
        if not isinstance(cls, type):
            continue
        public = {member for member, _ in public_members(cls)}
        assert public == classes[name], (name, public ^ classes[name])


def test_the_stubs_have_every_function_parameter():
    import ast
    stubs = {node.name: node for node in stub_tree().body if isinstance(node, ast.FunctionDef)}
    for name in flexkin.__all__:
        function = getattr(flexkin._flexkin, name, None)
        if function is None or isinstance(function, type):
            continue
        args = stubs[name].args
        stub_names = [a.arg for a in args.posonlyargs + args.args + args.kwonlyargs]
        assert stub_names == pybind_parameters(function), name
