"""The extreme-case stability suite and report (``glphong stability``).

Each `Case` is data: one shading point (surface point at the origin, a raw normal, an eye
position), a material and lights.  Its expected value comes from `oracle`, an independent
60-digit mpmath evaluation of the textbook model E6 from the material's, lights' and camera's own
parameters (rounded to float32, the documented input precision, so float64 rounding cannot hide in
the expectation; never from the uniforms).  The GPU evaluates the real GLSL ``shade_point()`` at
that point through a 'points' program; the float64 twin evaluates its mirror.  Inside the valid
range the GPU passes when it lies within the tolerance band's widths of the oracle (the band of
`glphong.checks.tolerances`, computed around the twin, moved onto the oracle's value) and is neither NaN
nor Inf; outside it, the documented float32 behaviour (flush to 0, saturation) is what the twin
mirrors, and the GPU is judged in the band around the twin.

Valid ranges (`VALID_RANGES`): inside them the GPU result equals the textbook value within
the band.  Outside them it is still never NaN from finite input: results below FLT_MIN flush
to 0, irradiance beyond FLT_MAX saturates at FLT_MAX, and sums beyond FLT_MAX become +Inf.
"""
import hashlib
import json
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from glphong.checks.tolerances import FLT_MAX, FLT_MIN, point_band
from glphong.checks.verify import relative_error
from glphong.definitions.cases import Case, _mirror_eye, _unit, _with_ka, cases_for, generic_cases, lobe_cases  # noqa: F401
from glphong.checks import reference as ref
from glphong.checks.points import shade_points
from glphong.gpu.contexts import create_context
from glphong.gpu.programs import ProgramCache
from glphong.materials import ParamValues, ShadingFrame, registered_models
from glphong.materials.blinn import BlinnPhong
from glphong.materials.phong import Phong
from glphong.scene.camera import PerspectiveCamera
from glphong.scene.geometry import MeshData
from glphong.lights import AmbientLight, LightModel, light_named, registered_lights
from glphong.shaders.numerics import numerics_pieces
from glphong.scene.scene import Scene
from glphong.shaders.keys import ProgramKey, TermKey
from glphong.shaders.options import NUMERICS_PIECES
from glphong.shaders.binding import binding

__all__ = ["Case", "CASES", "case_scene", "case_inputs", "generic_cases", "lobe_cases", "cases_for", "VALID_RANGES", "oracle", "StabilityRow", "StabilityReport", "run_stability", "case_numerics",
           "CaseExpectations", "case_expectation"]

#: documented ranges inside which the GPU equals the textbook model within the tolerance band
VALID_RANGES = {
    "q": "0 <= q <= 1e7 tested at and around the peak (any finite q <= FLT_MAX is accepted and never NaN)",
    "distance": "every coordinate difference (light - point, eye - point) in [FLT_MIN, FLT_MAX] per largest component, "
                "e.g. light distances 1e-30 m to 1e30 m",
    "power": "Phi / (4 pi) and the irradiance E = Phi / (4 pi d^2) in [FLT_MIN, FLT_MAX] (about 1.2e-38 to 3.4e38); "
             "Phi itself is accepted from 0 to 4 pi FLT_MAX",
    "result": "each light's term and the sum in [FLT_MIN, FLT_MAX]; below: flushed to 0, above: FLT_MAX or +Inf",
    "normals": "any finite non-zero normal (1e-37 to 1e38 in length); zero or non-finite normals give the ambient terms",
}


def case_scene(case):
    """`Case` ``case`` as a one-object `Scene` (a dummy triangle carries the material)."""

    eye = np.asarray(case.eye)
    up = (0.0, 1.0, 0.0) if abs(eye[1]) < 0.9 * np.max(np.abs(eye)) else (1.0, 0.0, 0.0)
    camera = PerspectiveCamera.look_at(eye, (0.0, 0.0, 0.0), up=up, znear=1e-30 * np.max(np.abs(eye)) + 1e-37)
    lights = [light if isinstance(light, LightModel) else light_named(light[0])(light[1], light[2]) for light in case.lights]
    scene = Scene(camera, lights=lights, ambient=None if case.ambient is None else AmbientLight(case.ambient))
    scene.add(MeshData([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 1]] * 3, [[0, 1, 2]],
                       uvs=[case.uv] * 3, tangents=[case.tangent] * 3), case.material)
    return scene


