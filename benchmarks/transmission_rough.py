"""The error of rough transmission's filtered lookup (glsl/transmission_thin.glsl, the glTF Sample Viewer's method)
against a float64 integral of KHR_materials_transmission's lobe over the background image (docs/transmission.md).

Scene (the twin's geometry, no GPU: the GPU equals the twin of the method within its band, `glphong.verify`): an
orthographic camera looks down -z at a thin transmissive plane (normal +z, so ``n.v = 1``) at height ``gap`` [m] above
an opaque background plane; the image is ``SIZE`` px square over [-1, 1] m.  The background is an image ``B`` (the
opaque scene's render): a checker of 8 px squares (0.1 and 1.0), a smooth gradient, a uniform 1, or a small bright
square (8 px, 50 over 0.2).

- the method: ``(1 - m) t (1 - F(n.v)) c`` times the trilinear lookup of ``B``'s pyramid of 2x2 box means at the
  pixel, ``lod = log2(SIZE) r`` (ior 1.5) (`glphong.checks.transmission_twin.background_lookup`);
- the integral: the specification's thin-walled BTDF, the light direction mirrored through the surface (the Sample
  Viewer's ``l_mirror``): ``L_t = (1 - m) t c integral (1 - F(v.h)) D(h) V(n.l', n.v) (n.l') B(hit(l)) dw_l'`` over
  the upper hemisphere, ``l'`` the mirror of the transmitted direction ``l``, ``h = normalize(l' + v)``, D and V
  Appendix B's GGX and height-correlated Smith with ``alpha = r^2``, ``F`` Schlick's with ``f0 = 0.04``; ``B(hit)``
  the background image bilinearly interpolated (clamped to its edge) where the ray from the surface point along
  ``l`` meets the background plane.  Quadrature: ``h`` by GGX's own distribution (``theta_h = atan(alpha sqrt(u/(1 -
  u)))``, ``u`` on Gauss-Legendre nodes, the azimuth on the midpoint rule), at ``N`` and ``2 N`` nodes a side: their
  difference is printed (the integral's own error).

Printed per background, roughness and gap: the relative RMS error over the plane's pixels ``sqrt(sum |err|^2 / sum
|exact|^2)``, the median and the largest per-pixel relative error.  Run: ``python benchmarks/transmission_rough.py``
(about two minutes on one core at the defaults).
"""
import argparse

import numpy as np

from glphong.checks.transmission_twin import background_lookup
from glphong.definitions.surface import _bilinear
from glphong.materials.gltf_transmission import background_levels, gltf_transmission_lod, gltf_transmission_weight

SIZE = 128
F0 = 0.04


