"""Plots a person would rather look at: BRDF lobes in the plane of incidence and albedo against angle.

matplotlib is imported here only (and only when a plot is drawn), with the non-interactive Agg backend.

- `lobe_curves` / `plot_lobes`: ``f_r(wi, wo) cos(theta_o)`` for ``wo`` swept through the plane of incidence
  (``theta_o`` from -90 to 90 degrees; negative on the light's side), the lecture's "effect of q" and
  "Phong against Blinn-Torrance" slides; a polar plot whose radius is the reflected radiance per unit
  irradiance [1/sr].
- `plot_albedo`: the directional albedo `glphong.analysis.albedo` against the incident angle.
- `plot_gallery`: the lobe of every built-in model of the gallery at one incident angle, one panel each.
- `lobe_surface` / `plot_lobe_3d`: the whole lobe over the hemisphere as a 3D surface (radius ``f_r
  cos(theta_o)`` in the direction ``wo``), where a plane of incidence hides what matters: anisotropic
  lobes (Ward, Ashikhmin-Shirley) and off-plane structure of measured tables.
"""
import numpy as np
from glphong.analysis.gallery import GALLERY
from glphong.analysis.questions import albedo, f_r

__all__ = ["lobe_curves", "plot_lobes", "plot_albedo", "plot_gallery", "lobe_surface", "plot_lobe_3d"]


def lobe_curves(material, theta_i, count=721, tangent=(1.0, 0.0, 0.0)):
    """The lobe of ``material`` in the plane of incidence (x-z plane, normal +z, light from -x).

    Parameters
    ----------
    material : glphong.materials.Material
    theta_i : float
        Incident angle [rad], in [0, pi/2).
    count : int
        Samples of ``theta_o`` in (-pi/2, pi/2).

    Returns
    -------
    theta_o : (count,) ndarray
        Viewing angle [rad]: positive on the side of the mirror direction, negative on the light's.
    value : (count, 3) ndarray
        ``f_r cos(theta_o)`` [1/sr] from the float64 twin (0 where ``n.l <= 0``).
    """

    if not 0.0 <= theta_i < np.pi / 2:
        raise ValueError(f"theta_i must be in [0, pi/2) rad (got {theta_i!r})")
    theta_o = np.linspace(-np.pi / 2, np.pi / 2, count + 2)[1:-1]
    wi = np.repeat([[-np.sin(theta_i), 0.0, np.cos(theta_i)]], count, axis=0)
    wo = np.stack([np.sin(theta_o), np.zeros(count), np.cos(theta_o)], axis=-1)
    return theta_o, f_r(material, wi, wo, tangent) * np.cos(theta_o)[:, None]


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _polar(ax, curves, theta_i, title):
    for label, (theta_o, value) in curves.items():
        ax.plot(theta_o, value.mean(axis=1), label=label)
    ax.set_thetalim(-np.pi / 2, np.pi / 2)
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.plot([-theta_i, -theta_i], [0, ax.get_rmax()], color="0.6", lw=0.8, ls="--")
    from matplotlib.ticker import MaxNLocator

    ax.yaxis.set_major_locator(MaxNLocator(3))
    ax.tick_params(labelsize=6)
    ax.set_title(title, fontsize=9)


def plot_lobes(materials, theta_i, path, title=None):
    """Polar plot of several materials' lobes at one incident angle; returns the curves by label.

    Parameters
    ----------
    materials : dict of str to Material, or sequence of Material
    theta_i : float
        Incident angle [rad].
    path : str
        PNG path.
    """
    if not isinstance(materials, dict):
        materials = {repr(m): m for m in materials}
    curves = {label: lobe_curves(m, theta_i) for label, m in materials.items()}
    plt = _pyplot()
    fig, ax = plt.subplots(subplot_kw={"projection": "polar"}, figsize=(6.4, 4.2))
    _polar(ax, curves, theta_i, title or f"f_r cos(theta_o) [1/sr] in the plane of incidence, "
                                          f"theta_i = {np.degrees(theta_i):.0f} deg (dashed: the light)")
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.1, -0.15))
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return curves


def plot_albedo(materials, path, theta_i=None):
    """Directional albedo (mean over channels) against the incident angle; returns ``(theta_i, {label: (N, 3)})``."""

    if not isinstance(materials, dict):
        materials = {repr(m): m for m in materials}
    theta_i = np.radians(np.linspace(0.0, 89.0, 36)) if theta_i is None else np.asarray(theta_i, dtype=np.float64)
    values = {label: albedo(m, theta_i) for label, m in materials.items()}
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for label, a in values.items():
        ax.plot(np.degrees(theta_i), a.mean(axis=1), label=label)
    ax.axhline(1.0, color="0.5", lw=0.8, ls="--")
    ax.set_xlabel("incident angle theta_i [deg]")
    ax.set_ylabel("directional albedo (white furnace: <= 1)")
    ax.legend(fontsize=7)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return theta_i, values


