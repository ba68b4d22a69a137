"""Tangent frames and texture coordinates: from the mesh to the shader and its twin (docs/design.md section 8).

What is tested:

- `glphong.scene.geometry.tangents_from_uvs` (Lengyel's method): the plane's UVs give t = +x, w = +1; UVs
  mirrored in u give t = -x, w = -1; on an icosphere with spherical UVs the derived tangent agrees
  with the analytic dp/dphi away from the poles and the u seam (measured tolerance below), the
  handedness is the one the UV map has, and it matches `glphong.primitives.sphere`'s analytic
  tangents; t is orthogonal to the normal; degenerate UV triangles give t = 0 and no NaN.
- common.glsl ``frame_from_tangent`` on the GPU (`glphong.testing.probe`) against its numpy twin on seeded
  random normals and tangents and on the edge cases: tangent parallel to n (Duff et al.'s fallback
  basis), zero tangent, negative and zero handedness; (t, b, n) orthonormal.
- A user material that needs ``'tangent'`` (``test_aniso``) defined through `MaterialModel`: its
  GLSL against its twin (`assert_twin_matches`), renders of the sphere and the plane cross-checked
  pixel by pixel (`assert_render_matches`) on both backends, the program key and the G-buffer carry
  the tangent (and a scene of built-in materials does not), a mesh without tangents or UVs is
  refused with a message saying what to do, and the image follows the tangent (closed form).
- A user material that needs ``'uv'`` (``test_uv_ramp``): render cross-check, G-buffer uv, and the
  radiance across the plane against its closed form.
- Per-vertex (Gouraud) shading of the anisotropic material: finite, equal to the per-pixel render
  where the radiance is constant, and following the tangent.
"""
import numpy as np
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.testing import probe
from glphong import reference as ref
from glphong.scene.geometry import MeshData, tangents_from_uvs
from glphong.materials import MaterialModel, Param, Properties
from glphong.testing import assert_render_matches, assert_twin_matches, direction_sets
from glphong.checks.tolerances import EPS
from glphong.shaders.binding import binding

RNG_SEED = 20261207
BACKENDS = ("egl", "osmesa")


# --------------------------------------------------------------------------- user materials
class Aniso(MaterialModel):
    """``k (n.l) (1 + a (l.t)^2)``: brighter where the light lies along the tangent."""

    name = "test_aniso"
    params = (Param("k", "rgb", low=0.0, unit="1/sr", doc="the BRDF value with the light across the tangent"),
              Param("a", "scalar", low=0.0, high=10.0, doc="anisotropy along the tangent"))
    needs = ("tangent",)
    vanishes_with = ("k",)
    properties = Properties(reciprocal=False, isotropic=False)
    glsl = """
    vec3 test_aniso_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        float c = dot(wi, f.t);
        return u_test_aniso_k * (n_dot_l * (1.0 + u_test_aniso_a * (c * c)));
    }"""

    def response(self, f, wi, wo, n_dot_l, p):
        c = np.sum(wi * f.t, axis=-1)
        return p.k * (n_dot_l * (1.0 + p.a * (c * c)))[..., None]


class UvRamp(MaterialModel):
    """``k (n.l) (0.5 + 0.5 u)``: a ramp along the texture's u."""

    name = "test_uv_ramp"
    params = (Param("k", "rgb", low=0.0, unit="1/sr", doc="the BRDF value at u = 1"),)
    needs = ("uv",)
    vanishes_with = ("k",)
    glsl = """
    vec3 test_uv_ramp_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
    {
        return u_test_uv_ramp_k * (n_dot_l * (0.5 + 0.5 * f.uv.x));
    }"""

    def response(self, f, wi, wo, n_dot_l, p):
        return p.k * (n_dot_l * (0.5 + 0.5 * f.uv[:, 0]))[..., None]


ANISO = Aniso(k=(0.3, 0.2, 0.1), a=4.0)
RAMP = UvRamp(k=(0.4, 0.3, 0.2))
#: the light of the closed-form checks: toward (sin 45 deg, 0, cos 45 deg), E = 2 W/m^2
LIGHT_THETA = np.radians(45.0)
LIGHT_E = 2.0


