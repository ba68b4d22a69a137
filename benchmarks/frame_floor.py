"""Where glphong's frame time goes on llvmpipe, and the floor under it (docs/speed.md, "Against PyVista and Open3D").

Per scene of the speed family (`glphong.bench.speed.speed_scenes`), in one process, interleaved rounds (each round
runs every step once, after two warm-up rounds), medians and their spread (25th to 75th percentile over the median):

- ``1x 8-bit``, ``4x 8-bit``: `Renderer.render_srgb8`, one sample and 4x MSAA (the frame the peers are timed against);
- ``4x draw``: the 4x display draw alone (clear, draw, ``glFinish``), no resolve or read-back;
- ``4x resolve``: the multisampled 8-bit target resolved into the single-sampled one (``glBlitFramebuffer``);
- ``resolve by shader``: the same averages by a full-screen pass of four ``texelFetch`` from a multisampled texture
  (the floor of any resolve on llvmpipe: its sample fetches);
- ``empty fill 1x``, ``empty fill 4x``: clear, then a full-screen triangle of a constant colour with the depth test
  (llvmpipe's fill rate with no shading);
- ``read RGB``, ``read RGBA``: ``glReadPixels`` of the resolved 8-bit target as RGB (a conversion in the driver) and
  as RGBA (a copy);
- ``constant 1x``, ``constant 4x``: the scene's triangles (every object, posed, with its own depth test, no culling)
  drawn with a constant colour into the 8-bit target, clear and ``glFinish`` (the rasteriser's share, no shading);
- ``vertex path``: the scene drawn by `render_srgb8` (one sample) with the camera turned away (no fragment: the
  vertex stage, the clip test, the clear and the read-back).

Run:  python benchmarks/frame_floor.py [--size 512] [--rounds 15] [--scenes plane "fine plane" "8 lights"]
"""
import argparse
import statistics

import moderngl
import numpy as np

import glphong
from glphong.bench.speed import speed_scenes
from glphong.core.timing import alternating_times
from glphong.gpu.resources import read_attachment
from glphong.scene.camera import PerspectiveCamera

_FULLSCREEN = ("#version 330\nvoid main() { vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2); "
               "gl_Position = vec4(2.0 * p - 1.0, 0.5, 1.0); }")
_POSED = ("#version 330\nlayout(location = 0) in vec3 in_position;\nuniform mat4 u_clip;\n"
          "void main() { gl_Position = u_clip * vec4(in_position, 1.0); }")
_CONSTANT = "#version 330\nout vec4 c;\nvoid main() { c = vec4(0.2, 0.3, 0.4, 1.0); }"
_RESOLVE = ("#version 330\nuniform sampler2DMS u_samples;\nout vec4 c;\nvoid main() { ivec2 p = ivec2(gl_FragCoord.xy); "
            "c = 0.25 * (texelFetch(u_samples, p, 0) + texelFetch(u_samples, p, 1) + texelFetch(u_samples, p, 2) "
            "+ texelFetch(u_samples, p, 3)); }")


def _away(scene):
    """The scene with its camera turned to look away from everything (the same position and field of view)."""
    camera = scene.camera
    eye = camera.pose[:3, 3]
    turned = glphong.Scene(PerspectiveCamera.look_at(tuple(eye), tuple(eye + camera.pose[:3, 2]), yfov=camera.yfov,
                                                     znear=camera.znear, zfar=camera.zfar), scene.lights, scene.ambient)
    for obj in scene.objects:
        turned.add(obj.mesh, obj.material, pose=obj.pose)
    return turned


