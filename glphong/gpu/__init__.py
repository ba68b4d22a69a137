"""OpenGL: contexts on EGL and OSMesa (`contexts`), compiled programs with strict uniform binding and
their cache (`programs`), textures (`textures`), the renderer and its frames (`renderer`, `frame`),
and `describe`, which lists what each program holds.
"""
