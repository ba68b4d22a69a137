"""OpenGL: contexts on EGL and OSMesa (`contexts`), the EGL devices (`devices`, listed by `egl_devices`),
compiled programs with strict uniform binding and their cache (`programs`), textures (`textures`), the
renderer and its frames (`renderer`, `frame`), and `describe`, which lists what each program holds.
"""
from glphong.gpu.egl_devices import EGLDevice, devices

__all__ = ["EGLDevice", "devices"]
