"""examples/data_for_training.py: its BOP scene holds both images and its three objects, its picture the six panels,
and every pass it verifies passes (the example asserts it), the matte's among them."""
import json

import numpy as np
from PIL import Image


def test_the_example_writes_its_bop_scene_and_picture(tmp_path, load_example):
    example = load_example("data_for_training")
    frame = example.main(str(tmp_path / "picture.png"), str(tmp_path / "bop"))
    picture = np.asarray(Image.open(tmp_path / "picture.png"))
    width, height = example.SIZE
    assert picture.shape == (height, 6 * width + 5 * 4, 3)
    gt = json.loads((tmp_path / "bop" / "000000" / "scene_gt.json").read_text())
    assert sorted(gt) == ["0", "1"] and [len(v) for v in gt.values()] == [3, 3]
    assert set(np.unique(frame.instance)) == {0, 1, 2, 3}
    moving = frame.mask & (np.hypot(frame.flow[..., 0], frame.flow[..., 1]) > 0.5)
    assert moving.sum() > 0.5 * frame.mask.sum()  # every object moves between the frames
    shares = frame.matte_fractions.sum(axis=-1)
    edges = (shares > 0) & (shares < 1)
    assert edges.sum() > 100 and np.all(shares <= 1)  # the silhouettes' pixels are partly covered
    coverage = picture[:, 3 * (width + 4):3 * (width + 4) + width]
    assert np.array_equal(coverage[~frame.mask & (shares == 0)], np.zeros((np.sum(~frame.mask & (shares == 0)), 3)))