def case_inputs(case, scene=None):
    """``(key, uniforms)`` of the case's 'points' program: exactly what the GPU is given (float32).

    ``scene`` is `case_scene` of the case when given (to build it once), else built here.
    """
    scene = case_scene(case) if scene is None else scene
    key = replace(binding(scene).program_key(scene.objects[0]), output="points", two_sided=False)
    uniforms = binding(scene).uniform_values(0, key, 1.0)
    for name in ("u_model", "u_view_projection", "u_normal_matrix"):
        uniforms.pop(name, None)
    return key, uniforms


def _build_cases():
    cases = []
    for model in registered_models():
        if model.__module__.startswith("glphong."):
            cases += cases_for(model)
    for kind in registered_lights():
        if kind.__module__.startswith("glphong."):
            cases += kind.stability_cases()
    light = _unit(30.0)
    grey = lambda x: (x, x, x)  # noqa: E731
    e_one = 4 * np.pi  # a point light at 1 m with E = 1 W/m^2
    phong = lambda kd=0.2, ks=0.5, q=50.0, ka=0.0: Phong(kd, ks, q, ka=ka)  # noqa: E731
    for label, normal in (("zero", (0.0, 0.0, 0.0)), ("tiny 1e-25", (0.0, 3e-26, 1e-25)), ("huge 1e25", (0.0, 3e24, 1e25)),
                          ("subnormal-free 1e-37", (0.0, 0.0, 1e-37)), ("NaN", (np.nan, 0.0, 1.0)), ("Inf", (0.0, np.inf, 1.0))):
        cases.append(Case(f"normal {label}", "normals", phong(ka=0.01), ambient=0.1, eye=_unit(10.0, 90.0),
                          normal=normal, lights=(("point", light, e_one),),
                          note="zero/non-finite normal: ambient terms only" if label in ("zero", "NaN", "Inf") else ""))
    for d in (1e-30, 1e-19, 1e-3, 1e3, 2e19, 1e30):
        representable = FLT_MIN <= 1.0 / (4 * np.pi * d * d) <= FLT_MAX
        cases.append(Case(f"distance {d:g}, Phi=1 W", "distance", phong(q=10.0), eye=_unit(20.0, 90.0),
                          lights=(("point", tuple(d * c for c in light), 1.0),), in_range=representable,
                          note="" if representable else "E outside float32: saturates at FLT_MAX or flushes to 0"))
        power = 4 * np.pi * d * d
        if 4 * np.pi * FLT_MIN <= power <= 4 * np.pi * FLT_MAX:
            cases.append(Case(f"distance {d:g}, E=1 W/m^2", "distance", phong(q=10.0), eye=_unit(20.0, 90.0),
                              lights=(("point", tuple(d * c for c in light), power),)))
    for phi in (1e-40, 1e-30, 1.0, 1e30, 3e38):
        i = phi / (4 * np.pi)
        cases.append(Case(f"power {phi:g} W at 1 m", "power", phong(q=10.0), eye=_unit(20.0, 90.0),
                          lights=(("point", light, phi),), in_range=i >= FLT_MIN,
                          note="" if i >= FLT_MIN else "intensity below FLT_MIN: flushed to 0"))
    cases.append(Case("all coefficients zero", "coefficients", phong(0.0, 0.0), eye=_unit(10.0, 90.0),
                      lights=(("point", light, e_one),)))
    cases.append(Case("kd=(1,0,0) under saturating light", "coefficients", phong((1.0, 0.0, 0.0), 0.0),
                      eye=_unit(10.0, 90.0), lights=(("point", tuple(1e-30 * c for c in light), 1.0),), in_range=False,
                      note="E saturates at FLT_MAX; zero channels stay 0, never 0 * Inf = NaN"))
    cases.append(Case("ks only, q=1e6 peak", "coefficients", phong(0.0, (0.0, 0.5, 1.0), 1e6),
                      eye=_mirror_eye(30.0, 0.0), lights=(("point", light, e_one),)))
    # light k at 10^(k-4) m delivering E_k = 10^(6k-20) W/m^2
    many = tuple(("point", tuple(10.0 ** (k - 4) * c for c in _unit(10.0 + 8 * k, 45.0 * k)),
                  4 * np.pi * 10.0 ** (2 * (k - 4)) * 10.0 ** (6 * k - 20)) for k in range(8))
    cases.append(Case("8 lights, E from 1e-20 to 1e22 W/m^2", "dynamic range", BlinnPhong(0.2, 0.5, 200.0),
                      eye=_unit(25.0, 200.0), lights=many))
    cases.append(Case("3 light kinds + ambient", "dynamic range", Phong(0.2, 0.5, 500.0, ka=grey(1e-3)), ambient=1e-2,
                      eye=_mirror_eye(30.0, 0.0), lights=(("point", light, e_one), ("unattenuated", (0.0, 5.0, 5.0), 1e-6),
                                                                 ("directional", (0.0, 0.0, -1.0), 1e6))))
    return tuple(cases)


