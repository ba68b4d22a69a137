"""Where each shadowing light's map lies (docs/design.md section 12): its geometry, computed once from the scene in
float64 and read by the renderer (to draw the map), the shader (its uniforms) and the twin (its band).

A light with ``shadows=True`` of a kind whose ``shadow_map`` is 'cube' gets six faces around its position
(`ShadowSetup.face_matrices`, the face conventions of glsl/shadows.glsl); one of kind 'ortho' gets an orthographic
map over the bounding box of every object of the scene, square, looking along its direction.
"""
import weakref
from dataclasses import dataclass

import numpy as np

from glphong.twin.functions import perpendiculars

__all__ = ["ShadowSetup", "shadow_setups", "scene_bounds", "object_bounds", "CUBE_FACES"]

#: the cube's faces in map order: (major axis, sign, the two other axes)
CUBE_FACES = tuple((a, s, tuple(b for b in range(3) if b != a)) for a in range(3) for s in (1.0, -1.0))


@dataclass(frozen=True)
class ShadowSetup:
    """One shadowing light's map.

    Attributes
    ----------
    slot : int
        Its number among the program's shadow maps (uniforms ``u_shadow_*<slot>``), in key order.
    kind : str
        The light's kind; ``index`` its number among the scene's lights of that kind.
    index : int
    map : {'cube', 'ortho'}
    size : int
        Texels along a side (a cube map: of each face).
    origin : (3,) ndarray
        Cube: the light's position [m]; ortho: the corner of the map's volume nearest the light [m].
    axis : (3,) ndarray
        Ortho: the unit direction of travel (cube: zeros).
    e1, e2 : (3,) ndarray
        Ortho: the map's axes in texels per metre (cube: zeros).
    texel : float
        Cube: the largest angle a texel subtends, ``2 / size`` [rad]; ortho: a texel's side [m].
    near, far : float
        The distances the pass draws between [m].
    """

    slot: int
    kind: str
    index: int
    map: str
    size: int
    origin: np.ndarray
    axis: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    texel: float
    near: float
    far: float

    @property
    def texture_size(self):
        """``(width, height)`` of the map's texture: six faces, three across and two up, for a cube."""
        return (3 * self.size, 2 * self.size) if self.map == "cube" else (self.size, self.size)

    def face_origin(self, face):
        """The texel where face ``face`` starts in the texture, ``(x, y)``."""
        return (face % 3) * self.size, (face // 3) * self.size

    def face_matrices(self):
        """The clip matrices of the pass, (4, 4) float64 each: six for a cube (in `CUBE_FACES` order), one for an
        orthographic map.  A cube face maps ``v = x - origin`` to clip ``(v_b, v_c, A w + B, w)``, ``w = s v_a``,
        so that its texel ``(i, j)`` is the ray through ``((i + 1/2) / size, (j + 1/2) / size)`` of
        glsl/shadows.glsl's ``cube_face``."""
        if self.map == "ortho":
            m = np.zeros((4, 4))
            depth = self.far
            m[0, :3], m[1, :3] = 2.0 * self.e1 / self.size, 2.0 * self.e2 / self.size
            m[2, :3] = 2.0 * self.axis / depth
            m[:3, 3] = -m[:3, :3] @ self.origin - 1.0
            m[3, 3] = 1.0
            return [m]
        n, f = self.near, self.far
        a_coef, b_coef = (f + n) / (f - n), -2.0 * f * n / (f - n)
        out = []
        for a, s, (b, c) in CUBE_FACES:
            rows = np.zeros((4, 3))
            rows[0, b], rows[1, c] = 1.0, 1.0
            rows[3, a] = s
            rows[2] = a_coef * rows[3]
            m = np.zeros((4, 4))
            m[:, :3] = rows
            m[:, 3] = -rows @ self.origin
            m[2, 3] += b_coef
            out.append(m)
        return out

    def uniform_values(self):
        """The shading program's uniforms of this map (float64; the sampler is bound by the renderer)."""
        values = {f"u_shadow_origin{self.slot}": self.origin, f"u_shadow_texel{self.slot}": self.texel}
        if self.map == "ortho":
            values |= {f"u_shadow_axis{self.slot}": self.axis, f"u_shadow_e1{self.slot}": self.e1,
                       f"u_shadow_e2{self.slot}": self.e2}
        return values


#: per mesh (immutable), the world bounds of its vertices under the poses it was last seen with
_BOUNDS = weakref.WeakKeyDictionary()


def object_bounds(mesh, pose):
    """``(low, high)`` of ``mesh``'s vertices under ``pose``, walked once per mesh and pose: a scene rebuilt every
    frame from the same meshes (pyrender's, `glphong.integrations.pyrender.shadows`) does not walk them again."""
    seen = _BOUNDS.get(mesh)
    if seen is None:
        seen = _BOUNDS[mesh] = {}
    key = np.asarray(pose, dtype=np.float64).tobytes()
    bounds = seen.get(key)
    if bounds is None:
        if len(seen) >= 16:  # a moving object: keep the last few poses only
            seen.clear()
        p = mesh.positions @ pose[:3, :3].T + pose[:3, 3]
        bounds = seen[key] = (p.min(axis=0), p.max(axis=0))
    return bounds


def scene_bounds(scene):
    """``(low, high)`` (3,) float64: the world-space bounding box of every object of ``scene``."""
    corners = []
    for obj in scene.objects:
        corners += list(object_bounds(obj.mesh, obj.pose))
    if not corners:
        return np.zeros(3), np.zeros(3)
    return np.min(corners, axis=0), np.max(corners, axis=0)


def shadow_setups(scene, key_lights, size):
    """The `ShadowSetup` of each shadowing light of a program's ``key_lights`` (its `LightKey` tuple), in slot order.

    Parameters
    ----------
    scene : glphong.Scene
    key_lights : tuple of glphong.shaders.key.LightKey
    size : int
        Texels along a side.
    """
    low, high = scene_bounds(scene)
    corners = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])
    out = []
    for light_key in key_lights:
        mine = [light for light in scene.lights if light.kind == light_key.name]
        for j in light_key.shadowed:
            light = mine[j]
            slot = len(out)
            if light.shadow_map == "cube":
                origin = np.asarray(light.position, dtype=np.float64)
                far = 2.0 * max(float(np.max(np.linalg.norm(corners - origin, axis=1))), 1e-30)
                out.append(ShadowSetup(slot, light.kind, j, "cube", size, origin, np.zeros(3), np.zeros(3), np.zeros(3),
                                       2.0 / size, far * 1e-7, far))
                continue
            axis = np.asarray(light.direction, dtype=np.float64)
            u1, u2 = perpendiculars(axis)
            centre = 0.5 * (low + high)
            offsets = corners - centre
            half = max(float(np.max(np.abs(offsets @ u1))), float(np.max(np.abs(offsets @ u2))), 1e-30) * (1.0 + 2.0 / size)
            depth = max(float(np.max(np.abs(offsets @ axis))), 1e-30) * 1.01
            origin = centre - half * (u1 + u2) - depth * axis
            texel = 2.0 * half / size
            out.append(ShadowSetup(slot, light.kind, j, "ortho", size, origin, axis, u1 / texel, u2 / texel, texel,
                                   0.0, 2.0 * depth))
    return out