# --------------------------------------------------------------------------- helpers
def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def spherical_icosphere(subdivisions):
    """A trimesh icosphere with u = azimuth / (2 pi), v = polar angle / pi, as MeshData (smooth normals)."""
    mesh = trimesh.creation.icosphere(subdivisions)
    p = np.asarray(mesh.vertices)
    phi = np.arctan2(p[:, 1], p[:, 0]) % (2 * np.pi)
    theta = np.arccos(np.clip(p[:, 2] / np.linalg.norm(p, axis=1), -1.0, 1.0))
    uvs = np.stack([phi / (2 * np.pi), theta / np.pi], axis=1)
    return MeshData(p, mesh.vertex_normals, mesh.faces, uvs=uvs), theta


def away_from_singularities(mesh, theta, pole_margin_deg=20.0):
    """Vertices more than ``pole_margin_deg`` from the poles and on no triangle that spans the u seam."""
    faces = mesh.indices.astype(np.int64)
    u = mesh.uvs[:, 0].astype(np.float64)
    seam = np.zeros(len(u), bool)
    seam[faces[np.ptp(u[faces], axis=1) > 0.5].ravel()] = True
    deg = np.degrees(theta)
    return ~seam & (deg > pole_margin_deg) & (deg < 180.0 - pole_margin_deg)


def d_p_d_phi(p):
    p = np.asarray(p, dtype=np.float64)
    return unit(np.stack([-p[:, 1], p[:, 0], np.zeros(len(p))], axis=1))


def angle_deg(a, b):
    return np.degrees(np.arccos(np.clip(np.sum(unit(a) * unit(b), axis=1), -1.0, 1.0)))


def plane_with(tangent=None, uvs=None, segments=1):
    """`primitives.plane` (2 m, facing +z) with other tangents or UVs (None: derived from the UVs)."""
    base = primitives.plane(2.0, segments)
    count = len(base.positions)
    return MeshData(base.positions, base.normals, base.indices, uvs=base.uvs if uvs is None else uvs,
                    tangents=None if tangent is None else np.tile(tangent, (count, 1)))


def top_view_scene(mesh, material):
    """The plane seen from above, lit by one directional light toward (sin theta, 0, cos theta)."""
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 2.5), (0.0, 0.0, 0.0), yfov=np.radians(40))
    toward = (np.sin(LIGHT_THETA), 0.0, np.cos(LIGHT_THETA))
    scene = glphong.Scene(camera, lights=[glphong.DirectionalLight(tuple(-c for c in toward), irradiance=LIGHT_E)])
    scene.add(mesh, material)
    return scene


def oblique_scene(material, sphere=True, plane=True):
    """The sphere (seen obliquely, pole and equator in view) on the plane, two lights and ambient."""
    camera = glphong.PerspectiveCamera.look_at((1.2, -2.6, 2.4), (0.0, 0.0, 0.3), up=(0.0, 0.0, 1.0),
                                               yfov=np.radians(50))
    scene = glphong.Scene(camera, lights=[glphong.PointLight((2.0, -1.0, 3.0), power=150.0),
                                          glphong.DirectionalLight((-0.5, 0.7, -1.0), irradiance=0.6)],
                          ambient=glphong.AmbientLight(0.05))
    if sphere:
        pose = np.eye(4)
        pose[:3, 3] = (0.0, 0.0, 0.8)
        scene.add(primitives.sphere(4, radius=0.7), material, pose=pose, name="sphere")
    if plane:
        scene.add(primitives.plane(3.0, 2), material, name="plane")
    return scene


@pytest.fixture(scope="module", params=BACKENDS)
def renderer(request, module_make_renderer):
    """A 96 x 96 per-pixel renderer on each backend, shared by this module's render tests."""
    return module_make_renderer(96, 96, request.param)


# --------------------------------------------------------------------------- 1. tangents_from_uvs
def test_plane_uvs_give_plus_x_and_mirrored_uvs_give_minus_x():
    plane = primitives.plane(2.0, 4)
    t = tangents_from_uvs(plane.positions, plane.normals, plane.indices, plane.uvs)
    np.testing.assert_allclose(t, np.tile([1.0, 0.0, 0.0, 1.0], (len(t), 1)), rtol=0, atol=1e-7)
    # mirrored in u: dp/du = -x and dp/dv = +y, so t = -x and (n x t).B = (-y).(+y) < 0: w = -1
    mirrored = plane.uvs * np.array([-1.0, 1.0]) + np.array([1.0, 0.0])
    t = tangents_from_uvs(plane.positions, plane.normals, plane.indices, mirrored)
    np.testing.assert_allclose(t, np.tile([-1.0, 0.0, 0.0, -1.0], (len(t), 1)), rtol=0, atol=1e-7)
    # the derived tangents reach MeshData.tangents when none are given
    mesh = plane_with(uvs=mirrored, segments=4)
    assert mesh.has_tangents
    np.testing.assert_array_equal(mesh.tangents, t)
    # and the primitive's analytic tangents are the ones its UVs derive
    np.testing.assert_allclose(plane.tangents, t * np.array([-1.0, 1.0, 1.0, -1.0]), rtol=0, atol=1e-7)