def plot_gallery(path, theta_i=np.radians(45.0), columns=4):
    """One polar lobe panel per entry of `glphong.analysis.gallery.GALLERY` at ``theta_i``; returns the curves by label."""

    entries = []
    for label, factory in GALLERY:
        try:
            entries.append((label, factory()))
        except AttributeError:
            continue
    plt = _pyplot()
    rows = -(-len(entries) // columns)
    fig, axes = plt.subplots(rows, columns, subplot_kw={"projection": "polar"}, figsize=(3.0 * columns, 2.4 * rows))
    curves = {}
    for ax, (label, material) in zip(np.ravel(axes), entries):
        curves[label] = lobe_curves(material, theta_i)
        _polar(ax, {label: curves[label]}, theta_i, label)
    for ax in np.ravel(axes)[len(entries):]:
        ax.set_visible(False)
    fig.suptitle(f"f_r cos(theta_o) in the plane of incidence, theta_i = {np.degrees(theta_i):.0f} deg", fontsize=10)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return curves


def lobe_surface(material, theta_i, rows=61, columns=121, tangent=(1.0, 0.0, 0.0)):
    """The lobe of ``material`` over the whole upper hemisphere (normal +z, tangent +x, light from -x).

    Parameters
    ----------
    material : glphong.materials.Material
    theta_i : float
        Incident angle [rad], in [0, pi/2).
    rows, columns : int
        Samples of ``theta_o`` in [0, pi/2) and of ``phi_o`` in [0, 2 pi].

    Returns
    -------
    wo : (rows, columns, 3) ndarray
        Unit viewing directions.
    value : (rows, columns, 3) ndarray
        ``f_r cos(theta_o)`` [1/sr] from the float64 twin.
    """

    if not 0.0 <= theta_i < np.pi / 2:
        raise ValueError(f"theta_i must be in [0, pi/2) rad (got {theta_i!r})")
    theta, phi = np.meshgrid(np.linspace(0.0, np.pi / 2, rows, endpoint=False), np.linspace(0.0, 2 * np.pi, columns),
                             indexing="ij")
    wo = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)
    wi = np.broadcast_to([-np.sin(theta_i), 0.0, np.cos(theta_i)], wo.shape)
    value = f_r(material, wi.reshape(-1, 3), wo.reshape(-1, 3), tangent).reshape(wo.shape) * np.cos(theta)[..., None]
    return wo, value


def plot_lobe_3d(material, theta_i, path, title=None):
    """The lobe as a surface: radius ``f_r cos(theta_o)`` (mean over channels) in each direction ``wo``, the
    light as a line; returns `lobe_surface`'s ``(wo, value)``."""
    wo, value = lobe_surface(material, theta_i)
    radius = value.mean(axis=-1)
    points = wo * radius[..., None]
    plt = _pyplot()
    from matplotlib import cm

    fig = plt.figure(figsize=(6.0, 5.0))
    ax = fig.add_subplot(projection="3d")
    top = radius.max() if radius.max() > 0 else 1.0
    ax.plot_surface(points[..., 0], points[..., 1], points[..., 2], facecolors=cm.viridis(radius / top),
                    rstride=1, cstride=1, linewidth=0, antialiased=False, shade=False)
    light = np.array([-np.sin(theta_i), 0.0, np.cos(theta_i)]) * top
    ax.plot([0, light[0]], [0, light[1]], [0, light[2]], color="0.3", lw=1.2, ls="--")
    reach = max(np.abs(points).max(), top) * 1.05  # one scale on every axis: the lobe's true shape
    ax.set_xlim(-reach, reach)
    ax.set_ylim(-reach, reach)
    ax.set_zlim(0, reach)
    ax.set_box_aspect((2, 2, 1))
    ax.set_xlabel("t (x)")
    ax.set_ylabel("b (y)")
    ax.set_zlabel("n (z)")
    ax.tick_params(labelsize=6)
    ax.set_title(title or f"{material!r}\nf_r cos(theta_o) [1/sr], theta_i = {np.degrees(theta_i):.0f} deg "
                          "(dashed: the light)", fontsize=8)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return wo, value