#: the suite, in report order
CASES = _build_cases()


def oracle(scene, normal, point=(0.0, 0.0, 0.0), digits=60, tangent=(1.0, 0.0, 0.0, 1.0), uv=(0.5, 0.5)):
    """Independent high-precision value of the shading equation at one point, from the objects' own parameters.

    Evaluates ``L = k_a + sum_terms k L_a + sum_j [n.l_j > 0] sum_terms response_term(n, l_j, v) E_j``
    in mpmath with ``digits`` significant digits for the first object of ``scene``, reading the public
    attributes of its material (each term's parameters and ``ka``), of the lights (``position`` and
    ``power`` with ``E = Phi / (4 pi d^2)``, ``radiance``, ``direction`` and ``irradiance``), of the
    ambient light and of the camera (``position``): never the uniforms, the twin or the tolerance band,
    so a wrong value on its way from a constructor to a shader uniform shows.  Each term's response
    comes from its model's ``oracle`` method (mpmath); a model without one is evaluated by its twin
    in float64 on the oracle's geometry (rounded to float64), and judged as well as that allows.
    The conventions are those of docs/design.md section 1 (a zero or non-finite normal gives the emission
    terms only).

    The GPU computes in float32, so every input coordinate and coefficient is first rounded to
    float32, the documented input precision; everything after that is exact to ``digits``.

    Parameters
    ----------
    scene : glphong.Scene
        Its first object's material is evaluated.
    normal : (3,) array_like
        Raw normal at ``point`` (normalised here; may be zero or non-finite).
    point : (3,) array_like
        World-space shading point [m].
    digits : int
    tangent : (4,) array_like
        Raw tangent and handedness, for terms that need a tangent frame.
    uv : (2,) array_like
        Texture coordinates, for terms that need them.

    Returns
    -------
    (3,) float64 ndarray
        Radiance [W/(m^2 sr)].
    """
    import mpmath  # noqa: PLC0415 - the oracle's, kept out of import time

    mp = mpmath.mp
    mp.dps = digits
    f = lambda x: mpmath.mpf(float(np.float32(x)))  # noqa: E731
    vec = lambda a: [f(x) for x in np.asarray(a, dtype=np.float64).ravel()[:3]]  # noqa: E731
    dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731

    def unit(a):
        length = mpmath.sqrt(dot(a, a))
        return [x / length for x in a]

    def mp_values(term):
        return ParamValues({p.name: (vec(term.uniform_value(p.name)) if p.kind == "rgb" else f(term.uniform_value(p.name)))
                            for p in term.uniform_params()} | {t.name: getattr(term, t.name) for t in term.tables}
                           | term.structure())

    material = scene.objects[0].material
    terms = [t for t in material.components if not t.vanishes()]
    out = vec(material.ka)
    if scene.ambient is not None:
        for term in terms:
            if term.ambient is not None:
                k = vec(getattr(term, term.ambient))
                scale = mpmath.mpf(term.ambient_scale)
                occlusion = f(getattr(term, term.occluded_by)) if term.occluded_by else mpmath.mpf(1)
                out = [o + occlusion * scale * a * la for o, a, la in zip(out, k, vec(scene.ambient.radiance))]
    for term in material.components:
        if term.emission is not None:
            out = [o + e for o, e in zip(out, vec(getattr(term, term.emission)))]
    raw_n = np.asarray(normal, dtype=np.float32)
    if not np.all(np.isfinite(raw_n)) or not np.any(raw_n):
        return np.array([float(o) for o in out])
    x = vec(point)
    n = unit(vec(raw_n))
    eye, w = vec(scene.camera.eye), f(scene.camera.eye[3])  # homogeneous: v = normalize(e - w x)
    v = unit([e - w * p for e, p in zip(eye, x)])
    frame = _oracle_frame(n, vec(tangent[:3]), float(np.float32(tangent[3])), [f(c) for c in uv[:2]], unit, dot)
    for light in scene.lights:
        if light.extent == "extended":  # the exact integral: float64 quadrature converged to 1e-9 (section 13)
            value = _extended_exact(light, terms, [float(c) for c in x], [float(c) for c in n], [float(c) for c in v],
                                    tangent, uv)
            out = [o + mpmath.mpf(float(c)) for o, c in zip(out, value)]
            continue
        reached = light.oracle(x) if light.oracle is not None else _light_twin_at(light, x)
        if reached is None:
            continue
        l, e = reached
        ndl = dot(n, l)
        if ndl <= 0:
            continue
        for term in terms:
            view = v if "view" in term.needs else [mpmath.mpf(0)] * 3  # as the shader: v = 0 unless needed
            if term.oracle is not None:
                response = term.oracle(frame, l, view, ndl, mp_values(term))
            else:
                response = _twin_at(term, n, l, view, ndl, tangent, uv)
            out = [o + r * ee for o, r, ee in zip(out, response, e)]
    return np.array([float(o) for o in out])