def test_icosphere_tangents_follow_d_p_d_phi():
    """Measured (subdivision 3, 20 deg pole margin, seam triangles left out): at most 0.81 deg from
    dp/dphi at 567 of 642 vertices; asserted below 1.5 deg, and below 2 deg at every vertex further
    than 10 deg from the poles (measured 1.08 deg).  The UV map (v southward) has handedness -1."""
    mesh, theta = spherical_icosphere(3)
    t = mesh.tangents
    assert np.all(np.isfinite(t))
    keep = away_from_singularities(mesh, theta)
    assert keep.sum() > 500
    angles = angle_deg(t[keep, :3], d_p_d_phi(mesh.positions[keep]))
    assert angles.max() < 1.5, angles.max()
    wider = away_from_singularities(mesh, theta, pole_margin_deg=10.0)
    assert angle_deg(t[wider, :3], d_p_d_phi(mesh.positions[wider])).max() < 2.0
    # (n x t).(dp/dv) < 0: dp/dv points south, n x dp/dphi north
    np.testing.assert_array_equal(t[keep, 3], -1.0)
    b = t[keep, 3:] * np.cross(unit(mesh.normals[keep]), t[keep, :3])
    south = unit(np.stack([np.cos(theta[keep]) * mesh.positions[keep, 0], np.cos(theta[keep]) * mesh.positions[keep, 1],
                           -np.sin(theta[keep]) ** 2], axis=1))
    assert np.all(np.sum(b * south, axis=1) > 0.99)
    # a refinement halves the angle: the method converges to dp/dphi (measured 0.81 -> 0.42 deg)
    fine, fine_theta = spherical_icosphere(4)
    keep = away_from_singularities(fine, fine_theta)
    assert angle_deg(fine.tangents[keep, :3], d_p_d_phi(fine.positions[keep])).max() < 0.75


def test_sphere_primitive_tangents_match_its_uvs():
    """`primitives.sphere`'s analytic tangents are the ones Lengyel's method derives from its own
    UVs: same direction (within 0.5 deg at level 4 away from poles and seam) and same handedness."""
    sphere = primitives.sphere(4)
    theta = np.arccos(np.clip(sphere.normals[:, 2].astype(np.float64), -1.0, 1.0))
    derived = tangents_from_uvs(sphere.positions, sphere.normals, sphere.indices, sphere.uvs)
    keep = away_from_singularities(sphere, theta)
    assert keep.sum() > 2000
    assert angle_deg(derived[keep, :3], sphere.tangents[keep, :3]).max() < 0.5
    np.testing.assert_array_equal(sphere.tangents[keep, 3], derived[keep, 3])
    # the poles (rho = 0) carry t = 0: the shader falls back to a basis around n there
    rho = np.hypot(sphere.normals[:, 0], sphere.normals[:, 1])
    assert (rho == 0).sum() == 2 and np.all(sphere.tangents[rho == 0, :3] == 0)


@pytest.mark.parametrize("which", ["plane", "icosphere", "sphere"])
def test_derived_tangents_are_unit_and_orthogonal_to_the_normal(which):
    if which == "plane":
        mesh = primitives.plane(2.0, 4)
    elif which == "icosphere":
        mesh = spherical_icosphere(3)[0]
    else:
        mesh = primitives.sphere(3)
    t = tangents_from_uvs(mesh.positions, mesh.normals, mesh.indices, mesh.uvs).astype(np.float64)
    n = unit(mesh.normals)
    length = np.linalg.norm(t[:, :3], axis=1)
    usable = length > 0
    assert usable.mean() > 0.99
    np.testing.assert_allclose(length[usable], 1.0, rtol=0, atol=1e-6)
    assert np.abs(np.sum(n * t[:, :3], axis=1)).max() < 1e-6
    assert set(np.unique(t[:, 3])) <= {-1.0, 1.0}


