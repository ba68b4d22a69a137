"""Helpers of the sphinx-gallery configuration in ``conf.py``, named there by string (a picklable configuration).

The gallery's examples are scripts that write PNG files rather than matplotlib figures.  `reset_argv` gives
each executed script an output path in a temporary folder of this build (so nothing is written into
``examples/``), and `png_scraper` embeds the PNG files a script wrote there, after the block that wrote them; a
script that writes float32 radiance frames (``.npy``) instead, as a batch does, is shown by a contact sheet of
them.  The tutorial shows its renders with matplotlib, which sphinx-gallery's own scraper embeds.

autosummary imports the API before the gallery runs, with pyrender and PyOpenGL mocked (``autodoc_mock_imports``
in ``conf.py``): ``glphong.integrations.pyrender`` stays imported on the mocks.  Before each example,
`reset_argv` drops such modules (`drop_mocked_modules`), so that an example that uses pyrender imports them again
on the real packages (and chooses PyOpenGL's platform itself, as it does when run on its own).
"""
import atexit
import shutil
import sys
import tempfile
from pathlib import Path
from types import ModuleType

import numpy as np
from sphinx_gallery.scrapers import figure_rst

from glphong.imaging import save_png

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
OUT = Path(tempfile.mkdtemp(prefix="glphong-gallery-"))
atexit.register(shutil.rmtree, OUT, ignore_errors=True)
_EMBEDDED = set()

#: the command-line arguments each script gets in the build: its output file or folder
_ARGUMENTS = {
    "phong_examples": lambda out: [str(out / "phong_examples.png")],
    "fresnel_grazing": lambda out: [str(out / "fresnel_grazing.png")],
    "textured_scene": lambda out: [str(out)],
    "transparency": lambda out: [str(out / "transparency.png")],
    "gltf_layers": lambda out: [str(out / "gltf_layers.png")],
    "custom_material": lambda out: [str(out / "custom_material.png")],
    "custom_light": lambda out: [str(out / "custom_light.png")],
    "model_scene": lambda out: [str(EXAMPLES / "data" / "torus.obj"), str(out / "model_scene.png")],
    "pyrender_scene": lambda out: ["egl", str(out / "pyrender_scene.png")],
    "batch_turntable": lambda out: ["8", str(out)],
    "continuous_version": lambda out: [str(out / "continuous_version.png")],
    "test_my_shader": lambda out: [str(out / "test_my_shader.png")],
    # the BOP scene beside the example's folder: its masks and images are data, not pictures to embed
    "data_for_training": lambda out: [str(out / "data_for_training.png"), str(OUT / "bop-data_for_training")],
}
#: frames per row of a contact sheet of radiance frames
_SHEET_COLUMNS = 4


def _folder(src_file):
    folder = OUT / Path(src_file).stem
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def order(filename):
    """The tutorial first, then the examples by name."""
    return (filename != "tutorial.py", filename)


def _holds_mocked(name, module, dropped):
    """Whether a global of ``module`` is a mock of autodoc's, or a module or object of a module in ``dropped``."""
    for attribute, value in vars(module).items():
        try:
            if getattr(value, "__sphinx_mock__", None) is not None:
                return True
            if isinstance(value, ModuleType):
                owner = None if value.__name__ == f"{name}.{attribute}" else value.__name__  # a package's child
            else:
                owner = getattr(value, "__module__", None)
        except Exception:  # noqa: BLE001 - an object that refuses attribute look-ups holds no mock
            continue
        if owner in dropped:
            return True
    return False


def drop_mocked_modules():
    """Remove from ``sys.modules`` the glphong modules imported on autodoc's mocks, and those holding their objects
    (until none is left): the next import runs them again on the real packages.  Returns the names removed."""
    dropped = set()
    while True:
        found = {name for name, module in list(sys.modules.items())
                 if name.startswith("glphong") and name not in dropped and isinstance(module, ModuleType)
                 and _holds_mocked(name, module, dropped)}
        if not found:
            break
        dropped |= found
    for name in dropped:
        del sys.modules[name]
    return dropped


def reset_argv(gallery_conf, script_vars):
    """``sys.argv[1:]`` of an executed example: its output path in this build's temporary folder.

    The script also gets the ``__file__`` that ``python examples/<name>.py`` gives it, which sphinx-gallery leaves
    undefined (the examples find their data files and shaders beside themselves), and no module imported on
    autodoc's mocks (`drop_mocked_modules`).
    """
    drop_mocked_modules()
    script_vars["example_globals"]["__file__"] = script_vars["src_file"]
    name = Path(script_vars["src_file"]).stem
    arguments = _ARGUMENTS.get(name)
    return arguments(_folder(script_vars["src_file"])) if arguments else []


def _contact_sheet(frames, path):
    """The float32 radiance frames ``(H, W, 3)`` in rows of `_SHEET_COLUMNS`, written to ``path`` as sRGB
    (exposure 1, as ``glphong render`` writes them)."""
    images = [np.load(frame) for frame in frames]
    images += [np.zeros_like(images[0])] * (-len(images) % _SHEET_COLUMNS)
    rows = [np.concatenate(images[i:i + _SHEET_COLUMNS], axis=1) for i in range(0, len(images), _SHEET_COLUMNS)]
    save_png(path, np.concatenate(rows, axis=0))


def png_scraper(block, block_vars, gallery_conf):
    """Embed the PNG files the example wrote into its output folder since the last block, and a contact sheet of
    the radiance frames (``.npy``) it wrote without a PNG of the same name."""
    folder = _folder(block_vars["src_file"])
    written = [p for p in sorted(folder.rglob("*.png")) if p not in _EMBEDDED]
    frames = [p for p in sorted(folder.rglob("*.npy"))
              if p not in _EMBEDDED and not p.with_suffix(".png").exists() and np.load(p, mmap_mode="r").ndim == 3]
    images = []
    for png, image_path in zip(written, block_vars["image_path_iterator"]):
        shutil.copyfile(png, image_path)
        _EMBEDDED.add(png)
        images.append(image_path)
    if frames:
        images.append(next(block_vars["image_path_iterator"]))
        _contact_sheet(frames, images[-1])
        _EMBEDDED.update(frames)
    return figure_rst(images, gallery_conf["src_dir"])
