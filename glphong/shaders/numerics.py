"""Stability where a scene needs it: which pieces of a program's arithmetic ``Renderer(numerics='auto')``
specialises, decided per object from the values the scene holds (docs/design.md section 3, "Stability where a
scene needs it").

The stable formulation of section 3 guards against ranges a scene may not have.  For each piece of
`glphong.shaders.key.NUMERICS_PIECES` this module evaluates the bound of the design document over the object's
ranges and returns a `NumericsDecision`: the piece is specialised only where the bound is established, and keeps the
stable arithmetic, with the reason, everywhere else.

- ``normal``, ``view``, ``light``: the textbook ``normalize(x)`` / ``length(x)`` (``plain_normalize``) in place of
  ``safe_normalize`` at the fragment normal, the view vector, and the direction of point, spot and unattenuated
  lights.  Proven where every length the site can see lies in ``[NORMAL_LENGTHS[0], NORMAL_LENGTHS[1]]`` (its square
  in float32's normal range with margin) and stays above the float32 resolution of the positions it is made from:
  there the textbook arithmetic makes a subset of the stable one's roundings (no division by the largest component),
  so its error is within the stable one's bound, which the band covers.
- ``falloff``: ``I / (d d)`` in place of ``min((I / d) / d, FLT_MAX)`` for point lights, proven where ``d`` is in the
  range above and ``I / d^2`` stays below ``FLT_MAX / 16`` at the nearest point of the object (one rounding and one
  division against two divisions).
- ``lobe_tail``: the cosine-power lobes leave out their ``log`` branch (``delta >= 1/2``, ``cos <= 1/2``) where every
  lobe exponent of the object's material is a constant of at least `LOBE_TAIL_Q`: there both forms give 0, bit for
  bit.

The pieces are chosen from the object's world bounding box (its vertices under its pose), the camera (position, near
plane, orthographic or not), the lights' positions and intensities as float32 uniforms, the vertex normals and the
normal matrix, and the material's exponents.  The textbook lobe ``pow(dot(v, r), q)`` is never chosen: section 3
shows that its error near the horizon exceeds the band for every ``q > 0``.
"""
import weakref
from dataclasses import dataclass, replace

import numpy as np

from glphong.scene.camera import OrthographicCamera
from glphong.scene.shadows import object_bounds
from glphong.shaders.options import NUMERICS_PIECES

__all__ = ["NumericsDecision", "numerics_decisions", "numerics_pieces", "allowed_pieces", "with_numerics", "view_decision",
           "normal_range", "NUMERICS", "NORMAL_LENGTHS", "POSITION_RESOLUTION", "FALLOFF_LIMIT", "LOBE_TAIL_Q"]

#: the choices of ``Renderer(numerics=...)``: 'auto' specialises what the scene's ranges prove, 'stable' nothing
NUMERICS = ("auto", "stable")
#: lengths whose squares, and sums of three squares, stay in float32's normal range with margin: 2^-50 to 2^63
#: (a component below 2^-63 has a flushed square, at most 2^-126 against |x|^2 >= 2^-100: a relative 2^-26)
NORMAL_LENGTHS = (2.0 ** -50, 2.0 ** 63)
#: a float32 position is resolved to 2^-24 of its largest coordinate; the bound asks 16 times that as margin for
#: the rounding of interpolated positions and uniforms
POSITION_RESOLUTION = 2.0 ** -20
#: the largest point-light irradiance the textbook falloff may produce [W/m^2]: FLT_MAX / 16
FALLOFF_LIMIT = float(np.finfo(np.float32).max) / 16
#: the smallest exponent for which the lobe is 0 in float32 wherever delta >= 1/2:
#: 151 (ln(1/2) + 2^-21) < -104, and exp(-104) ~ 6.8e-46 rounds to 0
LOBE_TAIL_Q = 151.0


@dataclass(frozen=True)
class NumericsDecision:
    """Whether one piece of arithmetic is specialised for one object, and why.

    Attributes
    ----------
    piece : str
        One of `glphong.shaders.key.NUMERICS_PIECES`.
    specialised : bool
        True: the program compiles the piece's specialised form (its define set).
    reason : str
        The bound that was established, or why it could not be.
    """

    piece: str
    specialised: bool
    reason: str


def _fmt(x):
    return f"{x:.3g}"


def _box_distances(point, low, high):
    """``(nearest, farthest)`` distance from ``point`` (3,) to the box ``[low, high]`` [m]."""
    point = np.asarray(point, dtype=np.float64)
    nearest = float(np.linalg.norm(np.maximum(np.maximum(low - point, 0.0), point - high)))
    farthest = float(np.linalg.norm(np.maximum(np.abs(point - low), np.abs(point - high))))
    return nearest, farthest


