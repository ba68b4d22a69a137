"""Shadows (docs/design.md section 12): shadow maps for point, spot and directional lights against the ray-cast twin.

- On the test scenes (a sphere over a plane, a box on a box, a self-shadowing torus, a grazing light) every pixel
  agrees with the float64 ray-cast visibility except inside the band (a shadow boundary, seen from the light, within
  the filter's reach plus one texel, or an occluder nearer the receiver than the derived bias), on both backends, with
  and without percentage-closer filtering; the band is reported apart and stays a small part of the image.
- The twin's visibility matches the closed form of a sphere's shadow on a plane (a cone from a point light).
- The band is not vacuous: a shadow map looked up one texel off, or a bias ten times too small (acne), fails.
- What a scene does not need is left out: no shadowing light (or nothing that casts), no shadow code.
"""
import importlib.util
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.checks import shadows
from glphong.checks.shadows import shadow_visibility
from glphong.shaders.binding import binding
from glphong.shaders import assembly

SPHERE_CENTRE, SPHERE_RADIUS = np.array([0.0, 0.0, 0.7]), 0.5


def _translate(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def _light(kind, position=(0.3, 0.2, 2.0), target=(0.0, 0.0, 0.0), power=60.0):
    """A shadowing light of ``kind`` at ``position`` shining toward ``target`` (a directional one along that line)."""
    position, target = np.asarray(position, dtype=float), np.asarray(target, dtype=float)
    axis = target - position
    return {"point": lambda: glphong.PointLight(position, power, shadows=True),
            "spot": lambda: glphong.SpotLight(position, axis, power / 8.0, 0.3, 0.9, shadows=True),
            "directional": lambda: glphong.DirectionalLight(axis, power / 30.0, shadows=True)}[kind]()


def sphere_over_plane(kind, ambient=0.02):
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -3.0, 3.0), (0.0, 0.0, 0.0)), [_light(kind)],
                          ambient=glphong.AmbientLight(ambient) if ambient else None)
    scene.add(primitives.sphere(3, radius=SPHERE_RADIUS), glphong.Phong(0.3, 0.4, 30.0), pose=_translate(*SPHERE_CENTRE))
    scene.add(primitives.plane(4.0), glphong.Lambert(0.6))
    return scene


def box_on_box(kind):
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((2.0, -2.6, 2.2), (0.0, 0.0, 0.1), up=(0.0, 0.0, 1.0)),
                          [_light(kind, (1.6, -1.2, 1.4), (-0.2, 0.1, 0.0), power=40.0)])
    scene.add(trimesh.creation.box((2.0, 2.0, 0.4)), glphong.Lambert(0.5), pose=_translate(0.0, 0.0, -0.2), smooth=False)
    scene.add(trimesh.creation.box((0.5, 0.5, 0.8)), glphong.Lambert(0.7), pose=_translate(-0.2, 0.1, 0.4), smooth=False)
    return scene


def torus(kind):
    # a low light: the near side of the ring shadows the far side, and the tube its own inside
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -1.8, 1.6), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)),
                          [_light(kind, (-1.9, -0.5, 0.8), (0.3, 0.1, 0.0), power=40.0)])
    scene.add(trimesh.creation.torus(0.8, 0.3, 64, 32), glphong.Phong(0.4, 0.3, 20.0))
    return scene


def grazing(kind):
    """A light 85 degrees from the floor's normal: long shadows and a receiver nearly edge-on."""
    tilt = np.radians(85.0)
    light = {"directional": glphong.DirectionalLight((np.sin(tilt), 0.0, -np.cos(tilt)), 3.0, shadows=True),
             "point": glphong.PointLight((-3.0 * np.sin(tilt), 0.0, 3.0 * np.cos(tilt)), 80.0, shadows=True),
             "spot": glphong.SpotLight((-3.0 * np.sin(tilt), 0.0, 3.0 * np.cos(tilt)), (np.sin(tilt), 0.0, -np.cos(tilt)),
                                       10.0, 0.2, 0.6, shadows=True)}[kind]
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -2.5, 2.0), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)),
                          [light])
    scene.add(primitives.plane(4.0, segments=4), glphong.Lambert(0.6))
    scene.add(trimesh.creation.box((0.3, 0.3, 0.6)), glphong.Lambert(0.6), pose=_translate(-0.5, 0.0, 0.3), smooth=False)
    return scene