def backgrounds(size):
    """The background images (row 0 at the top), dict of name to (size, size, 3)."""
    j, i = np.mgrid[0:size, 0:size]
    checker = np.where(((i // 8) + (j // 8)) % 2 == 0, 1.0, 0.1)
    gradient = 0.2 + 0.8 * (i / (size - 1)) * (0.5 + 0.5 * np.sin(j / size * 2 * np.pi))
    spot = np.full((size, size), 0.2)
    c = size // 2
    spot[c - 4:c + 4, c + 8:c + 16] = 50.0
    return {name: np.repeat(a[..., None], 3, axis=2).astype(np.float64)
            for name, a in (("uniform", np.ones((size, size))), ("gradient", gradient), ("checker", checker),
                            ("bright square", spot))}


def _ggx(n_dot_h, alpha):
    a2 = alpha * alpha
    d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0
    return a2 / (np.pi * d * d)


def _visibility(n_dot_l, n_dot_v, alpha):
    a2 = alpha * alpha
    return 0.5 / (n_dot_v * np.sqrt(n_dot_l ** 2 * (1 - a2) + a2) + n_dot_l * np.sqrt(n_dot_v ** 2 * (1 - a2) + a2))


def exact(image, xy, gap, roughness, nodes):
    """The integral (module) at surface points ``xy`` (P, 2) [m], (P, 3), for c = t = 1, m = 0."""
    alpha = roughness ** 2
    u, wu = np.polynomial.legendre.leggauss(nodes)
    u, wu = 0.5 * (u + 1.0), 0.5 * wu
    phi = (np.arange(2 * nodes) + 0.5) / (2 * nodes) * 2 * np.pi
    wphi = np.full(phi.shape, 1.0 / (2 * nodes))  # d phi / (2 pi)
    theta = np.arctan(alpha * np.sqrt(u / (1.0 - u)))
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    weight = np.outer(wu, wphi).ravel()
    h = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1).reshape(-1, 3)
    v = np.array([0.0, 0.0, 1.0])
    v_dot_h = h @ v
    lm = 2.0 * v_dot_h[:, None] * h - v  # l', the mirrored light direction
    n_dot_l = lm[:, 2]
    n_dot_h = h[:, 2]
    ok = n_dot_l > 0
    # the density D (n.h) dw_h = du dphi / (2 pi); dw_l' = 4 (v.h) dw_h
    f = np.where(ok, (1.0 - (F0 + (1.0 - F0) * (1.0 - v_dot_h) ** 5)) * _visibility(np.maximum(n_dot_l, 1e-300), 1.0,
                                                                                      alpha)
                 * n_dot_l * 4.0 * v_dot_h / n_dot_h, 0.0) * weight
    down = lm * np.array([1.0, 1.0, -1.0])  # the transmitted direction l (mirror of l' through the surface)
    reach = gap / np.maximum(-down[:, 2], 1e-300)
    height, width = image.shape[:2]
    out = np.zeros((len(xy), 3))
    for k in range(0, len(xy), 64):
        p = xy[k:k + 64]
        hit = np.clip(p[:, None, :] + reach[None, :, None] * down[None, :, :2], -4.0, 4.0)  # beyond: the edge's texel
        uv = np.stack([(hit[..., 0] + 1.0) / 2.0, (1.0 - hit[..., 1]) / 2.0], axis=-1).reshape(-1, 2)
        radiance = _bilinear(image, uv, "clamp")[0].reshape(len(p), -1, 3)
        out[k:k + 64] = np.einsum("pkc,k->pc", radiance, f)
    return out


def method(image, rows, columns, roughness):
    """The twin of the GPU's lookup (module), (P, 3), for c = t = 1, m = 0, n.v = 1."""
    height, width = image.shape[:2]
    levels = background_levels(image[::-1])  # GL row order
    uv = np.stack([(columns + 0.5) / width, (height - 1 - rows + 0.5) / height], axis=1)
    lod = gltf_transmission_lod(np.full(len(rows), roughness, np.float32), np.float32(1.5), np.log2(width))
    looked = background_lookup(levels, uv, lod.astype(np.float64))[0]
    return gltf_transmission_weight(np.ones(len(rows)), np.ones(3), 0.0, 1.0, 1.5) * looked


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--nodes", type=int, default=48, help="quadrature nodes along theta_h (2x along phi)")
    parser.add_argument("--step", type=int, default=4, help="every step-th pixel of the plane, each way")
    args = parser.parse_args()
    size = SIZE
    j, i = np.mgrid[size // 4:3 * size // 4:args.step, size // 4:3 * size // 4:args.step]
    rows, columns = j.ravel(), i.ravel()
    xy = np.stack([(columns + 0.5) / size * 2 - 1, 1 - (rows + 0.5) / size * 2], axis=1)
    print(f"{size} px, {len(rows)} pixels of the plane, {args.nodes} x {2 * args.nodes} nodes (checked at twice)")
    print("| background | roughness | gap [m] | RMS | median | worst | quadrature |")
    print("|-|-|-|-|-|-|-|")
    for name, image in backgrounds(size).items():
        for roughness in (0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0):
            for gap in ((0.1,) if name == "uniform" else (0.02, 0.1, 0.5)):
                ref = exact(image, xy, gap, roughness, args.nodes)
                finer = exact(image, xy, gap, roughness, 2 * args.nodes)
                quadrature = np.max(np.abs(ref - finer) / np.abs(finer))
                got = method(image, rows, columns, roughness)
                err = got - finer
                rel = np.abs(err) / np.abs(finer)
                rms = np.sqrt(np.sum(err ** 2) / np.sum(finer ** 2))
                print(f"| {name} | {roughness:g} | {gap:g} | {100 * rms:.3g} % | {100 * np.median(rel):.3g} % | "
                      f"{100 * rel.max():.3g} % | {quadrature:.1e} |", flush=True)


if __name__ == "__main__":
    main()