def _length_check(what, nearest, farthest, scale):
    """None where lengths from ``nearest`` to ``farthest`` pass the normal-range bound, else the reason it fails;
    ``scale``: the largest coordinate magnitude the vector is made from."""
    floor = max(NORMAL_LENGTHS[0], POSITION_RESOLUTION * scale)
    if not np.isfinite(farthest) or not nearest >= floor:
        return f"{what} may be as short as {_fmt(nearest)}, below {_fmt(floor)}"
    if farthest > NORMAL_LENGTHS[1]:
        return f"{what} may be as long as {_fmt(farthest)}, above 2^63"
    return None


#: per mesh (immutable): the smallest value of min(|n_i|^2, n_i . n_j) over its triangles, and the largest |n_i|
_NORMAL_RANGES = weakref.WeakKeyDictionary()


def normal_range(mesh):
    """``(low, high)``: a lower bound on the squared length of every convex combination of a triangle's vertex
    normals, over the triangles of ``mesh``, and the largest vertex normal length (object space; cached per mesh).

    The bound: for weights ``w_i >= 0`` summing to 1, ``|sum w_i n_i|^2 = sum_ij w_i w_j n_i . n_j >= min_ij n_i . n_j``
    (the diagonal terms are ``|n_i|^2``), so where every pairwise dot product of a triangle is positive the
    interpolated normal is never shorter than ``sqrt(low)``.  ``low`` is 0 or negative where a triangle's normals may
    cancel (or are not finite).
    """
    cached = _NORMAL_RANGES.get(mesh)
    if cached is None:
        n = np.asarray(mesh.normals, dtype=np.float64)
        tri = np.asarray(mesh.indices, dtype=np.int64).reshape(-1, 3)
        if not np.all(np.isfinite(n)):
            cached = (-np.inf, np.inf)
        elif len(tri) == 0:
            cached = (np.inf, 0.0)
        else:
            a, b, c = n[tri[:, 0]], n[tri[:, 1]], n[tri[:, 2]]
            dots = [np.einsum("ij,ij->i", u, v) for u, v in ((a, a), (b, b), (c, c), (a, b), (b, c), (a, c))]
            cached = (float(np.min(np.minimum.reduce(dots))), float(np.sqrt(np.max(np.einsum("ij,ij->i", n, n)))))
        _NORMAL_RANGES[mesh] = cached
    return cached


def _normal_decision(obj):
    low, high = normal_range(obj.mesh)
    if not low > 0:
        return False, "a triangle's vertex normals may cancel (a pairwise dot product is not positive) or are not finite"
    stretch = np.linalg.svd(np.asarray(obj.normal_matrix, dtype=np.float64), compute_uv=False)
    shortest, longest = float(np.sqrt(low) * stretch[-1]), float(high * stretch[0])
    why = _length_check("the interpolated normal", shortest, longest, longest)
    return (False, why) if why else \
        (True, f"interpolated normals from {_fmt(shortest)} to {_fmt(longest)} long (pairwise dots of each triangle's "
               "normals positive)")


#: per scene object: (the camera last asked about, its view decision)
_VIEWS = weakref.WeakKeyDictionary()


def view_decision(obj, camera):
    """``(specialised, reason)`` of the ``view`` piece for ``obj`` seen by ``camera`` (kept per object for the camera
    last asked about: a renderer asks again only when the scene's camera is another object)."""
    seen = _VIEWS.get(obj)
    if seen is not None and seen[0] is camera:
        return seen[1]
    low, high = object_bounds(obj.mesh, obj.pose)
    found = _view_decision(camera, low, high)
    _VIEWS[obj] = (camera, found)
    return found


def _view_decision(camera, low, high):
    if isinstance(camera, OrthographicCamera):
        return True, "orthographic camera: the view vector is the camera's unit backward axis"
    eye = np.asarray(camera.pose[:3, 3], dtype=np.float64)
    nearest, farthest = _box_distances(eye, low, high)
    nearest = max(nearest, camera.znear * (1 - POSITION_RESOLUTION))  # a fragment lies beyond the near plane
    scale = max(float(np.max(np.abs(eye))), float(np.max(np.abs(np.concatenate([low, high])))))
    why = _length_check("the view vector", nearest, farthest, scale)
    return (False, why) if why else (True, f"view distances from {_fmt(nearest)} to {_fmt(farthest)} m")


