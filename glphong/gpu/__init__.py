"""OpenGL: contexts on EGL and OSMesa (`contexts`), the EGL devices (`devices`, listed by `egl_devices`), what GL objects glphong holds (`gl_objects_alive`),
compiled programs with strict uniform binding and their cache (`programs`), textures (`textures`), the
renderer and its frames (`renderer`, `frame`), and `describe`, which lists what each program holds.
"""
from glphong.gpu.counters import GLCounts, gl_objects_alive
from glphong.gpu.egl_devices import EGLDevice, devices

__all__ = ["EGLDevice", "devices", "GLCounts", "gl_objects_alive"]