def steps(size, scene):
    """``{step: callable}`` for one scene (see the module)."""
    plain = glphong.Renderer(size, size, backend="egl")
    msaa = glphong.Renderer(size, size, backend="egl", samples=4)
    mgl = msaa._mgl
    constant = {}
    for renderer in (plain, msaa):
        with renderer.context:
            constant[renderer] = renderer._mgl.vertex_array(
                renderer._mgl.program(vertex_shader=_FULLSCREEN, fragment_shader=_CONSTANT), [])
    with msaa.context:
        program = mgl.program(vertex_shader=_FULLSCREEN, fragment_shader=_RESOLVE)
        program["u_samples"] = 0
        resolve = mgl.vertex_array(program, [])
        samples = mgl.texture((size, size), 4, samples=4)
        out = mgl.framebuffer([mgl.renderbuffer((size, size), 4)])
    away = _away(scene)

    def in_context(fn, renderer=msaa):
        def run():
            with renderer.context:
                fn()
                renderer._mgl.finish()
        return run

    def draw():
        msaa._draw(scene, "display", msaa._target("display"), {"u_exposure": 1.0})

    view_projection = scene.camera.projection_matrix(1.0) @ scene.camera.view_matrix()
    posed = {}
    for renderer in (plain, msaa):
        with renderer.context:
            gl = renderer._mgl
            program = gl.program(vertex_shader=_POSED, fragment_shader=_CONSTANT)
            objects = []
            for obj in scene.objects:
                vbo = gl.buffer(np.ascontiguousarray(obj.mesh.positions, np.float32).tobytes())
                ibo = gl.buffer(np.ascontiguousarray(obj.mesh.indices, np.uint32).tobytes())
                objects.append((gl.vertex_array(program, [(vbo, "3f", "in_position")], ibo, index_element_size=4),
                                np.ascontiguousarray((view_projection @ obj.pose).T, np.float32).tobytes()))
            posed[renderer] = (program, objects)

    def on_cleared_display(renderer, draw):
        """``draw()`` into the renderer's display target, cleared, depth test on, in its context."""
        def run():
            fbo = renderer._target("display")
            fbo.use()
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            renderer._mgl.enable(moderngl.DEPTH_TEST)
            draw()
        return in_context(run, renderer)

    def constant_draw(renderer):
        def draw():
            program, objects = posed[renderer]
            for vao, clip in objects:
                program["u_clip"].write(clip)
                vao.render(moderngl.TRIANGLES)
        return on_cleared_display(renderer, draw)

    def fill(renderer):
        return on_cleared_display(renderer, lambda: constant[renderer].render(moderngl.TRIANGLES, vertices=3))

    def by_shader():
        out.use()
        mgl.disable(moderngl.DEPTH_TEST)
        samples.use(0)
        resolve.render(moderngl.TRIANGLES, vertices=3)

    plain.render_srgb8(scene)
    msaa.render_srgb8(scene)
    return {"1x 8-bit": lambda: plain.render_srgb8(scene), "4x 8-bit": lambda: msaa.render_srgb8(scene),
            "4x draw": in_context(draw),
            "4x resolve": in_context(lambda: mgl.copy_framebuffer(msaa._target("srgb8"), msaa._target("display"))),
            "resolve by shader": in_context(by_shader),
            "empty fill 1x": fill(plain), "empty fill 4x": fill(msaa),
            "constant 1x": constant_draw(plain), "constant 4x": constant_draw(msaa),
            "read RGB": in_context(lambda: read_attachment(msaa._target("srgb8"), (size, size), 3, dtype="f1")),
            "read RGBA": in_context(lambda: read_attachment(msaa._target("srgb8"), (size, size), 4, dtype="f1")),
            "vertex path": lambda: plain.render_srgb8(away)}, (plain, msaa)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--scenes", nargs="+", default=["plane", "fine plane", "8 lights"])
    args = parser.parse_args()
    family = speed_scenes()
    print(f"{args.size}x{args.size}, EGL, {args.rounds} interleaved rounds after 2 warm-up rounds: median [ms] (spread)")
    for name in args.scenes:
        runs, renderers = steps(args.size, family[name])
        try:
            times = alternating_times(runs, args.rounds, warmup=2)
        finally:
            for renderer in renderers:
                renderer.release()
        cells = []
        for step, t in times.items():
            q1, q3 = np.percentile(t, [25, 75])
            median = statistics.median(t)
            cells.append(f"{step} {1e3 * median:.2f} ({100 * (q3 - q1) / median:.0f} %)")
        print(f"{name}: " + "; ".join(cells), flush=True)


if __name__ == "__main__":
    main()
