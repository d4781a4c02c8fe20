"""seamcl.render against `seamcl render` of the same build: the same image (bit for bit at the
precision the EXR stores), the same --json figures, the same options from the same table, the
same errors naming the same field."""
import inspect

import numpy as np
import pytest

import seamcl
from conftest import ASSETS, REPO
from exr import read_rgba

# Figures that depend on the run, not on what was rendered.
TIMED = {"ms", "kernel_build_ms", "scene_ms", "memory"}

CASES = [
    # (keywords, the same as flags)
    (dict(scene="quad2", size=(64, 64), method="discard", msaa=4),
     ["--scene", "quad2", "--size", "64x64", "--method", "discard", "--msaa", "4"]),
    (dict(scene="closeup-seam", size=(48, 40), method="traverse", filter="ewa", shading="centroid", msaa=2),
     ["--scene", "closeup-seam", "--size", "48x40", "--method", "traverse", "--filter", "ewa", "--shading",
      "centroid", "--msaa", "2"]),
    (dict(scene=str(REPO / "examples" / "scenes" / "quad2.json"), size=(40, 32), method="guardband", guard_band=2,
          texels="rgba32f", lod_bias=-0.5, frame=1, frames=8, tint=True),
     ["--scene", REPO / "examples" / "scenes" / "quad2.json", "--size", "40x32", "--method", "guardband",
      "--guard-band", "2", "--texels", "rgba32f", "--lod-bias", "-0.5", "--frame", "1", "--frames", "8", "--tint"]),
]


@pytest.mark.parametrize("keywords,flags", CASES, ids=["quad2-discard", "closeup-traverse-ewa", "scenefile-guardband"])
def test_render_equals_the_cli_exr_and_json(keywords, flags, cli_json, tmp_path):
    exr = tmp_path / "cli.exr"
    expected = cli_json("render", *flags, "-o", exr, "--json")
    r = seamcl.render(**keywords)

    stored, kind = read_rgba(exr)
    assert r.image.dtype == np.float32
    assert r.image.shape == stored.shape == (keywords["size"][1], keywords["size"][0], 4)
    # The EXR holds half floats unless a value is beyond half's range; bit-identical at that precision.
    np.testing.assert_array_equal(r.image.astype(kind).view(np.uint16 if kind == np.float16 else np.uint32),
                                  stored.view(np.uint16 if kind == np.float16 else np.uint32))
    assert np.all(np.isfinite(r.image))
    assert r.image[..., 3].max() > 0  # coverage somewhere: a real frame, not zeros
    assert float(r.image[..., :3].std()) > 0

    assert set(r.info) == set(expected) - {"output"}
    for key in set(expected) - TIMED - {"output"}:
        assert r.info[key] == expected[key], key
    assert r.info["fragments"] > 0


def test_scene_from_files_renders_as_the_cli_with_texture(cli_json, tmp_path):
    mesh, texture = ASSETS / "ptex" / "cube.obj", ASSETS / "ptex" / "cube_text.ptx"
    scene = seamcl.Scene.from_files(mesh, texture)
    assert scene.faces > 6 and scene.info["triangles"] == 2 * scene.faces
    exr = tmp_path / "cube.exr"
    expected = cli_json("render", "--scene", mesh, "--texture", texture, "--method", "traverse", "--size", "40x36",
                        "-o", exr, "--json")
    r = seamcl.render(scene=scene, method="traverse", size=(40, 36))
    stored, kind = read_rgba(exr)
    np.testing.assert_array_equal(r.image.astype(kind), stored)
    assert r.info["options"] == expected["options"]
    assert r.info["texture_bytes"] == expected["texture_bytes"] > 0
    assert r.info["triangles"] == expected["triangles"] == scene.info["triangles"]


