"""The main job (CLI), the output encoders and the installed package's GLSL sources."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import glphong
from glphong.imaging import encode_srgb8, save_npy, save_png, srgb_encode


def test_srgb_curve_exact_values():
    # independent values of IEC 61966-2-1: the linear segment, the joint, the power segment
    x = np.array([0.0, 0.001, 0.0031308, 0.18, 0.5, 1.0, 2.0, -1.0, np.nan])
    want = np.array([0.0, 0.01292, 0.04044994, 1.055 * 0.18 ** (1 / 2.4) - 0.055,
                     0.7353569830524495, 1.0, 1.0, 0.0, 0.0])
    np.testing.assert_allclose(srgb_encode(x), want, rtol=1e-6, atol=1e-9)


def test_encode_srgb8_applies_exposure_then_curve():
    radiance = np.array([[[0.25, 0.5, 4.0]]])
    out = encode_srgb8(radiance, exposure=2.0)
    assert out.dtype == np.uint8
    np.testing.assert_array_equal(out, [[[188, 255, 255]]])  # sRGB(0.5) * 255 = 187.52 -> 188


def test_png_and_npy_round_trip(tmp_path):
    radiance = np.random.default_rng(1).uniform(0, 2, size=(5, 7, 3)).astype(np.float32)
    save_png(tmp_path / "a.png", radiance, exposure=0.5)
    save_npy(tmp_path / "a.npy", radiance)
    png = np.asarray(Image.open(tmp_path / "a.png"))
    np.testing.assert_array_equal(png, encode_srgb8(radiance, 0.5))
    np.testing.assert_array_equal(np.load(tmp_path / "a.npy"), radiance)


def test_glsl_sources_ship_with_the_package():
    from glphong.materials import registered_models
    from glphong.core.glsl_files import chunk_source, glsl_root

    for name in ("common", "lights", "lobe", "shade", "mesh_vertex", "mesh_fragment", "shade_points", "srgb", "encode"):
        text = chunk_source(name)
        assert text.startswith(f"// {name}.glsl --"), name  # every chunk opens with its formula header
    builtin = [m for m in registered_models() if m.__module__.startswith("glphong.")]
    assert {m.name for m in builtin} >= {"lambert", "phong_lobe", "blinn_lobe"}
    for model in builtin:  # one file per model under glsl/materials/, opening with its formula header
        path = f"materials/{model.name}.glsl"
        assert (glsl_root() / path).is_file(), path
        text = (glsl_root() / path).read_text(encoding="utf-8")
        assert text.startswith(f"// {path} -- the model '{model.name}'"), path
        assert model.source().rstrip().endswith(text.rstrip()), path  # after the chunks it reads first (GlslFile(before=...)), if any


def test_main_job_from_outside_the_checkout(tmp_path):
    """`python -m glphong` with no arguments writes the default figure in the working directory."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    result = subprocess.run([sys.executable, "-m", "glphong", "--tile", "32"], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "wrote phong_examples.png" in result.stdout
    image = Image.open(tmp_path / "phong_examples.png")
    assert image.size == (10 * 32 + 22, 4 * 32 + 44)
    pixels = np.asarray(image)
    assert pixels[22:-22, 22:].max() == 255 and pixels[22:-22, 22:].std() > 10  # highlights and shading


def test_cli_verify_reports_cross_check(tmp_path):
    from glphong.tools.cli import main

    code = main(["render", "--tile", "24", "--verify", "--out", str(tmp_path / "f.png"), "--npy", str(tmp_path / "f.npy")])
    assert code == 0
    radiance = np.load(tmp_path / "f.npy")
    assert radiance.shape == (4 * 24, 10 * 24, 3) and radiance.dtype == np.float32
    assert np.isfinite(radiance).all() and radiance.max() > 1.0  # linear, unclamped highlights


def test_cli_rejects_unknown_backend(capsys):
    from glphong.tools.cli import main

    with pytest.raises(SystemExit):
        main(["render", "--backend", "vulkan"])
    assert "invalid choice" in capsys.readouterr().err


def test_import_does_not_pull_optional_packages():
    code = "import sys, glphong; print(sorted(m for m in ('pyrender', 'matplotlib', 'hypothesis', 'OpenGL') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_setup_cfg_ships_every_subpackage():
    """Every package directory of glphong is listed in setup.cfg (the wheel would miss it otherwise)."""
    import configparser
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    if not (root / "setup.cfg").is_file():
        pytest.skip("not running from a source checkout")
    config = configparser.ConfigParser()
    config.read(root / "setup.cfg")
    listed = set(config["options"]["packages"].split())
    found = {".".join(p.parent.relative_to(root).parts) for p in (root / "glphong").rglob("__init__.py")}
    assert found | {"glphong.glsl"} == listed