def test_degenerate_uv_triangles_give_zero_tangent_without_nan():
    # two triangles sharing vertex 0: the first with a proper UV map, the second with collinear UVs
    # (det = 0); vertex 3 lies only on the degenerate one, a third triangle with all-equal UVs
    positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, -1, 0], [2, 2, 0], [3, 2, 0], [2, 3, 0]]
    normals = [[0, 0, 1]] * 7
    faces = [[0, 1, 2], [0, 3, 1], [4, 5, 6]]
    uvs = [[0, 0], [1, 0], [0, 1], [-1, 0], [0.5, 0.5], [0.5, 0.5], [0.5, 0.5]]
    with np.errstate(all="raise"):  # no division by zero, no invalid operation on the way
        t = tangents_from_uvs(positions, normals, faces, uvs)
    assert np.all(np.isfinite(t))
    np.testing.assert_allclose(t[[0, 1, 2]], np.tile([1.0, 0.0, 0.0, 1.0], (3, 1)), rtol=0, atol=1e-7)
    np.testing.assert_array_equal(t[[3, 4, 5, 6], :3], 0.0)
    np.testing.assert_array_equal(t[:, 3], 1.0)  # w = +1 where (n x t).B is 0
    # a mesh whose whole UV map is degenerate: t = 0 everywhere, finite
    zero = plane_with(uvs=np.zeros((4, 2)))
    assert np.all(np.isfinite(zero.tangents)) and np.all(zero.tangents[:, :3] == 0)


# --------------------------------------------------------------------------- 2. frame_from_tangent
def _frame_inputs():
    """Seeded random unit normals and raw tangents (any length, either handedness), then the edges."""
    rng = np.random.default_rng(RNG_SEED)
    count = 1000
    n = unit(rng.normal(size=(count, 3)))
    xyz = unit(rng.normal(size=(count, 3))) * 10.0 ** rng.uniform(-3, 3, size=(count, 1))
    w = rng.choice([-1.0, 1.0], size=(count, 1))
    random = np.concatenate([xyz, w], axis=1)
    edge_n, edge_t, labels = [], [], []

    def edge(label, normal, tangent):
        edge_n.append(unit(normal))
        edge_t.append(tangent)
        labels.append(label)

    axis_normals = [(0, 0, 1), (0, 0, -1), (1, 0, 0), (0, 1, 0), (0, -1e-7, -1), (1e-7, 0, 1)]
    for normal in axis_normals + [tuple(v) for v in unit(rng.normal(size=(6, 3)))]:
        nn = unit(normal)
        for scale in (1.0, -2.5, 1e-3, 1e3):
            edge("parallel", normal, (*(scale * nn), 1.0))
        edge("parallel, w < 0", normal, (*nn, -1.0))
        edge("zero", normal, (0.0, 0.0, 0.0, 1.0))
        edge("zero, w < 0", normal, (0.0, 0.0, 0.0, -1.0))
    for normal in [(0, 0, 1), (0.6, 0, 0.8), (-0.36, 0.48, -0.8)]:
        edge("w = 0 counts as +1", normal, (0.0, 1.0, 0.0, 0.0))
        edge("w < 0", normal, (0.0, 1.0, 0.0, -1.0))
        edge("tiny", normal, (1e-30, 2e-30, -1e-30, 1.0))
    n = np.concatenate([n, edge_n]).astype(np.float32)
    tangent = np.concatenate([random, edge_t]).astype(np.float32)
    return n, tangent, np.array(["random"] * count + labels)


def test_frame_from_tangent_against_twin(session_gl):
    """GPU against the float64 twin on the same float32 inputs.

    Where the projection is used, the GPU's t may differ by the conditioning of Gram-Schmidt:
    asserted ``|dt| <= 4 eps (1 + cot)`` per component, ``cot = |n.T| / |T - (n.T) n|``, eps = 2^-24
    (llvmpipe: at most 1.8 eps scaled, 1.0e-6 absolute on the random set, cot up to 19); on the
    fallback (parallel and zero tangents) ``|dt| <= 4 eps`` (measured 0.9 eps).  The same for
    ``b = sign(w) n x t`` (w = 0 counts as +1).
    """
    n, tangent, labels = _frame_inputs()
    gpu = probe.evaluate(session_gl, "frame_from_tangent", n=n, tangent=tangent)
    n64, tangent64 = n.astype(np.float64), tangent.astype(np.float64)
    t, b = ref.frame_from_tangent(n64, tangent64)
    along = np.sum(n64 * tangent64[:, :3], axis=1)
    across = np.linalg.norm(tangent64[:, :3] - along[:, None] * n64, axis=1)
    fallback = np.char.startswith(labels, "parallel") | np.char.startswith(labels, "zero")
    with np.errstate(divide="ignore", invalid="ignore"):
        condition = np.where(fallback, 0.0, np.abs(along) / across)
    tol = np.where(fallback, 4 * EPS, 4 * EPS * (1 + condition))[:, None]
    for name, gpu_v, twin_v in (("t", gpu["t"], t), ("b", gpu["b"], b)):
        err = np.abs(gpu_v.astype(np.float64) - twin_v)
        bad = np.any(err > tol, axis=1)
        assert not bad.any(), (name, labels[bad][:5], n[bad][:3], tangent[bad][:3], gpu_v[bad][:3], twin_v[bad][:3])
    # the edges really are the cases they claim: parallel and zero tangents take the fallback
    duff = _duff_tangent(n64)
    np.testing.assert_allclose(t[fallback], duff[fallback], rtol=0, atol=1e-12)
    # and the random ones the projection
    random = labels == "random"
    np.testing.assert_allclose(t[random], unit(tangent64[random, :3] - along[random, None] * n64[random]), atol=1e-12)


