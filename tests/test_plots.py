"""Lobe and albedo plots (`glphong.analysis.plots`, ``glphong plot``): the curves are the twin's BRDF, checked against
closed forms, and the PNGs are written.

- The lecture's Phong lobe in the plane of incidence is ``ks cos^q(theta_o - theta_i) cos(theta_o) / cos(theta_i)``
  (written here): the curve agrees to 1e-5 relative down to 1e-6 of the peak (float32 directions), and its peak lies where that
  closed form peaks (``theta_o`` below the mirror angle by about ``tan(theta_o)/q`` rad: the cosine's pull).
- The albedo plot's values are `glphong.analysis.albedo`'s: NormalizedPhong's at normal incidence is rho_s.
- ``glphong plot lobe|albedo|gallery`` write PNGs; a bad expression or angle is refused before work.
"""
import numpy as np
import pytest
from PIL import Image

import glphong
from glphong.analysis import plots
from glphong.tools.cli import main


def test_phong_lobe_curve_is_the_closed_form(tmp_path):
    theta_i = np.radians(45.0)
    curves = plots.plot_lobes({"q=20": glphong.Phong(0.0, 0.5, 20.0), "q=100": glphong.Phong(0.0, 0.5, 100.0)},
                              theta_i, str(tmp_path / "lobes.png"))
    for q in (20.0, 100.0):
        theta_o, value = curves[f"q={q:g}"]
        closed = 0.5 * np.maximum(np.cos(theta_o - theta_i), 0) ** q * np.cos(theta_o) / np.cos(theta_i)
        strong = closed > 1e-6 * closed.max()
        # the twin sees float32-rounded directions: q eps / (1 - cos) relative in the tail
        np.testing.assert_allclose(value[strong, 0], closed[strong], rtol=1e-5)
        assert abs(theta_o[np.argmax(value[:, 0])] - theta_o[np.argmax(closed)]) <= np.pi / 720
        assert theta_o[np.argmax(value[:, 0])] < theta_i  # pulled toward the normal by cos(theta_o)
    assert Image.open(tmp_path / "lobes.png").size[0] > 300


def test_albedo_plot_values(tmp_path):
    theta_i, values = plots.plot_albedo({"np": glphong.NormalizedPhong(0.0, 0.8, 50.0)}, str(tmp_path / "a.png"),
                                        theta_i=np.radians([0.0, 60.0]))
    np.testing.assert_allclose(values["np"][0], 0.8, rtol=1e-6)
    assert values["np"][1, 0] < 0.8 and (tmp_path / "a.png").stat().st_size > 1000


def test_cli_plot(tmp_path, capsys):
    assert main(["plot", "lobe", "Phong(kd=0, ks=0.5, q=20)", "BlinnPhong(kd=0, ks=0.5, q=80)",
                 "--theta-i", "30", "--out", str(tmp_path / "l.png")]) == 0
    assert main(["plot", "gallery", "--out", str(tmp_path / "g.png")]) == 0
    assert (tmp_path / "l.png").exists() and (tmp_path / "g.png").exists()
    assert main(["plot", "lobe", "open('x')", "--out", str(tmp_path / "x.png")]) == 2
    assert "cannot build a material" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["plot", "lobe", "Lambert(0.2)", "--theta-i", "95"])
    with pytest.raises(ValueError, match=r"theta_i must be in \[0, pi/2\)"):
        plots.lobe_curves(glphong.Lambert(0.2), 2.0)


def test_lobe_surface_is_the_brdf_and_shows_anisotropy(tmp_path):
    """The 3D lobe's radius is f_r cos(theta_o) of the twin; Ward's lobe (alpha_x 0.3, alpha_y 0.06) is
    wider along t than along b around the mirror direction, an isotropic Phong lobe is not."""
    theta_i = np.radians(30.0)
    ward = glphong.Ward(0.0, 0.5, 0.3, 0.06)
    wo, value = plots.plot_lobe_3d(ward, theta_i, str(tmp_path / "w.png"))
    wi = np.broadcast_to([-np.sin(theta_i), 0.0, np.cos(theta_i)], wo.shape)
    expected = glphong.analysis.f_r(ward, wi.reshape(-1, 3), wo.reshape(-1, 3)).reshape(wo.shape) * wo[..., 2:]
    np.testing.assert_allclose(value, expected, rtol=1e-12)
    assert Image.open(tmp_path / "w.png").size[0] > 300

    def spread(material):
        """Half-widths (x, y) of the region above half the lobe's maximum, in direction cosines."""
        directions, v = plots.lobe_surface(material, theta_i)
        high = v.mean(axis=-1) > 0.5 * v.mean(axis=-1).max()
        x, y = directions[high, 0], directions[high, 1]
        return np.ptp(x), np.ptp(y)

    wx, wy = spread(ward)
    px, py = spread(glphong.Phong(0.0, 0.5, 60.0))
    assert wx > 2.5 * wy and 0.7 < px / py < 1.3


def test_cli_lobe3d(tmp_path, capsys):
    assert main(["plot", "lobe3d", "AshikhminShirley(0.1, 0.1, 1000.0, 20.0)", "--out", str(tmp_path / "a.png")]) == 0
    assert (tmp_path / "a.png").stat().st_size > 1000
    assert main(["plot", "lobe3d", "Lambert(0.1)", "Lambert(0.2)", "--out", str(tmp_path / "b.png")]) == 2
    assert "exactly one material" in capsys.readouterr().err
