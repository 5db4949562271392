"""Colliders through flexkin.run and RunOptions (docs/colliders.md): the scenario's form of each
collider as a list of dicts, read by the scenario reader itself, so a run from Python is the
scenario file's run bit for bit; keyframed colliders ("motion", times in leader steps) included;
the overall method's L2 metric among them; mistakes named by JSON pointer."""
import json

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES


def scenario_and_colliders(name):
    with open(EXAMPLES / name) as f:
        text = json.load(f)
    scenario = flexkin.load_scenario(EXAMPLES / name)
    return scenario, text["colliders"]


@pytest.mark.parametrize("name", ["rope_round_post.json", "rope_swept.json"])
def test_run_with_colliders_is_the_scenario_run_bit_for_bit(name):
    scenario, colliders = scenario_and_colliders(name)
    from_file = flexkin.run_scenario(EXAMPLES / name)
    options = scenario.options
    from_python = flexkin.run(scenario.chain, scenario.leader_steps, method=options.method,
                              substeps=options.substeps, colliders=colliders)
    assert np.array_equal(from_python.frames, from_file.frames)
    assert from_python.contacts.contact_link_steps == from_file.contacts.contact_link_steps
    assert from_python.contacts.contact_link_steps > 0
    assert from_python.contacts.least_clearance >= -1e-12


def test_a_moving_collider_pushes_the_rope_and_reads_back_with_its_motion():
    scenario, colliders = scenario_and_colliders("rope_swept.json")
    options = flexkin.RunOptions(substeps=4, colliders=colliders)
    back = options.colliders
    assert len(back) == 1 and back[0]["shape"] == "sphere"
    assert back[0]["motion"]["interpolation"] == "linear"
    assert [k["time"] for k in back[0]["motion"]["keyframes"]] == [10, 130]
    pushed = flexkin.run(scenario.chain, scenario.leader_steps, substeps=4, colliders=back)
    free = flexkin.run(scenario.chain, scenario.leader_steps, substeps=4)
    # The free rope stays on the line y = 0; the ball pushes the pushed one off it.
    assert np.abs(free.frames[..., 1]).max() < 1e-12
    assert np.abs(pushed.frames[..., 1]).max() > 0.1
    lengths = np.linalg.norm(np.diff(pushed.frames, axis=1), axis=2)
    assert np.abs(lengths - 0.05).max() < 1e-13


def test_bad_colliders_are_named_by_json_pointer():
    p = [[0.0, 0.0], [0.0, -1.0]]
    with pytest.raises(flexkin.InputError, match=r"/colliders/0/radius"):
        flexkin.run(p, [[0.0, 1.0]], colliders=[{"shape": "sphere", "center": [3, 0],
                                                  "radius": -1}])
    with pytest.raises(flexkin.InputError, match=r"/colliders/0/motion/keyframes/1/time"):
        flexkin.RunOptions(colliders=[{"shape": "sphere", "center": [3, 0], "radius": 1,
                                       "motion": {"keyframes": [{"time": 2}, {"time": 1}]}}])
    with pytest.raises(flexkin.InputError, match=r"colliders"):
        flexkin.RunOptions(colliders={"shape": "sphere"})
    with pytest.raises(flexkin.InputError, match=r"points\[1\].*inside"):
        flexkin.run(p, [[0.0, 1.0]], colliders=[{"shape": "sphere", "center": [0, -1],
                                                  "radius": 0.5}])


def test_the_overall_l2_metric_slides_round_the_post_through_the_front_door():
    # The paper's L2 metric with colliders (docs/colliders.md, "The L2 metric"): the rope of
    # rope_round_post.json, every link outside the post in every frame, the lengths kept.
    scenario, colliders = scenario_and_colliders("rope_round_post.json")
    steps = scenario.leader_steps
    free = flexkin.run(scenario.chain, steps, method="overall",
                       overall=flexkin.ObjectiveWeights(l2=1))
    result = flexkin.run(scenario.chain, steps, method="overall",
                         overall=flexkin.ObjectiveWeights(l2=1), colliders=colliders)
    assert result.overall.failures == 0
    assert result.contacts.contact_link_steps > 0
    assert result.contacts.least_clearance >= -1e-12
    center, radius = np.array([-0.35, 1.65]), 0.3
    s = np.linspace(0.0, 1.0, 51)[None, None, :, None]
    a, b = result.frames[:, :-1, None, :], result.frames[:, 1:, None, :]
    assert np.linalg.norm(a + s * (b - a) - center, axis=-1).min() >= radius - 1e-12
    a, b = free.frames[:, :-1, None, :], free.frames[:, 1:, None, :]
    assert np.linalg.norm(a + s * (b - a) - center, axis=-1).min() < radius - 0.05
    lengths = np.linalg.norm(np.diff(result.frames, axis=1), axis=2)
    assert np.abs(lengths - 0.05).max() < 1e-13
    # A moving collider is refused by name for it.
    moving = [dict(colliders[0], motion={"keyframes": [{"time": 0, "translation": [0, 0]},
                                                       {"time": 5, "translation": [0.1, 0]}]})]
    with pytest.raises(flexkin.InputError, match=r"overall.weights.l2"):
        flexkin.run(scenario.chain, steps, method="overall",
                    overall=flexkin.ObjectiveWeights(l2=1), colliders=moving)