SCENES = {"sphere over plane": sphere_over_plane, "box on box": box_on_box, "torus": torus, "grazing": grazing}


def _without_shadows(scene):
    """The same scene with every light's shadows off."""
    lights = [type(light)(**{k: v for k, v in light.parameter_values().items() if k != "shadows"}) for light in scene.lights]
    out = glphong.Scene(scene.camera, lights, ambient=scene.ambient)
    for obj in scene.objects:
        out.add(obj.mesh, obj.material, pose=obj.pose, name=obj.name)
    return out


CASES = [(name, kind) for name in SCENES for kind in ("point", "spot", "directional")
         if (name, kind) != ("grazing", "spot")]  # a spot light along the floor: the point light's case again


@pytest.mark.parametrize("filter_radius", [0, 1])
@pytest.mark.parametrize("name, kind", CASES)
def test_shadows_verify_outside_the_band(name, kind, filter_radius, glphong_backend, glphong_make_renderer):
    scene = SCENES[name](kind)
    renderer = glphong_make_renderer(120, 90, glphong_backend, shadow_map_size=1024, shadow_filter_radius=filter_radius)
    report = glphong.verify(scene, renderer)
    assert report.passed, str(report)
    # the band is the shadows' edges and contacts, not the picture: at most a fifth of the covered pixels
    assert 0 < report.shadow_band_count < report.covered_pixels / 5, report.summary()
    unshadowed = glphong.reference.shade(_without_shadows(scene), renderer.gbuffer(scene))
    shadowed = (report.reference < 0.5 * unshadowed).any(axis=-1) & report.mask & ~report.shadow_band
    assert shadowed.sum() >= 10, "the scene must have shadow outside the band"


def test_sphere_shadow_is_the_closed_form_cone(glphong_make_renderer):
    """The twin's ray cast against the closed form: a point x of the plane is in the shadow of a sphere (centre C,
    radius r) from a point light L exactly when the segment from x to L passes within r of C.  The mesh is an
    inscribed polyhedron, between the sphere and the sphere of radius r cos(its largest edge's half-angle)."""
    scene = sphere_over_plane("point", ambient=0.0)
    renderer = glphong_make_renderer(160, 120, "egl", shadow_map_size=512)
    gbuffer = renderer.gbuffer(scene)
    floor = gbuffer.object_index == 1
    x = gbuffer.position[floor].astype(np.float64)
    light = np.asarray(scene.lights[0].position)
    t = np.clip(np.sum((SPHERE_CENTRE - x) * (light - x), axis=1) / np.sum((light - x) ** 2, axis=1), 0.0, 1.0)
    distance = np.linalg.norm(x + t[:, None] * (light - x) - SPHERE_CENTRE, axis=1)
    mesh = primitives.sphere(3, radius=SPHERE_RADIUS)
    edges = mesh.positions[mesh.indices.reshape(-1, 3)]
    half_angle = np.max(np.arcsin(np.linalg.norm(edges[:, 0] - edges[:, 1], axis=1) / (2 * SPHERE_RADIUS)))
    inner = SPHERE_RADIUS * np.cos(half_angle) ** 2  # the polyhedron contains the sphere through its faces' centres
    key = renderer.program_key(scene, scene.objects[1])
    (setup,) = binding(scene).shadow_setups(key.lights, key.shadow_size)
    exact, low, high = shadow_visibility(scene, setup, x, np.tile([0.0, 0.0, 1.0], (len(x), 1)), 0)
    assert np.all(exact[distance > SPHERE_RADIUS * (1 + 1e-9)] == 1.0)
    assert np.all(exact[distance < inner * (1 - 1e-9)] == 0.0)
    assert (distance < inner).sum() > 500 and (distance > SPHERE_RADIUS).sum() > 5000
    # the GPU agrees wherever the band does not hold the pixel (no ambient light: a shadowed pixel is black)
    gpu_visible = renderer.render(scene).radiance[floor][:, 0] > 0.0
    certain = low == high
    assert np.all(gpu_visible[certain] == (exact[certain] == 1.0))
    assert certain.sum() > 0.9 * len(x)


