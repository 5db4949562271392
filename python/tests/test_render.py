"""flexkin.render: the files of `flexkin render` from a Result."""
import shutil

import numpy as np
import pytest

import flexkin

pytestmark = pytest.mark.skipif(not hasattr(flexkin._flexkin, "render"),
                                reason="flexkin.render not built (no render components)")

@pytest.fixture(scope="module")
def small_result():
    return flexkin.run(flexkin.parabola(links=6), [[0.1, 0.05]] * 4)


def test_png_glb_html(small_result, tmp_path):
    out = tmp_path / "new" / "dir"
    written = flexkin.render(small_result, out, ["glb", "png", "html"], width=128)
    assert written == [str(out / "result.png"), str(out / "result.html"), str(out / "result.glb")]
    assert (out / "result.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "result.glb").read_bytes()[:4] == b"glTF"
    assert b"<html" in (out / "result.html").read_bytes()[:2000].lower()


def test_comma_separated_formats_and_stem(small_result, tmp_path):
    written = flexkin.render(small_result, str(tmp_path), "svg,plots", stem="fig", width=128)
    assert str(tmp_path / "fig.svg") in written
    assert str(tmp_path / "fig_path_length.png") in written
    assert all((tmp_path / p).exists() for p in written)


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="ffmpeg is not installed")
def test_mp4(small_result, tmp_path):
    (path,) = flexkin.render(small_result, tmp_path, ["mp4"], width=64, fps=10, max_frames=4)
    assert path.endswith(".mp4") and b"ftyp" in open(path, "rb").read(16)


def test_unknown_format_and_bad_options_refused(small_result, tmp_path):
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(small_result, tmp_path, ["png", "jpeg"])
    assert info.value.field == "formats" and '"jpeg"' in str(info.value)
    for name in ("svg", "png", "pdf", "plots", "mp4", "gif", "html", "gltf", "glb"):
        assert name in info.value.expected
    with pytest.raises(flexkin.InputError, match="width"):
        flexkin.render(small_result, tmp_path, ["png"], width=3)
    with pytest.raises(flexkin.InputError):
        flexkin.render(42, tmp_path, ["png"])
    with pytest.raises(FileNotFoundError, match="no_such.json"):
        flexkin.render(tmp_path / "no_such.json", tmp_path, ["png"])
    assert list(tmp_path.iterdir()) == []


EXAMPLES = __import__("pathlib").Path(__file__).resolve().parents[2] / "examples"


