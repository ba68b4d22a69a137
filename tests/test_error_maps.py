"""`glphong.analysis.error_maps.error_image` and the gallery example that shows glTF's layered materials with it."""
from types import SimpleNamespace

import numpy as np
import pytest

from glphong.analysis.error_maps import error_image


def _report(errors, mask):
    return SimpleNamespace(relative_error=np.array(errors, dtype=float), mask=np.array(mask, dtype=bool))


def test_error_image_is_log_scaled_between_low_and_high_per_pixel_largest_channel():
    errors = [[[1e-9, 0.0, 0.0], [1e-8, 1e-8, 1e-8], [10 ** -6.5, 1e-9, np.nan], [1e-5, 0.0, 0.0],
               [1.0, 1.0, 1.0], [np.nan, np.nan, np.nan], [1.0, 1.0, 1.0]]]
    grey = error_image(_report(errors, [[True] * 6 + [False]]), low=1e-8, high=1e-5)
    assert grey.shape == (1, 7, 3) and np.all(grey[..., 0] == grey[..., 1]) and np.all(grey[..., 1] == grey[..., 2])
    np.testing.assert_allclose(grey[0, :, 0], [0.0, 0.0, 0.5, 1.0, 1.0, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("low, high", [(0.0, 1e-5), (1e-5, 1e-5), (1e-4, 1e-5)])
def test_error_image_refuses_a_scale_that_is_not_increasing(low, high):
    with pytest.raises(ValueError, match="0 < low < high"):
        error_image(_report([[[0.0, 0.0, 0.0]]], [[True]]), low=low, high=high)


def test_example_gltf_layers_verifies_its_coat_sheen_and_glass(tmp_path, load_example):
    module = load_example("gltf_layers")
    used = {name: obj.material.extensions() for name, obj in
            ((obj.name, obj) for obj in module.build_scene().objects)}
    assert {"clearcoat"} <= set(used["clear coat"]) and {"sheen"} <= set(used["sheen"])
    assert {"transmission"} <= set(used["glass"])
    report = module.main(tmp_path / "layers.png", 120, 60)
    assert report.passed and report.mask.sum() > 2000 and (tmp_path / "layers.png").is_file()