PLANTED = {
    "the map looked up one texel off": ("ivec2 texel = clamp(ivec2(floor(st)),",
                                        "ivec2 texel = clamp(ivec2(floor(st)) + ivec2(1, 0),"),
    "a bias ten times too small": ("    float bias = shadow_bias(", "    float bias = 0.1 * shadow_bias("),
}


PLANTED_CASES = [(planted, name, kind) for planted in PLANTED for name, kind in (
    ("sphere over plane", "point"), ("box on box", "spot"), ("torus", "directional"), ("grazing", "point"),
    ("sphere over plane", "directional"))
    # measured: a lookup one texel off stays inside the band on these two at 160x120 and 128 texels (the shift
    # runs along their shadows' edges, or the band of a grazing light is that wide); the bias is caught on all five
    if (planted, name, kind) not in (("the map looked up one texel off", "box on box", "spot"),
                                     ("the map looked up one texel off", "grazing", "point"))]


@pytest.mark.parametrize("planted, name, kind", PLANTED_CASES)
def test_planted_errors_fail(planted, name, kind, monkeypatch, glphong_make_renderer):
    """The same scenes pass unplanted at this map size (test_shadows_verify_outside_the_band at 1024 and here)."""
    old, new = PLANTED[planted]
    original = assembly.chunk_source
    source = original("shadows")
    assert old in source
    monkeypatch.setattr(assembly, "chunk_source", lambda label: source.replace(old, new) if label == "shadows"
                        else original(label))
    # a map whose texels are about a pixel's footprint, so that a texel's error shows in whole pixels
    renderer = glphong_make_renderer(160, 120, "egl", shadow_map_size=128)
    report = glphong.verify(SCENES[name](kind), renderer)
    assert not report.passed and report.outside_count > 0, report.summary()


@pytest.mark.parametrize("name, kind", [("sphere over plane", "point"), ("box on box", "spot"), ("torus", "directional"),
                                        ("grazing", "point"), ("sphere over plane", "directional")])
def test_the_planted_scenes_pass_unplanted(name, kind, glphong_make_renderer):
    assert glphong.verify(SCENES[name](kind), glphong_make_renderer(160, 120, "egl", shadow_map_size=128)).passed


def test_what_a_scene_does_not_need_is_left_out(glphong_make_renderer):
    plain = sphere_over_plane("point")
    key = binding(plain).program_key(plain.objects[1])
    assert key.shadow_slots and "shadows" in key.shading_chunks()
    dark = glphong.Scene(plain.camera, [glphong.PointLight((0.3, 0.2, 2.0), 60.0)])
    dark.add(primitives.plane(4.0), glphong.Lambert(0.6))
    key = binding(dark).program_key(dark.objects[0])
    assert not key.shadow_slots and "shadows" not in key.shading_chunks()
    assert any("shadow maps" in line for line in key.left_out())
    nothing_casts = glphong.Scene(plain.camera, [_light("point")])
    nothing_casts.add(primitives.plane(4.0), glphong.Lambert(0.6), casts_shadow=False)
    assert not binding(nothing_casts).program_key(nothing_casts.objects[0]).shadow_slots
    # a sphere that casts no shadow leaves the floor unshadowed: the same image as without shadows
    renderer = glphong_make_renderer(64, 48, "egl")
    ghost = glphong.Scene(plain.camera, [_light("point")])
    ghost.add(primitives.sphere(3, radius=SPHERE_RADIUS), glphong.Lambert(0.3), pose=_translate(*SPHERE_CENTRE),
              casts_shadow=False)
    ghost.add(primitives.plane(4.0), glphong.Lambert(0.6))
    unshadowed = glphong.Scene(plain.camera, [glphong.PointLight((0.3, 0.2, 2.0), 60.0)])
    unshadowed.add(primitives.sphere(3, radius=SPHERE_RADIUS), glphong.Lambert(0.3), pose=_translate(*SPHERE_CENTRE))
    unshadowed.add(primitives.plane(4.0), glphong.Lambert(0.6))
    np.testing.assert_array_equal(renderer.render(ghost).radiance, renderer.render(unshadowed).radiance)
    assert glphong.verify(ghost, renderer).passed


