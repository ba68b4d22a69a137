"""glphong's shadow maps inside a pyrender frame (docs/design.md section 12).

When pyrender's render flags ask for a light's shadows (``SHADOWS_DIRECTIONAL``, ``SHADOWS_SPOT``,
``SHADOWS_POINT``), the surfaces with a `GlphongMaterial` read glphong's own maps of that light, drawn with
glphong's shadow pass (`glphong.gpu.shadows.ShadowMaps`) from pyrender's vertex arrays: every visible triangle
primitive of the scene casts, whatever its material (each instance of an instanced one), as every one does in
pyrender's own pass.  The maps' geometry is `glphong.scene.shadows.shadow_setups` of those casters, so a
scene whose meshes all have glphong materials gets the maps `glphong.Renderer` draws for
`scene_from_pyrender` of it.  pyrender's own surfaces keep pyrender's maps (directional and spot lights; pyrender
has none for point lights).
"""
import weakref

import numpy as np
import pyrender

from glphong.gpu.shadows import ShadowMaps
from glphong.materials import Lambert
from glphong.scene.geometry import MeshData
from glphong.shaders.binding import binding

__all__ = ["EmbeddedShadows"]

#: what a caster is added to the glphong scene with: it is only ever drawn into shadow maps
_CASTER = Lambert(0.0)


class _PrimitiveDraw:
    """Draws a pyrender primitive's own vertex array (position at location 0, as glphong's shadow pass reads it)."""

    def __init__(self, primitive, program):
        self.primitive, self.program = primitive, program

    def render(self, mode):
        from OpenGL.GL import GL_TRIANGLES, GL_UNSIGNED_INT, glDrawArrays, glDrawElements, glUseProgram

        primitive = self.primitive
        glUseProgram(self.program.gl_program.glo)
        primitive._bind()
        if primitive.indices is not None:
            glDrawElements(GL_TRIANGLES, primitive.indices.size, GL_UNSIGNED_INT, None)
        else:
            glDrawArrays(GL_TRIANGLES, 0, len(primitive.positions))
        primitive._unbind()


class EmbeddedShadows:
    """The shadow maps of one enabled pyrender renderer: their textures, and each caster's positions (for the maps'
    bounds), read once per primitive.

    Parameters
    ----------
    mgl : moderngl.Context
        pyrender's context, attached (`glphong.gpu.contexts.attach_current`).
    """

    def __init__(self, mgl):
        self._targets = {}
        self._maps = ShadowMaps(mgl, self._targets)
        self._meshes = weakref.WeakKeyDictionary()  # pyrender primitive -> MeshData of its positions
        self._primitives = {}  # id(MeshData) -> primitive, for this frame's draw

    def add_casters(self, glphong_scene, scene):
        """Add every visible triangle primitive of pyrender ``scene`` to ``glphong_scene`` as an object that casts
        shadows (each instance of an instanced one), with a stand-in material: they are drawn into the maps only."""
        self._primitives = {}
        for node in scene.mesh_nodes:
            if not node.mesh.is_visible:
                continue
            pose = scene.get_pose(node)
            for primitive in node.mesh.primitives:
                if primitive.mode != pyrender.constants.GLTF.TRIANGLES:
                    continue
                data = self._meshes.get(primitive)
                if data is None:
                    positions = np.asarray(primitive.positions, dtype=np.float64)
                    count = len(positions) - len(positions) % 3
                    indices = np.arange(count, dtype=np.int64).reshape(-1, 3) if primitive.indices is None else \
                        np.rint(np.asarray(primitive.indices, dtype=np.float64)).astype(np.int64).reshape(-1, 3)
                    data = self._meshes[primitive] = MeshData(positions, np.zeros_like(positions), indices)
                self._primitives[id(data)] = primitive
                instances = [np.eye(4)] if primitive.poses is None else primitive.poses
                for instance in instances:
                    glphong_scene.add(data, _CASTER, pose=pose @ instance, name=node.name)

    def draw(self, glphong_scene, programs, size):
        """Draw the maps of ``glphong_scene``'s shadowing lights; their sampler values by uniform name (dict).  The GL
        state the pass changes (framebuffer bindings, viewport, write masks, capabilities) is restored for pyrender."""
        from OpenGL import GL

        lights = binding(glphong_scene).light_keys()
        if not any(k.shadowed for k in lights):
            return {}
        # moderngl's framebuffers set their own depth and colour write masks and scissor test: pyrender clears its
        # shadow maps before it sets the depth mask again, so every piece of state the pass touches is put back
        draw_fb = GL.glGetIntegerv(GL.GL_DRAW_FRAMEBUFFER_BINDING)
        read_fb = GL.glGetIntegerv(GL.GL_READ_FRAMEBUFFER_BINDING)
        viewport = [int(v) for v in GL.glGetIntegerv(GL.GL_VIEWPORT)]
        depth_mask = bool(GL.glGetBooleanv(GL.GL_DEPTH_WRITEMASK))
        color_mask = [bool(v) for v in GL.glGetBooleanv(GL.GL_COLOR_WRITEMASK)]
        enabled = {cap: bool(GL.glIsEnabled(cap)) for cap in (GL.GL_SCISSOR_TEST, GL.GL_DEPTH_TEST, GL.GL_CULL_FACE,
                                                               GL.GL_BLEND)}
        try:
            return self._maps.draw(binding(glphong_scene).shadow_setups(lights, size), glphong_scene.objects, programs,
                                   lambda mesh, program: _PrimitiveDraw(self._primitives[id(mesh)], program))
        finally:
            GL.glBindVertexArray(0)
            GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, int(draw_fb))
            GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, int(read_fb))
            GL.glViewport(*viewport)
            GL.glDepthMask(depth_mask)
            GL.glColorMask(*color_mask)
            for cap, on in enabled.items():
                (GL.glEnable if on else GL.glDisable)(cap)

    def release(self):
        """Free the maps' textures and framebuffers."""
        for fbo in self._targets.values():
            for texture in fbo.color_attachments:
                texture.release()
            fbo.release()
        self._targets.clear()