def _duff_tangent(n):
    """Duff et al. 2017, listing 3: b1 = (1 + s x^2 a, s x y a, -s x), s = sign(z), a = -1 / (s + z)."""
    s = np.where(n[:, 2] >= 0, 1.0, -1.0)
    a = -1.0 / (s + n[:, 2])
    return np.stack([1 + s * n[:, 0] ** 2 * a, s * n[:, 0] * n[:, 1] * a, -s * n[:, 0]], axis=1)


def test_frame_from_tangent_is_orthonormal_on_the_gpu(session_gl):
    """(t, b, n) orthonormal on the GPU: ``||t| - 1|``, ``||b| - 1|`` <= 4 eps (measured 1.8 and 2.5
    eps); ``|n.t|``, ``|t.b|``, ``|n.b|`` <= 4 eps (1 + cot), cot = |n.T| / |T_perp| the conditioning,
    0 on the fallback (measured at most 1.6 eps scaled); ``b = sign(w) n x t`` to 4 eps (measured
    1.2 eps); flipping w flips b and nothing else."""
    n, tangent, labels = _frame_inputs()
    out = probe.evaluate(session_gl, "frame_from_tangent", n=n, tangent=tangent)
    t, b = out["t"].astype(np.float64), out["b"].astype(np.float64)
    n64 = n.astype(np.float64)
    along = np.sum(n64 * tangent[:, :3], axis=1)
    across = np.linalg.norm(tangent[:, :3] - along[:, None] * n64, axis=1)
    projected = ~(np.char.startswith(labels, "parallel") | np.char.startswith(labels, "zero"))
    with np.errstate(divide="ignore", invalid="ignore"):
        cot = np.where(projected, np.abs(along) / across, 0.0)
    assert np.all(np.isfinite(t)) and np.all(np.isfinite(b))
    np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(np.linalg.norm(b, axis=1), 1.0, rtol=0, atol=4 * EPS)
    limit = 4 * EPS * (1 + cot)
    for a, c in ((n64, t), (t, b), (n64, b)):
        assert np.all(np.abs(np.sum(a * c, axis=1)) <= limit)
    sign = np.where(tangent[:, 3] < 0, -1.0, 1.0)[:, None]
    np.testing.assert_allclose(b, sign * np.cross(n64, t), rtol=0, atol=4 * EPS)
    # the handedness really flips b: the same frame with w = +1 and w = -1
    flipped = probe.evaluate(session_gl, "frame_from_tangent", n=n, tangent=tangent * np.array([1, 1, 1, -1], np.float32))
    np.testing.assert_array_equal(flipped["t"], out["t"])
    np.testing.assert_array_equal(flipped["b"][tangent[:, 3] != 0], -out["b"][tangent[:, 3] != 0])


def test_shading_frame_twin_reads_the_key():
    """`reference.shading_frame` builds t, b only where the key has a tangent, uv only with has_uv."""
    from glphong.shaders.key import response_key

    n = np.array([[0.0, 0.0, 1.0]])
    tangent = np.array([[0.0, 2.0, 0.5, -1.0]])
    uv = np.array([[0.25, 0.75]])
    f = ref.shading_frame(n, tangent, uv, response_key(ANISO))
    np.testing.assert_allclose(f.t, [[0.0, 1.0, 0.0]], atol=1e-15)
    np.testing.assert_allclose(f.b, [[1.0, 0.0, 0.0]], atol=1e-15)  # -(z x y) = +x
    assert f.uv is None
    f = ref.shading_frame(n, tangent, uv, response_key(RAMP))
    assert f.t is None and f.b is None
    np.testing.assert_array_equal(f.uv, uv)