def _oracle_frame(n, tangent, handedness, uv, unit, dot):
    """The shading frame in mpmath: ``t`` the tangent made orthogonal to n (Gram-Schmidt), ``b = sign(w) n x t``."""

    along = dot(n, tangent)
    projected = [a - along * b for a, b in zip(tangent, n)]
    if dot(projected, projected) == 0:
        return ShadingFrame(n, None, None, uv)
    t = unit(projected)
    sign = -1 if handedness < 0 else 1
    b = [sign * (n[1] * t[2] - n[2] * t[1]), sign * (n[2] * t[0] - n[0] * t[2]), sign * (n[0] * t[1] - n[1] * t[0])]
    return ShadingFrame(n, t, b, uv)


def _light_twin_at(light, x):
    """A light kind's twin at one mpmath point, in float64 (for kinds without an oracle): ``(wi, E)`` or None."""
    import mpmath  # noqa: PLC0415 - the oracle's, kept out of import time

    valid, wi, e = light.incident(np.array([[float(c) for c in x]]), light.values())
    if not valid[0]:
        return None
    return [mpmath.mpf(float(c)) for c in np.ravel(wi)[:3]], [mpmath.mpf(float(c)) for c in np.ravel(e)[:3]]


def _extended_exact(light, terms, x, n, v, tangent, uv):
    """An extended light's exact integral of the terms' float64 twin responses at one point, (3,): the kind's
    ``exact`` (an adaptive quadrature converged to 1e-9 relative, independent of its GLSL and twin)."""
    key = ProgramKey(terms=tuple(TermKey(t.name, "", tuple(t.needs)) for t in terms),
                     has_tangent=any("tangent" in t.needs for t in terms), has_uv=any("uv" in t.needs for t in terms))
    frame = ref.shading_frame(np.array([n]), np.array([tangent], dtype=np.float64), np.array([uv], dtype=np.float64), key)
    view = np.array([v])

    def integrand(index, w):
        out = np.zeros(w.shape)
        for term in terms:
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                out = out + term.response(frame.select(index), w, view[index] if "view" in term.needs else np.zeros_like(w),
                                          np.sum(frame.n[index] * w, axis=-1), term.values())
        return out

    value, error, converged = light.exact(np.array([x]), np.array([n]), light.values(), integrand)
    if not converged[0]:
        raise RuntimeError(f"{light!r}: its exact integral at {x} did not converge (error estimate {error[0]:.3g}); the "
                           "case has no trustworthy expected value")
    return np.asarray(value, dtype=np.float64)[0]


def _twin_at(term, n, l, v, ndl, tangent, uv):
    """A term's twin response at one mpmath geometry, in float64 (for models without an oracle)."""
    import mpmath  # noqa: PLC0415 - the oracle's, kept out of import time

    as64 = lambda a: np.array([[float(c) for c in a]])  # noqa: E731
    key = ProgramKey(terms=(TermKey(term.name, "", tuple(term.needs)),), has_tangent="tangent" in term.needs,
                     has_uv="uv" in term.needs)
    frame = ref.shading_frame(as64(n), np.array([tangent], dtype=np.float64), np.array([uv], dtype=np.float64), key)
    r = term.response(frame, as64(l), as64(v), np.array([float(ndl)]), term.values())
    return [mpmath.mpf(float(c)) for c in np.asarray(r, dtype=np.float64)[0]]


