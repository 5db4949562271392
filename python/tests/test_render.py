"""flexkin.render: the files of `flexkin render` from a Result."""
import shutil

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
        flexkin.render("not a result", tmp_path, ["png"])
    assert list(tmp_path.iterdir()) == []
