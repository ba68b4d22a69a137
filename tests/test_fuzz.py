"""A property-based fuzz of the public API (hypothesis, bounded): random scenes, built-in and
user-defined materials, lights, cameras and render options, valid and invalid values.

Every construction either succeeds or raises the documented TypeError / ValueError; every scene that
was accepted renders without raising and without a NaN, per pixel and per vertex.  The whole run
happens in a subprocess, so a crash of the process (a driver abort) fails the test instead of
killing the suite.
"""
import os
import subprocess
import sys
import textwrap

FUZZ = textwrap.dedent(r'''
    import sys, math
    import numpy as np
    from hypothesis import HealthCheck, given, settings, strategies as st
    import glphong
    from glphong import primitives
    from glphong.materials import MaterialModel, Param

    class Sheen(MaterialModel):
        name = "fuzz_sheen"
        params = (Param("k", "rgb", low=0.0), Param("p", "scalar", low=0.0, high=64.0, default=5.0))
        needs = ("view",)
        ambient = "k"
        vanishes_with = ("k",)
        glsl = """
        vec3 fuzz_sheen_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
        {
            float c = 1.0 - clamp(dot(f.n, wo), 0.0, 1.0);
            return u_fuzz_sheen_k * (n_dot_l * pow(max(c, 1e-30), u_fuzz_sheen_p));
        }"""
        def response(self, f, wi, wo, n_dot_l, p):
            c = 1.0 - np.clip(np.sum(f.n * wo, axis=-1), 0.0, 1.0)
            return p.k * (n_dot_l * np.maximum(c, 1e-30) ** p.p)[..., None]

    EXTREME = [0.0, 1e-40, 1e-30, 1.0, 0.3, 1e30, 3e38]
    BAD = [-1.0, float("nan"), float("inf"), "1", True, None, (1.0, 2.0), [[1.0]]]
    def sometimes_bad(valid):
        """``valid``, or one in 25 times an invalid value (so that most scenes are accepted)."""
        return st.integers(0, 24).flatmap(lambda i: st.sampled_from(BAD) if i == 0 else valid)

    coefficient = sometimes_bad(st.one_of(st.sampled_from(EXTREME), st.floats(0, 10),
                                          st.tuples(*[st.sampled_from(EXTREME)] * 3)))
    exponent = sometimes_bad(st.one_of(st.sampled_from([0.0, 0.5, 1.0, 1e3, 1e7, 3e38]), st.floats(0, 1e4)))
    coordinate = st.one_of(st.floats(-1e3, 1e3), st.sampled_from([0.0, 1e-30, 1e30, -1e30, 3e38]))
    vector = sometimes_bad(st.tuples(coordinate, coordinate, coordinate))
    # the eye: a direction (not along the camera's up, +y) at a distance from 1e-3 to 1e30 m
    eye_vector = sometimes_bad(st.tuples(st.floats(-1, 1), st.floats(-0.9, 0.9), st.floats(0.2, 1),
                                         st.sampled_from([1e-3, 1.0, 3.0, 1e3, 1e30])).map(
        lambda t: tuple(c * t[3] for c in t[:3])))

    @st.composite
    def material(draw):
        kind = draw(st.sampled_from(["lambert", "phong", "blinn", "sheen"]))
        kd, ks, q, ka = draw(coefficient), draw(coefficient), draw(exponent), draw(st.sampled_from([0.0, 0.01, 1e-40]))
        two_sided = draw(sometimes_bad(st.booleans()))
        return lambda: {"lambert": lambda: glphong.Lambert(kd, ka=ka, two_sided=two_sided),
                        "phong": lambda: glphong.Phong(kd, ks, q, ka=ka, two_sided=two_sided),
                        "blinn": lambda: glphong.BlinnPhong(kd, ks, q, ka=ka, two_sided=two_sided),
                        "sheen": lambda: Sheen(kd, p=min(abs(q), 64.0) if isinstance(q, float) and math.isfinite(q) else q,
                                               ka=ka, two_sided=two_sided)}[kind]()

    @st.composite
    def light(draw):
        kind = draw(st.sampled_from(["point", "unattenuated", "directional"]))
        where, value = draw(vector), draw(coefficient)
        return lambda: {"point": glphong.PointLight, "unattenuated": glphong.UnattenuatedPointLight,
                        "directional": glphong.DirectionalLight}[kind](where, value)

    RENDERERS = {}

    def renderer(shading, samples, supersample):
        key = (shading, samples, supersample)
        if key not in RENDERERS:
            RENDERERS[key] = glphong.Renderer(24, 20, shading=shading, samples=samples, supersample=supersample)
        return RENDERERS[key]

    counts = {"rendered": 0, "refused": 0}

    @settings(max_examples=int(sys.argv[1]), deadline=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(materials=st.lists(material(), min_size=1, max_size=3), lights=st.lists(light(), max_size=3),
           eye=eye_vector, ambient=st.one_of(st.none(), coefficient),
           options=st.sampled_from([("pixel", 1, 1), ("vertex", 1, 1), ("pixel", 4, 1), ("pixel", 1, 2)]))
    def fuzz(materials, lights, eye, ambient, options):
        try:
            camera = glphong.PerspectiveCamera.look_at(eye, (0.0, 0.0, 0.0))
            scene = glphong.Scene(camera, lights=[make() for make in lights],
                                  ambient=None if ambient is None else glphong.AmbientLight(ambient))
            for i, make in enumerate(materials):
                pose = np.eye(4)
                pose[0, 3] = i - 1.0
                scene.add(primitives.sphere(1, radius=0.4), make(), pose=pose)
        except (TypeError, ValueError):
            counts["refused"] += 1
            return
        frame = renderer(*options).render(scene)
        assert not np.isnan(frame.radiance).any(), (options, [repr(o.material) for o in scene.objects], scene.lights)
        counts["rendered"] += 1

    fuzz()
    for r in RENDERERS.values():
        r.release()
    print(counts["rendered"], counts["refused"])
''')


def test_fuzzed_public_api_raises_only_documented_errors_and_never_nan(tmp_path):
    script = tmp_path / "fuzz.py"
    script.write_text(FUZZ)
    env = dict(os.environ)
    out = subprocess.run([sys.executable, str(script), "150"], capture_output=True, text=True, timeout=600,
                         cwd=tmp_path, env=env)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-5000:]
    rendered, refused = map(int, out.stdout.split()[-2:])
    assert rendered >= 50 and refused >= 10, (rendered, refused)  # both kinds really exercised
