"""Drawing the shadow maps of a frame (docs/design.md section 12).

Each shadowing light's map (`glphong.scene.shadows.ShadowSetup`) is a float32 texture: six faces (three across,
two up) for a light at a point, one square for a light at infinity.  The pass (`glphong.shaders.key.shadow_key`,
glsl/shadow_fragment.glsl) draws every object that casts shadows into it, writing its distance from the light, and
blends with MIN into a target cleared to FLT_MAX, so each texel keeps the nearest caster's distance exactly as
float32 computes it (no depth buffer and no depth precision in the way).  Textures are kept per size and reused
from frame to frame; the maps are redrawn every frame.
"""
import moderngl

from glphong.core.validate import FLT_MAX
from glphong.shaders.builders import shadow_key

__all__ = ["ShadowMap", "ShadowMaps", "shadow_map_bytes"]


class ShadowMap:
    """A drawn shadow map: its texture, bound to a program's sampler unit (`glphong.gpu.programs`)."""

    def __init__(self, texture, setup):
        self.texture = texture
        self.setup = setup

    def use(self, unit):
        """Bind the texture to texture unit ``unit``."""
        self.texture.use(location=unit)


def shadow_map_bytes(setups):
    """GPU memory of the maps of ``setups`` [bytes]: 4 bytes a texel (float32)."""
    return sum(4 * setup.texture_size[0] * setup.texture_size[1] for setup in setups)


class ShadowMaps:
    """The shadow-map textures and framebuffers of one renderer, kept per (slot, texture size) among the renderer's
    render targets (``targets``, released with them)."""

    def __init__(self, mgl, targets):
        self._mgl = mgl
        self._targets = targets

    def draw(self, setups, casters, programs, vertex_array):
        """Draw each map of ``setups``.

        Parameters
        ----------
        setups : sequence of glphong.scene.shadows.ShadowSetup
        casters : sequence of glphong.scene.scene.SceneObject
            The objects that cast shadows.
        programs : glphong.gpu.programs.ProgramCache
        vertex_array : callable
            ``vertex_array(mesh, program)``: the mesh's vertex array for a program (the renderer's buffers).

        Returns
        -------
        dict of str to ShadowMap
            By sampler uniform name, ``u_shadow_map<slot>``.
        """
        mgl = self._mgl
        out = {}
        mgl.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        mgl.enable(moderngl.BLEND)
        mgl.blend_func = moderngl.ONE, moderngl.ONE
        mgl.blend_equation = moderngl.MIN
        try:
            for setup in setups:
                texture, fbo = self._target(setup)
                fbo.use()
                fbo.clear(FLT_MAX, FLT_MAX, FLT_MAX, FLT_MAX)
                program = programs.get(shadow_key(setup.map))
                base = {"u_shadow_origin": setup.origin}
                if setup.map == "ortho":
                    base["u_shadow_axis"] = setup.axis
                for face, matrix in enumerate(setup.face_matrices()):
                    fbo.viewport = (*setup.face_origin(face), setup.size, setup.size)
                    for obj in casters:
                        program.bind({**base, "u_model": obj.pose, "u_view_projection": matrix})
                        vertex_array(obj.mesh, program).render(moderngl.TRIANGLES)
                out[f"u_shadow_map{setup.slot}"] = ShadowMap(texture, setup)
        finally:
            mgl.blend_equation = moderngl.FUNC_ADD
            mgl.blend_func = moderngl.DEFAULT_BLENDING
            mgl.disable(moderngl.BLEND)
        return out

    def _target(self, setup):
        key = ("shadow", setup.slot, setup.texture_size)
        fbo = self._targets.get(key)
        if fbo is None:
            texture = self._mgl.texture(setup.texture_size, 1, dtype="f4")
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            texture.repeat_x = texture.repeat_y = False
            fbo = self._targets[key] = self._mgl.framebuffer(color_attachments=[texture])
        return fbo.color_attachments[0], fbo
