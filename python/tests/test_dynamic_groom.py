"""Dynamic strands through the front door (docs/dynamics.md "Strands", docs/groom-format.md
"dynamics"): run_groom of a groom with "dynamics" writes the strand file `flexkin run` writes, bit
for bit, with the energy of every recorded frame; the projection can be overridden; mistakes are
named and nothing is written."""
import json
import math
import subprocess

import numpy as np
import pytest

import flexkin


def small_groom(**dynamics):
    return {"name": "small_dynamic_groom",
            "strands": [{"points": [[0, 0, 1], [0, 0.05, 1.05], [0, 0.1, 1.1], [0, 0.15, 1.15]]},
                        {"points": [[1, 0, 0], [1.05, 0, 0.05], [1.1, 0, 0.1]]}],
            "motion": {"fps": 30, "keyframes": [
                {"time": 0}, {"time": 1, "rotation": {"axis": [0, 0, 1], "angle_deg": 40}}]},
            "colliders": [{"shape": "sphere", "center": [0, 0, 0], "radius": 0.9}],
            "record": {"precision": "float64"},
            "dynamics": {"gravity": [0, 0, -9.81], "damping": 0.5, **dynamics}}


def test_run_groom_is_flexkin_run_and_the_hair_falls(tmp_path, cli):
    scenario = tmp_path / "groom.json"
    scenario.write_text(json.dumps(small_groom(projection="tractrix")))
    report = flexkin.run_groom(scenario, tmp_path / "python.npz", threads=1)
    subprocess.run([cli, "run", str(scenario), "-o", str(tmp_path / "cli.npz"), "--threads", "1",
                    "--quiet"], check=True)
    ours, theirs = np.load(tmp_path / "python.npz"), np.load(tmp_path / "cli.npz")
    assert np.array_equal(ours["points"], theirs["points"])
    info = json.loads(bytes(ours["groom.json"]).decode())
    assert info["dynamics"]["projection"] == "tractrix"
    energy = info["report"]["energy"]
    assert energy[0] is None and len(energy) == 31
    assert report.energy[1:] == energy[1:] and math.isnan(report.energy[0])
    # The tips fell: the last frame's tip is lower than the grown one.
    points = ours["points"]
    assert points[-1, 3, 2] < points[0, 3, 2] - 0.01
    assert report.max_length_error < 1e-13


def test_projection_override_and_refusals(tmp_path):
    groom = small_groom()
    a = flexkin.run_groom(groom, tmp_path / "a.npz", projection="dftl")
    info = json.loads(bytes(np.load(tmp_path / "a.npz")["groom.json"]).decode())
    assert info["dynamics"]["projection"] == "dftl" and a.failures == 0
    # SHAKE runs on strands as on chains; an unknown projection is refused by name.
    b = flexkin.run_groom(groom, tmp_path / "s.npz", projection="shake")
    info = json.loads(bytes(np.load(tmp_path / "s.npz")["groom.json"]).decode())
    assert info["dynamics"]["projection"] == "shake" and b.max_length_error < 1e-12
    with pytest.raises(flexkin.InputError, match="projection"):
        flexkin.run_groom(groom, tmp_path / "b.npz", projection="shaky")
    with pytest.raises(flexkin.InputError, match="method"):
        flexkin.run_groom(groom, tmp_path / "c.npz", method="ftl")
    bad = small_groom(frame_rate=60)
    with pytest.raises(flexkin.InputError, match="/dynamics/frame_rate"):
        flexkin.run_groom(bad, tmp_path / "d.npz")
    assert not (tmp_path / "b.npz").exists() and not (tmp_path / "d.npz").exists()
    kinematic = small_groom()
    del kinematic["dynamics"]
    with pytest.raises(flexkin.InputError, match="projection"):
        flexkin.run_groom(kinematic, tmp_path / "e.npz", projection="overall")