# --------------------------------------------------------------------------- 3. a material that needs 'tangent'
@pytest.mark.parametrize("tangent", [(1.0, 0.0, 0.0), (0.3, 0.8, 0.5, -1.0), (0.0, 0.0, 1.0), "random"])
def test_aniso_twin_matches(glphong_backend, tangent):
    """GLSL against twin on glphong's direction sets, with the tangent along x, oblique and mirrored,
    parallel to the normal (the fallback), and a seeded random raw tangent per pair."""
    if tangent == "random":
        count = len(direction_sets(2000, 0)[0])
        rng = np.random.default_rng(RNG_SEED + 1)
        tangent = np.concatenate([rng.normal(size=(count, 3)), rng.choice([-1.0, 1.0], size=(count, 1))], axis=1)
    figures = assert_twin_matches(ANISO, backend=glphong_backend, tangent=tangent)
    assert figures["nonzero"] > 2000
    assert figures["max_relative_error"] < 1e-6, figures  # measured 2.2e-7


def test_aniso_twin_follows_the_tangent():
    """The twin is the closed form: with wi = (sin th, 0, cos th), t = x gives k cos th (1 + a sin^2 th),
    t = y gives k cos th."""
    wi = np.array([[np.sin(LIGHT_THETA), 0.0, np.cos(LIGHT_THETA)]])
    wo = np.array([[0.0, 0.0, 1.0]])
    along = glphong.testing.evaluate(ANISO, wi, wo, tangent=(1.0, 0.0, 0.0), twin=True)
    across = glphong.testing.evaluate(ANISO, wi, wo, tangent=(0.0, 1.0, 0.0), twin=True)
    k = np.array(ANISO.k)
    np.testing.assert_allclose(along[0], k * np.cos(LIGHT_THETA) * (1 + 4.0 * np.sin(LIGHT_THETA) ** 2), rtol=1e-7)
    np.testing.assert_allclose(across[0], k * np.cos(LIGHT_THETA), rtol=1e-7)


def test_aniso_render_matches_twin(renderer):
    scene = oblique_scene(ANISO)
    report = assert_render_matches(scene, renderer)
    assert report.covered_pixels > 4000
    assert report.nonfinite_count == 0
    assert report.max_relative_error < 1e-4, str(report)  # measured 4.1e-6
    gbuffer = renderer.gbuffer(scene)
    assert gbuffer.tangent is not None and gbuffer.tangent.shape == (96, 96, 4)
    assert gbuffer.uv is None  # no term needs uv
    # the plane's tangent is +x, w = +1; the sphere's dp/dphi (w = -1), orthogonal to its normal
    on_plane = gbuffer.object_index == 1
    on_sphere = gbuffer.object_index == 0
    assert on_plane.sum() > 1000 and on_sphere.sum() > 1000
    np.testing.assert_allclose(gbuffer.tangent[on_plane], np.tile([1.0, 0.0, 0.0, 1.0], (on_plane.sum(), 1)),
                               rtol=0, atol=1e-6)
    sphere_t = gbuffer.tangent[on_sphere].astype(np.float64)
    np.testing.assert_allclose(sphere_t[:, 3], -1.0, rtol=0, atol=1e-6)  # interpolated: -1 to an ulp
    # interpolated tangents are orthogonal to the interpolated normal up to the tessellation (p99 1.8e-3)
    assert np.percentile(np.abs(np.sum(unit(sphere_t[:, :3]) * gbuffer.normal[on_sphere], axis=1)), 99) < 0.01
    # the covered pixels are lit: the cross-check is not of a dark image
    assert np.percentile(report.reference[report.mask], 50) > 1e-3


def test_aniso_program_key_and_gbuffer_carry_the_tangent(renderer):
    scene = oblique_scene(ANISO, sphere=False)
    obj = scene.objects[0]
    key = renderer.program_key(scene, obj)
    assert key.has_tangent and not key.has_uv
    assert "in_tangent" in key.attributes() and "in_uv" not in key.attributes()
    gkey = renderer.program_key(scene, obj, "gbuffer")
    assert gkey.has_tangent and "in_tangent" in gkey.attributes()
    assert binding(scene).gbuffer_needs() == frozenset({"tangent"})


