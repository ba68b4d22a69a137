"""Checking renders: the image-level twin (`reference`), the error band of an image (`tolerances`),
`verify`, the exact ray cast (`raycast`) and the shadow twin's (`shadows`), a 'points' program's
``shade_point()`` at given points (`points`) and the stability suite (`stability`).  The users' GLSL
unit-test toolkit, which runs on top of these, is `glphong.testing`.
"""