def test_cli_gallery_renders_every_model_and_cross_checks_each_tile(tmp_path, capsys):
    from PIL import Image

    from glphong.tools.cli import main
    from glphong.analysis.gallery import GALLERY
    from glphong.materials import registered_models

    out = tmp_path / "gallery.png"
    code = main(["gallery", "--tile", "40", "--columns", "4", "--verify", "--out", str(out)])
    text = capsys.readouterr().out
    assert code == 0, text
    shown = [line for line in text.splitlines() if line.startswith("  ")]
    assert len(shown) == len(GALLERY) and all("PASS" in line for line in shown), text  # every entry defined here
    assert Image.open(out).size == (4 * 40, -(-len(GALLERY) // 4) * (40 + 16))
    drawn = {type(t).name for _, factory in GALLERY for t in factory().components}
    builtin = {m.name for m in registered_models() if m.__module__.startswith("glphong.")}
    assert drawn == builtin  # one tile at least per built-in model


@pytest.mark.parametrize("exposure", [1.0, 2.0, 0.37, 3.3e-7, 5e-324, 1e30])
def test_fast_srgb8_is_the_formula_at_every_step(exposure):
    """float32 radiance goes through the table of code steps: the same codes as the float64 formula on
    random values, at each of the 255 steps and one float32 ulp either side, and at NaN, +-Inf, -0,
    negative, subnormal and huge values."""
    from glphong.imaging import _float32_code_table, encode_srgb8_reference

    rng = np.random.default_rng(5)
    values = [(rng.random(30000) ** 3 * 1.2).astype(np.float32)]
    steps = _float32_code_table(float(exposure))[1][:-1]
    steps = steps[np.isfinite(steps) & (steps > 0)]
    values += [steps, np.nextafter(steps, np.float32(0)), np.nextafter(steps, np.float32(np.inf))]
    values.append(np.array([np.nan, -np.nan, -1.0, -0.0, 0.0, np.inf, -np.inf, 1e-45, 3e38, 1.0, 0.5], np.float32))
    flat = np.concatenate(values)
    image = np.resize(flat, len(flat) + (-len(flat)) % 3).reshape(-1, 1, 3)[::-1]  # a strided view, as frames are
    fast = encode_srgb8(image, exposure)
    assert fast.dtype == np.uint8 and np.array_equal(fast, encode_srgb8_reference(image, exposure))
    if exposure in (1.0, 2.0, 0.37):  # every step reachable: each of the 256 codes is met
        assert len(np.unique(fast)) == 256


def test_save_png_compress_level(tmp_path):
    radiance = np.random.default_rng(1).random((16, 16, 3)).astype(np.float32)
    for level in (0, 1, 9):
        save_png(tmp_path / f"{level}.png", radiance, compress_level=level)
        assert np.array_equal(np.asarray(Image.open(tmp_path / f"{level}.png")), encode_srgb8(radiance))
    with pytest.raises(ValueError, match=r"compress_level must be in \[0, 9\]"):
        save_png(tmp_path / "x.png", radiance, compress_level=10)


def test_frame_shows_itself_in_a_notebook(make_renderer):
    """Jupyter calls ``_repr_png_``: the PNG holds exactly ``to_srgb8(exposure)``."""
    from io import BytesIO

    from PIL import Image

    from glphong.analysis.figures import phong_examples_scene
    from glphong.materials import Phong

    renderer = make_renderer(24, 16, "egl")
    frame = renderer.render(phong_examples_scene(Phong, 10.0, 45.0))
    frame = frame.with_exposure(0.6)
    shown = np.asarray(Image.open(BytesIO(frame._repr_png_())))
    assert shown.shape == (16, 24, 3) and np.array_equal(shown, frame.to_srgb8(0.6))
    assert not np.array_equal(shown, frame.to_srgb8(1.0))


def test_render_file_writes_its_frame_passes(tmp_path, capsys):
    """``glphong render FILE --passes ... --passes-out ... --verify``: the passes written (.npz and .exr), each
    checked against its twin; a pass the file cannot give, or an unknown one, is a one-line error."""
    from glphong.datasets import load_exr, load_npz
    from glphong.tools.cli import main
    torus = str(Path(__file__).resolve().parent.parent / "examples" / "data" / "torus.obj")
    npz = tmp_path / "t.npz"
    assert main(["render", torus, "--width", "48", "--height", "36", "--out", str(tmp_path / "t.png"),
                 "--passes", "depth,instance,normal_camera", "--passes-out", str(npz), "--verify"]) == 0
    out = capsys.readouterr().out
    assert "depth pass" in out and "instance pass" in out and "PASS" in out
    arrays = load_npz(npz)
    assert set(arrays) == {"radiance", "depth", "instance", "normal_camera", "coverage"}
    assert arrays["instance"].max() == 1 and arrays["depth"].max() > 0
    assert main(["render", torus, "--width", "16", "--height", "12", "--out", str(tmp_path / "u.png"),
                 "--passes", "nocs", "--passes-out", str(tmp_path / "u.exr")]) == 0
    assert set(load_exr(tmp_path / "u.exr")) == {"radiance", "nocs", "coverage"}
    with pytest.raises(SystemExit):
        main(["render", torus, "--passes", "flow"])
    assert "--passes takes depth" in capsys.readouterr().err