def test_builtin_materials_have_no_tangent(renderer):
    scene = oblique_scene(glphong.Phong(kd=0.2, ks=0.5, q=30.0))
    for obj in scene.objects:
        key = renderer.program_key(scene, obj)
        assert not key.has_tangent and not key.has_uv
        assert "in_tangent" not in key.attributes() and "in_uv" not in key.attributes()
        assert not renderer.program_key(scene, obj, "gbuffer").has_tangent
    assert binding(scene).gbuffer_needs() == frozenset()
    gbuffer = renderer.gbuffer(scene)
    assert gbuffer.tangent is None and gbuffer.uv is None
    assert gbuffer.mask.sum() > 4000


def test_mesh_without_tangents_or_uvs_is_refused():
    scene = top_view_scene(primitives.plane(), ANISO)
    bare = trimesh.creation.icosphere(2)
    with pytest.raises(ValueError, match=r"'test_aniso' needs a tangent frame") as info:
        scene.add(bare, ANISO, name="bare sphere")
    message = str(info.value)
    assert "'bare sphere'" in message and "tangents=" in message and "uvs=" in message
    assert "glphong.primitives" in message
    with pytest.raises(ValueError, match=r"'test_uv_ramp' needs UVs.*uvs="):
        scene.add(bare, RAMP)
    # tangents without UVs serve the tangent term, not the uv term
    tangents_only = MeshData(bare.vertices, bare.vertex_normals, bare.faces,
                             tangents=np.tile([1.0, 0.0, 0.0], (len(bare.vertices), 1)))
    scene.add(tangents_only, ANISO)
    with pytest.raises(ValueError, match=r"'test_uv_ramp' needs UVs"):
        scene.add(tangents_only, RAMP)
    # the refused objects were not added
    assert len(scene.objects) == 2


def test_image_follows_the_tangent(renderer):
    """The plane lit from (sin 45 deg, 0, cos 45 deg) with E = 2: with t = +x the radiance is
    k E cos th (1 + a sin^2 th) = 3 k E cos th, with t = +y it is k E cos th, a factor 3 (asserted
    to 1e-5 relative against the closed form at every covered pixel, measured 7e-8; so the radiance
    changes by a factor 3, asserted > 2.9 at every pixel).
    A tangent given at 30 deg from +x gives 1 + a sin^2 th cos^2 30 deg = 2.5.  Derived from the UVs
    (no tangents given) the plane shades as t = +x; a degenerate UV map (t = 0) falls back to Duff
    et al.'s basis, whose tangent at n = +z is +x too."""
    k = np.array(ANISO.k)
    base = k * LIGHT_E * np.cos(LIGHT_THETA)
    cases = {"x": ((1.0, 0.0, 0.0, 1.0), 3.0), "y": ((0.0, 1.0, 0.0, 1.0), 1.0),
             "y mirrored": ((0.0, 1.0, 0.0, -1.0), 1.0),
             "30 deg": ((np.cos(np.radians(30)), np.sin(np.radians(30)), 0.0, 1.0), 2.5),
             "x, not unit, tilted off the plane": ((3.0, 0.0, 2.0, 1.0), 3.0)}
    frames = {}
    for label, (tangent, factor) in cases.items():
        frame = renderer.render(top_view_scene(plane_with(tangent=tangent), ANISO))
        assert frame.mask.sum() > 3000, label
        np.testing.assert_allclose(frame.radiance[frame.mask], np.broadcast_to(factor * base, (frame.mask.sum(), 3)),
                                   rtol=1e-5, err_msg=label)
        frames[label] = frame
    ratio = frames["x"].radiance[frames["x"].mask] / frames["y"].radiance[frames["y"].mask]
    assert np.all(ratio > 2.9)
    for label, mesh in (("derived from uvs", plane_with()), ("degenerate uvs", plane_with(uvs=np.zeros((4, 2))))):
        frame = renderer.render(top_view_scene(mesh, ANISO))
        np.testing.assert_allclose(frame.radiance[frame.mask], frames["x"].radiance[frame.mask], rtol=1e-6,
                                   err_msg=label)
        assert_render_matches(top_view_scene(mesh, ANISO), renderer)