def _light_decisions(lights, low, high):
    """``(light ok, light reason), (falloff ok, falloff reason)`` over the scene's lights whose kind reads the pieces
    (`glphong.lights.LightModel.numerics_bounds`)."""
    box_scale = float(np.max(np.abs(np.concatenate([low, high]))))
    direction, falloff = [], []
    light_why = falloff_why = None
    for j, light in enumerate(lights):
        bounds = type(light).numerics_bounds
        if "light" not in bounds:
            continue
        position = np.asarray(light.uniform_value(bounds["light"]), dtype=np.float32).astype(np.float64)
        nearest, farthest = _box_distances(position, low, high)
        why = _length_check(f"the direction to {light.kind} light {j}", nearest, farthest,
                            max(box_scale, float(np.max(np.abs(position)))))
        light_why = light_why or why
        direction.append((nearest, farthest))
        if "falloff" in bounds:
            intensity = float(np.max(np.asarray(light.uniform_value(bounds["falloff"]), dtype=np.float32)))
            peak = intensity / nearest ** 2 if nearest > 0 else np.inf
            falloff_why = falloff_why or why or (
                f"point light {j}'s irradiance may reach {_fmt(peak)} W/m^2, above FLT_MAX / 16" if peak > FALLOFF_LIMIT
                else None)
            falloff.append(peak)
    if not direction:
        light_result = (False, "no light whose direction the piece normalises (point, spot, unattenuated)")
    elif light_why:
        light_result = (False, light_why)
    else:
        light_result = (True, f"light distances from {_fmt(min(d[0] for d in direction))} to "
                              f"{_fmt(max(d[1] for d in direction))} m")
    if not falloff:
        falloff_result = (False, "no light with the point falloff")
    elif falloff_why:
        falloff_result = (False, falloff_why)
    else:
        falloff_result = (True, f"point-light irradiance at most {_fmt(max(falloff))} W/m^2, distances in range")
    return light_result, falloff_result


def _lobe_tail_decision(material):
    exponents = []
    for term in material.components:
        if "lobe" not in term.uses:
            continue
        if term.lobe_exponent is None:
            return False, f"{term.name} evaluates lobes with exponents of its own"
        q = getattr(term, term.lobe_exponent)
        if not isinstance(q, (int, float, np.integer, np.floating)):
            return False, f"{term.name}'s exponent {term.lobe_exponent} varies over the surface"
        q = float(np.float32(q))
        if q < LOBE_TAIL_Q:
            return False, f"{term.name}'s exponent q = {q:g} is below {LOBE_TAIL_Q:g}: its lobe is not 0 at cos <= 1/2"
        exponents.append(q)
    if not exponents:
        return False, "no cosine-power lobe"
    return True, f"lobe exponents from {min(exponents):g}: the lobe is 0 in float32 wherever cos <= 1/2"


def numerics_decisions(scene, obj, pieces=NUMERICS_PIECES):
    """The decision on each of ``pieces`` (default every piece of `glphong.shaders.key.NUMERICS_PIECES`) for one object
    of a scene.

    Parameters
    ----------
    scene : glphong.Scene
    obj : glphong.scene.scene.SceneObject
        One of the scene's objects.
    pieces : tuple of str
        The pieces to decide (only their bounds are evaluated).

    Returns
    -------
    tuple of NumericsDecision
        In the order of `NUMERICS_PIECES`.
    """
    pieces = tuple(p for p in NUMERICS_PIECES if p in pieces)
    low, high = object_bounds(obj.mesh, obj.pose)
    if not (np.all(np.isfinite(low)) and np.all(np.isfinite(high))):
        return tuple(NumericsDecision(p, False, "the object's bounds are not finite") for p in pieces)
    found = {}
    if "light" in pieces or "falloff" in pieces:
        found["light"], found["falloff"] = _light_decisions(scene.lights, low, high)
    if "normal" in pieces:
        found["normal"] = _normal_decision(obj)
    if "view" in pieces:
        found["view"] = view_decision(obj, scene.camera)
    if "lobe_tail" in pieces:
        found["lobe_tail"] = _lobe_tail_decision(obj.material)
    return tuple(NumericsDecision(piece, bool(found[piece][0]), found[piece][1]) for piece in pieces)


def numerics_pieces(scene, obj, pieces=NUMERICS_PIECES):
    """The specialised pieces of `numerics_decisions`, sorted (the `ProgramKey.numerics` of the object)."""
    return tuple(sorted(d.piece for d in numerics_decisions(scene, obj, pieces) if d.specialised))


#: the pieces a program of each output may specialise: the G-buffer writes the normal exactly as the radiance program
#: shades with it, so it normalises it the same way
_OUTPUT_PIECES = {"radiance": NUMERICS_PIECES, "display": NUMERICS_PIECES, "gbuffer": ("normal",)}


def allowed_pieces(key):
    """The pieces a program of ``key`` may specialise (tuple): by its output, for the stable formulation's
    specialised programs; none for the uber-shader, the textbook formulation and the other outputs."""
    return () if key.uber or key.formulation != "stable" else _OUTPUT_PIECES.get(key.output, ())


def with_numerics(key, scene, obj, decisions=None):
    """``key`` (a `glphong.shaders.key.ProgramKey` of ``obj``) with the pieces proven for ``obj`` among
    `allowed_pieces` (``decisions``: `numerics_decisions` already made for it, else made here)."""
    allowed = allowed_pieces(key)
    if not allowed:
        return key
    if decisions is None:
        decisions = numerics_decisions(scene, obj, allowed)
    pieces = tuple(sorted(d.piece for d in decisions if d.specialised and d.piece in allowed))
    return replace(key, numerics=pieces) if pieces != key.numerics else key