def test_refusals(glphong_make_renderer):
    scene = sphere_over_plane("point")
    with pytest.raises(ValueError, match="the uber-shader holds no shadow maps"):
        glphong_make_renderer(32, 32, "egl", specialise=False).render(scene)
    with pytest.raises(ValueError, match="shading='pixel'"):
        glphong_make_renderer(32, 32, "egl", shading="vertex").render(scene)
    with pytest.raises(ValueError, match="casts no shadows"):
        glphong.UnattenuatedPointLight((0, 0, 1), 1.0, shadows=True)
    with pytest.raises(TypeError, match="shadows must be a bool"):
        glphong.PointLight((0, 0, 1), 1.0, shadows="yes")
    with pytest.raises(ValueError, match="shadow settings"):
        renderer = glphong_make_renderer(32, 32, "egl")
        glphong.reference.shade(scene, renderer.gbuffer(scene))


def _blocked_run(blocked, body):
    """Run ``body`` in a fresh interpreter where the top-level packages ``blocked`` cannot be imported."""
    code = ("import sys\n"
            "class Block:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            f"        if name.split('.')[0] in {tuple(blocked)!r}:\n"
            "            raise ImportError('blocked ' + name, name=name)\n"
            "sys.meta_path.insert(0, Block())\n" + textwrap.dedent(body))
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)


TWIN_RUN = """
import numpy as np, glphong
from glphong import primitives
scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -3.0, 3.0), (0.0, 0.0, 0.0)),
                      [glphong.PointLight((0.3, 0.2, 2.0), 60.0, shadows=True)])
pose = np.eye(4); pose[2, 3] = 0.7
scene.add(primitives.sphere(3, radius=0.5), glphong.Lambert(0.3), pose=pose)
scene.add(primitives.plane(4.0), glphong.Lambert(0.6))
with glphong.Renderer(64, 48, backend="egl", shadow_map_size=256) as renderer:
    report = glphong.verify(scene, renderer)
print(report.passed, report.shadow_band_count, int(report.reference.sum() * 1e6))
"""


def test_without_embree_the_float64_intersector_gives_the_same_answer():
    if importlib.util.find_spec("rtree") is None:
        pytest.skip("rtree is not installed: trimesh's float64 intersector needs it (pip install rtree)")
    with_embree = _blocked_run((), TWIN_RUN)
    float64 = _blocked_run(("embreex",), TWIN_RUN)
    assert with_embree.returncode == 0 and float64.returncode == 0, with_embree.stderr[-1500:] + float64.stderr[-1500:]
    assert with_embree.stdout.split()[0] == "True" and with_embree.stdout == float64.stdout


def test_without_an_intersector_the_error_names_the_extra():
    out = _blocked_run(("embreex", "rtree"), TWIN_RUN)
    assert out.returncode != 0 and "pip install 'glphong[shadows]'" in out.stderr, out.stderr[-1500:]


@pytest.mark.parametrize("name, kind", [("sphere over plane", k) for k in ("point", "spot", "directional")]
                         + [("grazing", "point"), ("grazing", "directional")])
