"""Shader sources as text: the program key (`key`: the cache key and the source of the ``#define``s),
the chunks generated from a key (`generated`), and program assembly and the preprocessor (`assembly`).
No OpenGL here: `glphong.gpu` compiles what this package writes.
"""
