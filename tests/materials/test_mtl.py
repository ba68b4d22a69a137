"""MtlPhong, the MTL material of OBJ files: the lecture's Phong with MTL's own ambient coefficient.

What is specific to it (twin agreement on both backends, 4300 direction pairs, the definition's mechanics
and its stability cases, the generic geometry against the mpmath oracle of the textbook formula, are in
tests/test_conformance.py):

- Without an ambient light it renders the very image `Phong(Kd, Ks, Ns)` does (bit for bit: the same
  arithmetic); with ``L_a`` it adds ``Ka L_a`` where Phong adds ``Kd L_a``: the difference of the two
  images is ``(Ka - Kd) L_a`` at every covered pixel (to float32 rounding).
"""
import numpy as np

import glphong
from glphong import primitives
from glphong.materials import MtlPhong

KD, KS, NS, KA = (0.3, 0.2, 0.1), (0.5, 0.4, 0.3), 40.0, (0.05, 0.1, 0.2)


def test_it_is_the_lecture_phong_with_mtl_ambient(glphong_backend, glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.3, 3.0), (0.0, 0.0, 0.0))
    renderer = glphong_make_renderer(64, 64, glphong_backend)
    images = {}
    for ambient in (None, glphong.AmbientLight(0.5)):
        for name, material in (("mtl", MtlPhong(KD, KS, NS, KA)), ("phong", glphong.Phong(KD, KS, NS))):
            scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 2.0), 80.0)], ambient=ambient)
            scene.add(primitives.sphere(4), material)
            images[name, ambient is not None] = renderer.render(scene)
    assert np.array_equal(images["mtl", False].radiance, images["phong", False].radiance)
    covered = images["mtl", True].mask
    difference = images["mtl", True].radiance[covered] - images["phong", True].radiance[covered]
    np.testing.assert_allclose(difference, np.broadcast_to(0.5 * (np.array(KA) - np.array(KD)), difference.shape),
                               atol=2e-7)