@dataclass(frozen=True)
class StabilityRow:
    """One case's result (channel-wise arrays are lists of 3 floats)."""

    case: str
    group: str
    gpu: list
    expected: list
    twin: list
    low: list
    high: list
    relative_error: float
    band_width: float
    passed: bool
    nan: int
    inf: int
    in_range: bool
    note: str = ""
    numerics: tuple = ()


@dataclass
class StabilityReport:
    """The table of a stability run."""

    backend: str
    renderer: str
    formulation: str
    rows: list = field(default_factory=list)
    numerics: str = "stable"

    @property
    def passed_count(self):
        return sum(r.passed for r in self.rows)

    @property
    def nan_count(self):
        return sum(r.nan for r in self.rows)

    @property
    def inf_count(self):
        return sum(r.inf for r in self.rows)

    def to_json(self):
        """The whole report as a JSON string."""
        return json.dumps(asdict(self) | {"passed": self.passed_count, "cases": len(self.rows)}, indent=1,
                          default=float, allow_nan=True)

    def format_table(self):
        """A fixed-width text table, one case per line (the channel with the largest expected value)."""
        head = (f"{'case':44s} {'GPU':>12s} {'float64':>12s} {'rel err':>9s} {'band':>9s} {'':4s} NaN Inf  note")
        mode = f", numerics={self.numerics}" if self.formulation == "stable" else ""
        lines = [f"glphong stability: {self.formulation} formulation{mode} on {self.backend} ({self.renderer})", head,
                 "-" * len(head)]
        for r in self.rows:
            c = int(np.argmax(np.abs(r.expected))) if np.any(np.isfinite(r.expected)) else 0
            lines.append(f"{r.case[:44]:44s} {r.gpu[c]:12.5g} {r.expected[c]:12.5g} {r.relative_error:9.2g} "
                         f"{r.band_width:9.2g} {'pass' if r.passed else 'FAIL'} {r.nan:3d} {r.inf:3d}  "
                         f"{'' if r.in_range else '[outside valid range] '}{r.note}"
                         f"{' [specialised: ' + ', '.join(r.numerics) + ']' if r.numerics else ''}")
        lines.append(f"{self.passed_count}/{len(self.rows)} cases inside the tolerance band; "
                     f"{self.nan_count} NaN and {self.inf_count} Inf channels")
        return "\n".join(lines)


def case_numerics(case, scene=None):
    """The pieces ``Renderer(numerics='auto')`` specialises for the case's object (`glphong.shaders.numerics`), less
    'normal': the case's point is shaded with its own normal, which the points program normalises stably (sorted
    tuple).  The point, the origin, lies in the object's box, over which the pieces were decided."""
    scene = case_scene(case) if scene is None else scene
    return numerics_pieces(scene, scene.objects[0], tuple(p for p in NUMERICS_PIECES if p != "normal"))


class CaseExpectations:
    """The CPU side of the suite, kept for several runs: each case's float64 twin, tolerance band and oracle.

    They read the case and the uniforms its program is given, never the backend, the formulation or the
    numerics pieces, so runs on two backends, or of the stable, naive and auto formulations, may share one
    instance (pass it as ``run_stability(..., expectations=...)``) and compute them once: that is nine tenths of
    a run's time.  An entry is found by a digest of the case's name and validity, its program key (the model's and
    kinds' source hashes included) and its uniforms (names, dtypes, shapes and bytes): a uniform wired or a model
    written differently is computed afresh, never served from an earlier run.
    """

    def __init__(self):
        self._memo = {}

    def __len__(self):
        return len(self._memo)

    def of(self, case, scene, key, uniforms):
        """``(twin, low, high, expected)`` of ``case``, each (3,) float64: `case_expectation`, once per case and
        uniforms."""
        digest = hashlib.sha256(f"{case.name}|{case.in_range}|{key!r}".encode())
        for name in sorted(uniforms):
            value = np.ascontiguousarray(uniforms[name])
            digest.update(f"{name}{value.dtype}{value.shape}".encode())
            digest.update(value.tobytes())
        entry = digest.hexdigest()
        if entry not in self._memo:
            self._memo[entry] = case_expectation(case, scene, key, uniforms)
        return self._memo[entry]


