"""A 'points' program's GLSL ``shade_point()`` at arbitrary points, one point per vertex, captured by transform
feedback: glphong's own shader evaluated where a test chooses, without rasterising (`shade_points`).  The stability
suite (`glphong.checks.stability`) and `glphong.testing.assert_light_matches` run the shader through it.
"""
import moderngl
import numpy as np

__all__ = ["shade_points"]


def shade_points(gl, programs, key, uniforms, positions, normals, drop_unused=False, tangents=None, uvs=None):
    """Evaluate the GLSL ``shade_point()`` of a 'points' program at arbitrary points.

    Parameters
    ----------
    gl : glphong.gpu.contexts.GLContext
    programs : glphong.gpu.programs.ProgramCache
        Cache of ``gl``'s programs.
    key : glphong.shaders.key.ProgramKey
        With ``output='points'``.
    uniforms : dict of str to array_like
        Exactly the program's active uniforms (strict binding).
    positions, normals : (N, 3) array_like
        World-space points [m] and raw (unnormalised) normals; cast to float32.
    drop_unused : bool
        Drop given uniforms the compiler removed instead of raising (for the naive
        formulation, whose ``safe_normalize`` never fails, so that e.g. a Lambert program
        never reads ``u_eye``); missing uniforms are still an error.
    tangents : (N, 4) array_like, optional
        Raw tangents with handedness in w, where the key reads them (default (1, 0, 0, 1)).
    uvs : (N, 2) array_like, optional
        Texture coordinates, where the key reads them (default 0).

    Returns
    -------
    (N, 3) float32 ndarray
        Radiance [W/(m^2 sr)].
    """
    if key.output != "points":
        raise ValueError(f"key.output must be 'points' (got {key.output!r})")
    positions = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1, 3)
    normals = np.ascontiguousarray(normals, dtype=np.float32).reshape(-1, 3)
    if positions.shape != normals.shape:
        raise ValueError(f"positions and normals must have the same shape (got {positions.shape} and {normals.shape})")
    count = len(positions)
    columns = {"in_position": (positions, "3f"), "in_normal": (normals, "3f")}
    if key.has_tangent:
        tangents = np.broadcast_to((1.0, 0.0, 0.0, 1.0) if tangents is None else tangents, (count, 4))
        columns["in_tangent"] = (np.ascontiguousarray(tangents, dtype=np.float32), "4f")
    if key.has_uv:
        uvs = np.broadcast_to(0.0 if uvs is None else uvs, (count, 2))
        columns["in_uv"] = (np.ascontiguousarray(uvs, dtype=np.float32), "2f")
    mgl = gl.mgl
    with gl:
        program = programs.get(key)
        program.bind(uniforms, drop_unused=drop_unused)
        buffers = {name: mgl.buffer(data.tobytes()) for name, (data, _) in columns.items()}
        result = mgl.buffer(reserve=max(count, 1) * 12)
        content = [(buffers[name], fmt, name) for name, (_, fmt) in columns.items()
                   if name in program.gl_program]  # the normal is compiled out of unlit programs
        vao = mgl.vertex_array(program.gl_program, content)
        try:
            gl.bind_idle_framebuffer()
            vao.transform(result, mode=moderngl.POINTS, vertices=count)
            data = np.frombuffer(result.read(), dtype=np.float32)[:count * 3].reshape(count, 3).copy()
            gl.check_error(f"shade_points of {key.describe()}")
        finally:
            for obj in (vao, result, *buffers.values()):
                obj.release()
    return data