def test_rays_not_cast_are_clear_and_change_nothing(name, kind, monkeypatch, glphong_make_renderer):
    """Rays to a flat receiver that provably meet nothing before their threshold are not cast
    (`_clear_without_a_cast`): cast anyway, each is clear (its first hit no nearer than the threshold), and verify's
    arrays are those of casting every ray, bit for bit."""
    proofs = []
    original = shadows._clear_without_a_cast

    def record(cull, origins, directions, threshold):
        proven = original(cull, origins, directions, threshold)
        shape = threshold.shape + (3,)
        proofs.append((np.broadcast_to(origins, shape)[proven], np.broadcast_to(directions, shape)[proven],
                       threshold[proven]))
        return proven

    monkeypatch.setattr(shadows, "_clear_without_a_cast", record)
    renderer = glphong_make_renderer(64, 48, "egl")
    culled = glphong.verify(SCENES[name](kind), renderer)
    assert sum(len(t) for _, _, t in proofs) > 1000  # rays not cast
    scene = SCENES[name](kind)
    intersector = shadows._caster_mesh(scene)
    for origins, directions, threshold in proofs:
        assert np.all(shadows._first_hits(intersector, origins, np.ascontiguousarray(directions)) >= threshold)
    monkeypatch.setattr(shadows, "_clear_without_a_cast", lambda cull, o, d, threshold: np.zeros(threshold.shape, bool))
    every = glphong.verify(scene, renderer)
    for field in ("reference", "low", "high", "outside", "shadow_band"):
        assert np.array_equal(getattr(culled, field), getattr(every, field)), field


def _embree():
    """trimesh's Embree intersector (the test is skipped without embreex, the ``[shadows]`` extra)."""
    return pytest.importorskip("trimesh.ray.ray_pyembree").RayMeshIntersector


def _plain_hits(intersector, origins, directions):
    """Each ray's first hit as trimesh's own first-hit query gives it (``intersects_id``): the distance along the
    direction to the hit location, inf where none (or not ahead)."""
    _, ray, location = intersector.intersects_id(origins, directions, multiple_hits=False, return_locations=True)
    t = np.einsum("ij,ij->i", location - origins[ray], directions[ray])
    out = np.full(len(origins), np.inf)
    np.minimum.at(out, ray[t > 0.0], t[t > 0.0])
    return out


def _plain_visibility(scene, setup, position, normal, filter_radius):
    """`shadow_visibility` as its rules read (the module's docstring), every one of the nine rays of every point cast
    through trimesh's ``intersects_id`` on a fresh intersector: ``(exact, low, high)``."""
    intersector = _embree()(shadows._caster_mesh(scene).mesh)
    n_points = len(position)
    reach = (filter_radius + 0.5) * np.sqrt(2.0) * setup.texel
    band = (filter_radius * np.sqrt(2.0) + 1.0) * setup.texel
    if setup.map == "cube":
        v = position - setup.origin
        d = np.linalg.norm(v, axis=1)
        u = v / d[:, None]
        m = np.max(np.abs(u), axis=1)
        plane = shadows.shadow_plane_angle(d, np.abs(shadows.dot(normal, u)), reach * m)
        ring, _ = shadows._ring(u, band * m)
        origins = np.broadcast_to(setup.origin, (9, n_points, 3))
        directions = np.concatenate([u[None], ring])
    else:
        d = (position - setup.origin) @ setup.axis
        plane = shadows.shadow_plane_length(np.abs(normal @ setup.axis), reach)
        start = position - d[:, None] * setup.axis
        _, across = shadows._ring(np.broadcast_to(setup.axis, (n_points, 3)), np.full(n_points, band))
        origins = np.concatenate([start[None], start[None] + band * across])
        directions = np.broadcast_to(setup.axis, (9, n_points, 3))
    scale = np.abs(d) + (np.max(np.abs(position), axis=1) + np.max(np.abs(setup.origin)))
    q = shadows.SHADOW_QUANTUM * scale
    bias = shadows.shadow_bias(plane, scale)
    planes = shadows._plane_distance(normal[None], position[None], origins, directions)
    hits = _plain_hits(intersector, np.ascontiguousarray(origins).reshape(-1, 3),
                       np.ascontiguousarray(directions).reshape(-1, 3)).reshape(9, n_points)
    with np.errstate(invalid="ignore"):
        deficit = np.nan_to_num(planes - hits, nan=-np.inf)
    clear, blocked = deficit <= plane + q, deficit > bias + plane
    clear[0], blocked[0] = hits[0] >= d - q, hits[0] < d - bias
    exact = clear[0].astype(np.float64)
    certain = np.all(clear, axis=0) | np.all(blocked, axis=0)
    return exact, np.where(certain, exact, 0.0), np.where(certain, exact, 1.0)