def case_expectation(case, scene, key, uniforms):
    """The CPU side of one case: ``(twin, low, high, expected)``, each (3,) float64.

    ``twin`` is the float64 mirror of the GLSL at the case's point, ``low`` and ``high`` the band the GPU must lie in,
    ``expected`` the oracle's value.  Inside the valid range the band's widths are moved onto the oracle: the twin and
    the band read the uniforms, the oracle the constructors, so a wrongly wired input shows (a band reaching 0 stays
    at 0, or follows the oracle below it where the model may be negative).  Outside it, the documented float32
    behaviour (flush, saturation), which the twin mirrors, within the band around it.
    """
    position = np.zeros((1, 3))
    normal = np.asarray([case.normal], dtype=np.float32).astype(np.float64)
    tangent = np.asarray([case.tangent], dtype=np.float32).astype(np.float64)
    uv = np.asarray([case.uv], dtype=np.float32).astype(np.float64)
    u64 = {k: v.astype(np.float64) for k, v in uniforms.items()}
    n_valid, n, _ = ref.safe_normalize(normal)
    frame = ref.shading_frame(n, tangent, uv, key)
    twin = ref.shade_point(position, frame, n_valid, u64.get("u_eye"), key, u64, case.material)[0]
    low, high = point_band(key, u64, position, frame, n_valid, case.material)
    low, high = low[0], high[0]
    expected = oracle(scene, case.normal, tangent=case.tangent, uv=case.uv)
    if case.in_range:
        shifted = expected - (twin - low)
        low = np.where(low > 0, shifted, np.where(low < 0, np.minimum(0.0, shifted), 0.0))
        high = expected + (high - twin)
    return twin, low, high, expected


def run_stability(backend="auto", formulation="stable", cases=CASES, context=None, numerics="stable",
                  expectations=None):
    """Run the suite on a backend.

    Parameters
    ----------
    backend : {'auto', 'egl', 'osmesa'}
    formulation : {'stable', 'naive'}
        The shader formulation to evaluate ('naive': the textbook ``pow(dot(v, r), q)`` one).
    cases : sequence of Case
    context : glphong.gpu.contexts.GLContext, optional
        Use this context instead of creating one.
    numerics : {'stable', 'auto'}
        With the stable formulation, 'auto' evaluates each case with the pieces ``Renderer(numerics='auto')``
        would specialise for it (`case_numerics`; each row lists them).
    expectations : CaseExpectations, optional
        The twins, bands and oracles of earlier runs, to share with this one (default: computed for this run).

    Returns
    -------
    StabilityReport
    """

    gl = context or create_context(backend)
    programs = ProgramCache(gl.mgl)
    expectations = CaseExpectations() if expectations is None else expectations
    report = StabilityReport(gl.backend, gl.renderer_name, formulation, numerics=numerics)
    try:
        for case in cases:
            scene = case_scene(case)
            key, uniforms = case_inputs(case, scene)
            twin, low, high, expected = expectations.of(case, scene, key, uniforms)
            pieces = case_numerics(case, scene) if numerics == "auto" and formulation == "stable" else ()
            gpu = shade_points(gl, programs, replace(key, formulation=formulation, numerics=pieces), uniforms,
                               np.zeros((1, 3)), np.asarray([case.normal], dtype=np.float32),
                               tangents=np.asarray([case.tangent], dtype=np.float32),
                               uvs=np.asarray([case.uv], dtype=np.float32),
                               drop_unused=formulation == "naive")[0].astype(np.float64)
            finite_band = np.isfinite(high)
            ok = np.all((gpu >= low) & (gpu <= high)) and not np.any(np.isnan(gpu)) and \
                np.all(np.isfinite(gpu[finite_band]))
            with np.errstate(divide="ignore", invalid="ignore"):
                width = np.where(twin > 0, (high - low) / twin, 0.0)
            report.rows.append(StabilityRow(
                case.name, case.group, gpu.tolist(), expected.tolist(), twin.tolist(), low.tolist(), high.tolist(),
                float(np.max(np.nan_to_num(relative_error(gpu, expected), nan=np.inf))), float(np.nanmax(width)), bool(ok), int(np.isnan(gpu).sum()),
                int(np.isinf(gpu).sum()), case.in_range, case.note, pieces))
    finally:
        with gl:
            programs.release()
        if context is None:
            gl.release()
    return report