def test_files_of_every_kind_drawn_by_path_as_the_command_draws_them(small_result, tmp_path):
    # One library call (flexkin/draw.h) draws what a file holds: a result, a robot trajectory or a
    # strand file, told apart by content; the outputs are named after the file.
    small_result.write(tmp_path / "chain.npz")
    assert flexkin.render(tmp_path / "chain.npz", tmp_path / "out", "svg", width=128) == [
        str(tmp_path / "out" / "chain.svg")]
    flexkin.run_robot(EXAMPLES / "robot_planar_8link.json", output=tmp_path / "arm.json")
    written = flexkin.render(tmp_path / "arm.json", tmp_path / "out", width=128)
    assert written == [str(tmp_path / "out" / "arm.svg"), str(tmp_path / "out" / "arm.png")]
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(tmp_path / "arm.json", tmp_path / "out", "glb")
    assert info.value.field == "formats" and "robot trajectories" in str(info.value)
    flexkin.run_groom(EXAMPLES / "groom_grass_2d.json", tmp_path / "grass.npz")
    written = flexkin.render(tmp_path / "grass.npz", tmp_path / "out", "png,html", width=160,
                             max_strands=5)
    assert written == [str(tmp_path / "out" / "grass.png"), str(tmp_path / "out" / "grass.html")]
    assert (tmp_path / "out" / "grass.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(tmp_path / "grass.npz", tmp_path / "out", "plots")
    assert info.value.field == "formats" and "strand files" in str(info.value)
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(tmp_path / "grass.npz", tmp_path / "out", "png", max_strands=-1)
    assert info.value.field == "max_strands"
    # A problem of the file is named by the file, as on the command line.
    (tmp_path / "bad.json").write_text('{"format": "flexkin-result"}')
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(tmp_path / "bad.json", tmp_path / "out", "svg")
    assert info.value.field.startswith(str(tmp_path / "bad.json"))


def test_glb_and_html_hold_the_data(small_result, tmp_path):
    files = flexkin.render(small_result, tmp_path, "html,glb,gltf")
    html = (tmp_path / "result.html").read_text()
    assert f"{small_result.frames[-1, -1, 0]:.6g}"[:6] in html
    glb = (tmp_path / "result.glb").read_bytes()
    assert glb[:4] == b"glTF" and int.from_bytes(glb[8:12], "little") == len(glb)
    import json
    gltf = json.loads((tmp_path / "result.gltf").read_text())
    assert gltf["asset"]["version"] == "2.0" and len(gltf["skins"][0]["joints"]) == 7
    assert len(files) == 3


def test_option_objects_and_dicts_reach_the_writers(small_result, tmp_path):
    plain = flexkin.render(small_result, tmp_path / "a", ["glb", "html"])
    thin = flexkin.render(small_result, tmp_path / "b", ["glb", "html"],
                          gltf=flexkin.GltfOptions(tube_radius=0.01, tube_sides=3),
                          viewer={"playback_seconds": 2.5, "trail_points": [6], "digits": 17,
                                  "title": "my title"})
    a, b = (open(p, "rb").read() for p in (plain[1], thin[1]))
    assert a != b and len(b) < len(a)                           # fewer tube vertices
    html = open(thin[0]).read()
    assert "my title" in html and "my title" not in open(plain[0]).read()
    no_mesh = flexkin.render(small_result, tmp_path / "c", ["gltf"],
                             gltf={"include_mesh": False, "up_axis": "z", "scale": 2.0})
    import json
    doc = json.loads(open(no_mesh[0]).read())
    assert "meshes" not in doc or not doc["meshes"]
    legend = flexkin.render(small_result, tmp_path / "d", ["svg", "html"],
                            figure=flexkin.FigureOptions(width=200), title="keyword title")
    bare = flexkin.render(small_result, tmp_path / "e", ["svg"],
                          figure=flexkin.FigureOptions(width=200, show_legend=False))
    text = open(legend[0]).read()
    assert 'width="200px"' in text and len(open(bare[0]).read()) < len(text)
    assert "keyword title" in open(legend[1]).read()        # the viewer takes the title


def test_option_classes_check_their_fields(small_result, tmp_path):
    options = flexkin.GltfOptions(tube_sides=100)
    with pytest.raises(flexkin.InputError) as info:
        options.validate()
    assert info.value.field == "tube_sides"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(small_result, tmp_path, ["glb"], gltf=options)
    assert info.value.field == "gltf.tube_sides"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(small_result, tmp_path, ["html"], viewer={"digits": 3})
    assert info.value.field == "viewer.digits"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(small_result, tmp_path, ["html"], viewer={"trail_points": [7]})
    assert info.value.field == "viewer.trail_points[0]"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(small_result, tmp_path, ["png"], figure={"bogus": 1})
    assert info.value.field == "figure.bogus" and "show_legend" in info.value.expected
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(small_result, tmp_path, ["png"], plot=3)
    assert info.value.field == "plot"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.GltfOptions(up_axis="w")
    assert info.value.field == "up_axis"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.AnimationOptions(fps="fast")
    assert info.value.field == "fps"
    for empty in ([], ()):
        with pytest.raises(flexkin.InputError) as info:
            flexkin.render(small_result, tmp_path, empty)
        assert info.value.field == "formats"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.render(small_result, tmp_path, ["png"], every=-1)
    assert info.value.field == "every"
    assert list(tmp_path.iterdir()) == []


def test_render_equals_the_command_line(cli, tmp_path):
    import subprocess
    from conftest import EXAMPLES
    result = flexkin.run_scenario(EXAMPLES / "fig12_spatial_curve.json")
    path = tmp_path / "result.npz"
    result.write(path)
    formats = "svg,html,gltf,glb"
    subprocess.run([cli, "render", str(path), "--formats", formats, "--width", "300",
                    "--azimuth", "10", "-o", str(tmp_path / "cli"), "-q"], check=True)
    files = flexkin.render(flexkin.read_result(path), tmp_path / "py", formats, width=300,
                           azimuth=10)
    import re
    for file in files:                   # bit for bit (but cairo's process-wide surface numbers)
        name = file.rsplit("/", 1)[1]
        ours, theirs = open(file, "rb").read(), (tmp_path / "cli" / name).read_bytes()
        if name.endswith(".svg"):
            ours, theirs = (re.sub(rb'id="surface\d+"', b"", x) for x in (ours, theirs))
        assert ours == theirs, name


@pytest.mark.parametrize("up_axis", ["auto", "y", "z"])
def test_gltf_animation_reads_back_as_the_frames(tmp_path, up_axis):
    from conftest import EXAMPLES
    result = flexkin.run_scenario(EXAMPLES / "fig12_spatial_curve.json")
    options = flexkin.GltfOptions(steps_per_second=10, scale=2.0, up_axis=up_axis)
    for fmt in ("glb", "gltf"):
        (path,) = flexkin.render(result, tmp_path, [fmt], gltf=options)
        times, positions = flexkin.gltf_joint_positions(path)
        assert positions.shape == result.frames.shape
        assert np.allclose(times, result.steps / 10)
        scale = np.abs(result.frames).max()
        assert np.abs(positions - result.frames).max() < 1e-6 * scale
    with pytest.raises(flexkin.InputError) as info:
        flexkin.gltf_joint_positions(EXAMPLES / "fig12_spatial_curve.json")
    assert str(EXAMPLES / "fig12_spatial_curve.json") in info.value.field
    with pytest.raises(FileNotFoundError):
        flexkin.gltf_joint_positions(tmp_path / "missing.glb")


# A RobotResult (flexkin.run_robot, docs/robot-format.md) is drawn as `flexkin render` draws a
# trajectory file: the arm as a chain whose end effector leads, the base fixed; by default the
# figure (svg, png); the chain-only formats (plots, gltf, glb) are refused naming the valid ones.
# Before, render refused any object but a Result.
@pytest.fixture(scope="module")
def planar_robot():
    from conftest import EXAMPLES
    return flexkin.run_robot(EXAMPLES / "robot_planar_8link.json")


def test_a_robot_result_is_drawn_as_the_command_draws_its_trajectory(cli, tmp_path):
    import re
    import subprocess
    from conftest import EXAMPLES
    robot = flexkin.run_robot(EXAMPLES / "robot_planar_8link.json", output=tmp_path / "t.json")
    subprocess.run([cli, "render", str(tmp_path / "t.json"), "--formats", "svg,html", "--width",
                    "300", "-o", str(tmp_path / "cli"), "-q"], check=True)
    files = flexkin.render(robot, tmp_path / "py", "svg,html", stem="t", width=300)
    # the same pictures, bit for bit (the trajectory file holds the same numbers)
    assert [f.rsplit("/", 1)[1] for f in files] == ["t.svg", "t.html"]
    for file in files:
        name = file.rsplit("/", 1)[1]
        ours, theirs = open(file, "rb").read(), (tmp_path / "cli" / name).read_bytes()
        if name.endswith(".svg"):
            ours, theirs = (re.sub(rb'id="surface\d+"', b"", x) for x in (ours, theirs))
        assert ours == theirs, name
    assert b'"robot":{"links":8,"targets":200,"unreached":0,' in open(files[1], "rb").read()


def test_a_robot_result_by_default_and_its_refused_formats(planar_robot, tmp_path):
    written = flexkin.render(planar_robot, tmp_path, width=200)
    assert written == [str(tmp_path / "result.svg"), str(tmp_path / "result.png")]
    assert (tmp_path / "result.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for name in ("plots", "gltf", "glb"):
        with pytest.raises(flexkin.InputError) as info:
            flexkin.render(planar_robot, tmp_path / "no", ["svg", name])
        assert info.value.field == "formats" and f'"{name}"' in str(info.value)
        assert "not available for robot trajectories" in str(info.value)
        assert info.value.expected == "svg, png, pdf, mp4, gif, html"
    assert not (tmp_path / "no").exists()
