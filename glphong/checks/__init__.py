"""Checking renders: the image-level twin (`reference`), the error band of an image (`tolerances`),
`verify`, the exact ray cast (`raycast`), the GLSL function probe (`probe`) and the stability suite
(`stability`).
"""