@pytest.mark.parametrize("filter_radius", [0, 1])
@pytest.mark.parametrize("name, kind", [("sphere over plane", "point"), ("sphere over plane", "spot"),
                                        ("sphere over plane", "directional"), ("grazing", "point"),
                                        ("grazing", "directional"), ("torus", "point"), ("box on box", "spot")])
def test_visibility_is_every_ray_cast_plainly(name, kind, filter_radius, monkeypatch, glphong_make_renderer):
    """`shadow_visibility` leaves rays out (proven clear, or the ring of a point whose centre ray is neither clear
    nor blocked), takes the points in chunks and casts through Embree without trimesh's wrapper: its visibility and
    band are, bit for bit, those of casting all nine rays of every point through trimesh's own first-hit query."""
    monkeypatch.setattr(shadows, "CHUNK_POINTS", 701)  # several chunks (rows not in fours), a last one shorter
    monkeypatch.setattr(shadows, "CHUNK", 997)
    cast = []
    original = shadows._first_hits
    monkeypatch.setattr(shadows, "_first_hits", lambda i, o, d: cast.append(len(d)) or original(i, o, d))
    scene = SCENES[name](kind)
    renderer = glphong_make_renderer(96, 72, "egl", shadow_map_size=256, shadow_filter_radius=filter_radius)
    gbuffer = renderer.gbuffer(scene)
    points = 0
    for index, obj in enumerate(scene.objects):
        selection = gbuffer.object_index == index
        key = renderer.program_key(scene, obj)
        (setup,) = binding(scene).shadow_setups(key.lights, key.shadow_size)
        position = gbuffer.position[selection].astype(np.float64)
        face = gbuffer.face[selection].astype(np.float64)
        face /= np.linalg.norm(face, axis=1)[:, None]
        got = shadow_visibility(scene, setup, position, face, filter_radius, obj)
        for a, b in zip(got, _plain_visibility(scene, setup, position, face, filter_radius)):
            assert a.dtype == b.dtype and np.array_equal(a, b)
        points += len(position)
    assert 0 < sum(cast) <= 9 * points
    if name == "sphere over plane":  # the floor's rays beside the sphere; the ring where the centre decides nothing
        assert sum(cast) < 0.9 * 9 * points


def test_first_hits_are_trimeshs(monkeypatch):
    """`_first_hits` against trimesh's own first-hit query, bit for bit: rays from one point and from a point each,
    misses, rays along the floor (trimesh's cut: a line within 1e-5 of a plane is no hit), in chunks."""
    monkeypatch.setattr(shadows, "CHUNK", 999)
    scene = sphere_over_plane("point")
    intersector = shadows._caster_mesh(scene)
    plain = _embree()(intersector.mesh)
    rng = np.random.default_rng(7)
    light = np.array([0.3, 0.2, 2.0])
    directions = rng.normal(size=(5000, 3)) * [0.6, 0.6, 1.0] - [0.0, 0.0, 1.0]
    origins = np.concatenate([np.broadcast_to(light, (2500, 3)), rng.uniform(-2.5, 2.5, (2500, 3))])
    # grazing the floor (z = 0): from just above it, 1e-6 to 1e-4 off parallel
    slope = np.geomspace(1e-6, 1e-4, 400)
    graze_o = np.column_stack([np.full(400, -1.9), rng.uniform(-1.5, 1.5, 400), 2.0 * slope])
    graze_d = np.column_stack([np.ones(400), np.zeros(400), -slope])
    origins, directions = np.concatenate([origins, graze_o]), np.concatenate([directions, graze_d])
    expected = _plain_hits(plain, origins, directions)
    assert np.isinf(expected).sum() > 1000 and np.isfinite(expected).sum() > 1000
    assert np.isinf(expected[-400:]).sum() > 50 and np.isfinite(expected[-400:]).sum() > 50
    assert np.array_equal(shadows._first_hits(intersector, origins, directions), expected)
    one = _plain_hits(plain, np.broadcast_to(light, (2500, 3)).copy(), directions[:2500])
    assert np.array_equal(shadows._first_hits(intersector, light, directions[:2500]), one)
