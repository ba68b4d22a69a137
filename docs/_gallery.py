"""Helpers of the sphinx-gallery configuration in ``conf.py``, named there by string (a picklable configuration).

The gallery's examples are scripts that write PNG files rather than matplotlib figures.  `reset_argv` gives
each executed script an output path in a temporary folder of this build (so nothing is written into
``examples/``), and `png_scraper` embeds the PNG files a script wrote there, after the block that wrote them.
The tutorial shows its renders with matplotlib, which sphinx-gallery's own scraper embeds.
"""
import atexit
import shutil
import tempfile
from pathlib import Path

from sphinx_gallery.scrapers import figure_rst

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
OUT = Path(tempfile.mkdtemp(prefix="glphong-gallery-"))
atexit.register(shutil.rmtree, OUT, ignore_errors=True)
_EMBEDDED = set()

#: the command-line arguments each script gets in the build: its output file or folder
_ARGUMENTS = {
    "phong_examples": lambda out: [str(out / "phong_examples.png")],
    "fresnel_grazing": lambda out: [str(out / "fresnel_grazing.png")],
    "textured_scene": lambda out: [str(out)],
    "custom_material": lambda out: [str(out / "custom_material.png")],
    "custom_light": lambda out: [str(out / "custom_light.png")],
    "model_scene": lambda out: [str(EXAMPLES / "data" / "torus.obj"), str(out / "model_scene.png")],
    "pyrender_scene": lambda out: ["egl", str(out / "pyrender_scene.png")],
    "batch_turntable": lambda out: ["8", str(out)],
}


def _folder(src_file):
    folder = OUT / Path(src_file).stem
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def order(filename):
    """The tutorial first, then the examples by name."""
    return (filename != "tutorial.py", filename)


def reset_argv(gallery_conf, script_vars):
    """``sys.argv[1:]`` of an executed example: its output path in this build's temporary folder."""
    name = Path(script_vars["src_file"]).stem
    arguments = _ARGUMENTS.get(name)
    return arguments(_folder(script_vars["src_file"])) if arguments else []


def png_scraper(block, block_vars, gallery_conf):
    """Embed the PNG files the example wrote into its output folder since the last block."""
    folder = _folder(block_vars["src_file"])
    written = [p for p in sorted(folder.rglob("*.png")) if p not in _EMBEDDED]
    images = []
    for png, image_path in zip(written, block_vars["image_path_iterator"]):
        shutil.copyfile(png, image_path)
        _EMBEDDED.add(png)
        images.append(image_path)
    return figure_rst(images, gallery_conf["src_dir"])