# --------------------------------------------------------------------------- 4. a material that needs 'uv'
def test_uv_material_render(renderer):
    """``k (n.l) (0.5 + 0.5 u)`` on the plane seen from above: u = x / 2 + 1/2 at the G-buffer's
    position (to 1e-6; measured 1.2e-7); the radiance is ``k E cos th (0.5 + 0.5 u)`` to 1e-5 relative
    (measured 1.3e-7), and it increases with u along every image row (the camera's x is the world's x)."""
    scene = top_view_scene(primitives.plane(2.0, 2), RAMP)
    report = assert_render_matches(scene, renderer)
    assert report.covered_pixels > 3000
    gbuffer = renderer.gbuffer(scene)
    assert gbuffer.uv is not None and gbuffer.tangent is None
    mask = gbuffer.mask
    np.testing.assert_allclose(gbuffer.uv[mask, 0], gbuffer.position[mask, 0] / 2.0 + 0.5, rtol=0, atol=1e-6)
    np.testing.assert_allclose(gbuffer.uv[mask, 1], gbuffer.position[mask, 1] / 2.0 + 0.5, rtol=0, atol=1e-6)
    u = gbuffer.uv[mask, 0].astype(np.float64)
    want = np.array(RAMP.k) * LIGHT_E * np.cos(LIGHT_THETA) * (0.5 + 0.5 * u)[:, None]
    np.testing.assert_allclose(report.gpu[mask], want, rtol=1e-5)
    assert u.min() < 0.1 and u.max() > 0.9  # the whole ramp is in view
    rows = np.nonzero(mask.all(axis=1))[0]
    assert len(rows) > 40
    red = report.gpu[rows[:, None], np.arange(96)[None, :], 0]
    assert np.all(np.diff(red, axis=1) > 0)
    key = renderer.program_key(scene, scene.objects[0])
    assert key.has_uv and not key.has_tangent and key.attributes() == ("in_position", "in_normal", "in_uv")


def test_uv_material_on_the_sphere_matches_twin(renderer):
    report = assert_render_matches(oblique_scene(RAMP), renderer)
    assert report.covered_pixels > 4000 and report.nonfinite_count == 0


# --------------------------------------------------------------------------- 5. per-vertex shading
def test_per_vertex_aniso(module_make_renderer, renderer):
    """Gouraud shading reads the tangent in the vertex stage: on the plane under a directional light
    the radiance is constant, so the per-vertex render equals the per-pixel one (1e-6 relative) and
    the closed form; rotating the tangent to +y divides it by 3; the sphere renders finite and lit."""
    gouraud = module_make_renderer(96, 96, renderer.backend, shading="vertex")
    scene = top_view_scene(plane_with(tangent=(1.0, 0.0, 0.0, 1.0), segments=4), ANISO)
    key = gouraud.program_key(scene, scene.objects[0])
    assert key.shade_per_vertex and key.has_tangent and "in_tangent" in key.attributes()
    vertex = gouraud.render(scene)
    pixel = renderer.render(scene)
    np.testing.assert_array_equal(vertex.mask, pixel.mask)
    np.testing.assert_allclose(vertex.radiance[vertex.mask], pixel.radiance[pixel.mask], rtol=1e-6)
    base = np.array(ANISO.k) * LIGHT_E * np.cos(LIGHT_THETA)
    np.testing.assert_allclose(vertex.radiance[vertex.mask], np.broadcast_to(3.0 * base, (vertex.mask.sum(), 3)),
                               rtol=1e-5)
    rotated = gouraud.render(top_view_scene(plane_with(tangent=(0.0, 1.0, 0.0, 1.0), segments=4), ANISO))
    np.testing.assert_allclose(vertex.radiance[vertex.mask] / rotated.radiance[rotated.mask], 3.0, rtol=1e-5)
    sphere = gouraud.render(oblique_scene(ANISO))
    assert np.all(np.isfinite(sphere.radiance))
    assert sphere.mask.sum() > 4000 and np.percentile(sphere.radiance[sphere.mask], 50) > 1e-3


def test_tangent_and_uv_terms_in_one_scene(renderer):
    """One object needs the tangent, another the uv: the G-buffer carries both planes (tangent,
    then uv) for every object, and the render matches the twin."""
    scene = oblique_scene(ANISO, plane=False)
    scene.add(primitives.plane(3.0, 2), RAMP, name="plane")
    assert binding(scene).gbuffer_needs() == frozenset({"tangent", "uv"})
    report = assert_render_matches(scene, renderer)
    assert report.covered_pixels > 4000
    gbuffer = renderer.gbuffer(scene)
    on_plane = gbuffer.object_index == 1
    np.testing.assert_allclose(gbuffer.uv[on_plane, 0], gbuffer.position[on_plane, 0] / 3.0 + 0.5, rtol=0, atol=1e-6)
    np.testing.assert_allclose(gbuffer.tangent[on_plane], np.tile([1.0, 0.0, 0.0, 1.0], (on_plane.sum(), 1)),
                               rtol=0, atol=1e-6)
