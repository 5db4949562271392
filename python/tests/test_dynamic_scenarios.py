"""Dynamic chains through the one front door (docs/dynamics.md, docs/scenario-format.md
"dynamics"): run_scenario of a scenario with "dynamics" (a path, a dict or a loaded Scenario) is
`flexkin run`'s result bit for bit, with the energy at every frame; mistakes are named by JSON
pointer and nothing is written."""
import json
import subprocess

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES

ROPE = EXAMPLES / "rope_fall.json"


def small_rope(**dynamics):
    return {"name": "small_rope",
            "curve": {"shape": "line", "links": 4, "link_length": 0.25},
            "leader": {"pull": [0, 0], "steps": 40},
            "dynamics": {"gravity": [0, -9.81], **dynamics}}


def test_dynamic_scenario_runs_and_falls(tmp_path):
    result = flexkin.run_scenario(ROPE, output=tmp_path / "rope.npz")
    assert result.frames.shape == (181, 41, 2)
    assert list(result.steps) == list(range(181))
    assert result.link_angles is None
    d = result.dynamics
    assert d["projection"] == "overall" and d["frame_rate"] == 60 and d["substeps"] == 4
    assert d["energy"].shape == (181,)
    assert d["energy"][-1] < d["energy"][0] - 1.0          # the rope fell
    assert np.array_equal(result.frames[:, 0], np.zeros((181, 2)))  # its first point held
    assert result.frames[-1, -1, 1] < -0.5
    assert "dynamic, projection overall" in result.brief_report()
    # The file written is the same run; numpy reads it, the energy in result.json.
    archive = np.load(tmp_path / "rope.npz")
    assert np.array_equal(archive["frames"], result.frames)
    info = json.loads(archive["result.json"])
    assert info["dynamics"]["energy"] == list(d["energy"])
    # A kinematic run has none.
    assert flexkin.run_scenario(EXAMPLES / "fig07_straight_link.json").dynamics is None


def test_python_equals_command_line_bit_for_bit(tmp_path, cli):
    subprocess.run([cli, "run", str(ROPE), "-o", str(tmp_path / "cli.npz"), "--quiet"],
                   check=True)
    from_cli = flexkin.read_result(tmp_path / "cli.npz")
    from_python = flexkin.run_scenario(ROPE)
    assert np.array_equal(from_cli.frames, from_python.frames)
    assert np.array_equal(from_cli.dynamics["energy"], from_python.dynamics["energy"])
    # A dict and a loaded Scenario are the same run.
    with open(ROPE) as f:
        as_dict = flexkin.run_scenario(json.load(f))
    assert np.array_equal(as_dict.frames, from_python.frames)
    loaded = flexkin.load_scenario(ROPE)
    assert "dynamic: 180 frames at 60 fps" in loaded.summary()
    assert np.array_equal(flexkin.run_scenario(loaded).frames, from_python.frames)


@pytest.mark.parametrize("projection", ["overall", "tractrix", "dftl", "shake"])
def test_every_projection_and_record_every(projection, tmp_path):
    scenario = small_rope(projection=projection, substeps=2, damping=0.5)
    scenario["record"] = {"every": 10}
    result = flexkin.run_scenario(scenario, output=tmp_path / "r.json", csv=tmp_path / "r.csv")
    assert list(result.steps) == [0, 10, 20, 30, 40]
    assert result.dynamics["projection"] == projection
    assert result.dynamics["energy"].shape == (41,)
    back = flexkin.read_result(tmp_path / "r.json")
    assert np.array_equal(back.frames, result.frames)
    assert np.array_equal(back.dynamics["energy"], result.dynamics["energy"])
    lengths = np.linalg.norm(np.diff(result.frames, axis=1), axis=2)
    assert np.allclose(lengths, 0.25, rtol=1e-9, atol=0)


@pytest.mark.parametrize("change, pointer", [
    ({"dynamics": {"gravity": [0, -9.81], "projection": "shak"}}, "/dynamics/projection"),
    ({"dynamics": {"damping": 1}}, "/dynamics/gravity"),
    ({"dynamics": {"gravity": [0, -9.81], "mass": [1, 2]}}, "/dynamics/mass"),
    ({"dynamics": {"gravity": [0, -9.81], "wind_keys": [{"time": 1, "velocity": [0, 0]},
                                                        {"time": 0, "velocity": [0, 0]}]}},
     "/dynamics/wind_keys/1/time"),
    ({"method": "overall"}, "/method"),
    ({"accuracy": {"tolerance": 1e-6}}, "/accuracy/tolerance"),
])
def test_mistakes_are_named_and_nothing_is_written(change, pointer, tmp_path):
    scenario = small_rope()
    scenario.update(change)
    assert pointer in [p["field"] for p in flexkin.validate_scenario(scenario)]
    with pytest.raises(flexkin.InputError) as error:
        flexkin.run_scenario(scenario, output=tmp_path / "r.json")
    assert error.value.field == pointer
    assert list(tmp_path.iterdir()) == []