def test_image_views_the_renderers_buffer_without_a_copy():
    r = seamcl.render(scene="quad2", size=(24, 16))
    assert r.image.ctypes.data == r._buffer_address
    assert not r.image.flags.owndata and r.image.base is not None
    assert r.image.flags.c_contiguous and r.image.flags.writeable
    assert r.image.shape == (16, 24, 4) and r.image.strides == (24 * 16, 16, 4)
    view = r.image[2:4]
    del r
    assert np.all(np.isfinite(view))  # the buffer lives as long as a view of it


def test_every_render_option_is_a_keyword_with_the_tables_default(cli):
    table = {spec["key"]: spec for spec in seamcl._options.table("render")}
    params = inspect.signature(seamcl.render).parameters
    assert set(table) <= set(params)
    assert set(params) - set(table) == {"device", "progress"}
    help_text = cli("render", "--help").stdout
    for key, spec in table.items():
        # The command line's flags come from the same table.
        assert "--" + key.replace("_", "-") in help_text, key
        default = params[key].default
        if spec["type"] == "size":
            assert f"{default[0]}x{default[1]}" == spec["default"]
        else:
            assert default == spec["default"], key
    assert params["msaa"].default == 1 and params["method"].default == "discard" and params["size"].default == (480, 540)
    for key in ("method", "filter", "msaa", "guard_band", "lod_bias"):
        assert key in seamcl.render.__doc__


ERRORS = [
    (dict(msaa=3), ["--msaa", "3"], "msaa"),
    (dict(method="bogus"), ["--method", "bogus"], "method"),
    (dict(size=(0, 10)), ["--size", "0x10"], "size"),
    (dict(guard_band=99), ["--guard-band", "99"], "guard_band"),
    (dict(lod_bias=9.5), ["--lod-bias", "9.5"], "lod_bias"),
    (dict(scene="no/such/scene.json"), ["--scene", "no/such/scene.json"], "scene"),
    (dict(frames=10), ["--frames", "10"], "frames"),
    (dict(shading="sample", centroid=True), ["--shading", "sample", "--centroid"], "centroid"),
]


@pytest.mark.parametrize("keywords,flags,field", ERRORS, ids=[e[2] for e in ERRORS])
def test_bad_option_raises_input_error_naming_the_field_as_the_cli(keywords, flags, field, cli):
    size = [] if "size" in keywords else ["--size", "16x16"]
    done = cli("render", *size, *flags, check=False)
    assert done.returncode == 2
    with pytest.raises(seamcl.InputError) as caught:
        seamcl.render(**{"size": (16, 16), **keywords})
    assert isinstance(caught.value, ValueError)
    assert caught.value.field == field
    assert done.stderr.strip() == f"seamcl: {caught.value}"


def test_errors_of_the_python_front_end_name_their_field():
    with pytest.raises(seamcl.InputError) as caught:
        seamcl.render(colour="red")
    assert caught.value.field == "colour"
    with pytest.raises(seamcl.InputError) as caught:
        seamcl.render(size=(16, 16), aniso=float("nan"))
    assert caught.value.field == "aniso"
    with pytest.raises(seamcl.InputError) as caught:
        seamcl.render(device="")
    assert caught.value.field == "device"
    with pytest.raises(seamcl.InputError) as caught:
        seamcl.render(device="no such device anywhere")
    assert caught.value.field == "device"
    with pytest.raises(seamcl.InputError) as caught:
        seamcl.Scene.from_files(ASSETS / "ptex" / "cube.obj", "missing.ptx")
    assert caught.value.field == "texture"


def test_progress_lines_of_repeated_renders():
    lines = []
    r = seamcl.render(scene="quad2", size=(16, 16), repeat=3, progress=lines.append)
    assert lines == ["render 1/3", "render 2/3", "render 3/3"]
    assert r.info["runs"] == 3


def test_devices_and_scenes_as_the_cli_lists_them(cli, cli_json):
    listed = seamcl.devices()
    assert sum(d["chosen"] for d in listed) == 1
    text = cli("devices").stdout
    for d in listed:
        assert ("* " if d["chosen"] else "  ") + d["name"] in text
    assert seamcl.scenes() == cli_json("scenes", "--json")
