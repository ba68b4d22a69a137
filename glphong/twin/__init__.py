"""The numpy float64 twin's function library and the error band of single functions.

`functions` mirrors the GLSL library chunks (common, lights, lobe, fresnel) function by function, with
the same names, argument order and formulation; `band` holds the band constants and the band of a
cosine-power lobe.  Material models are built on these; nothing here knows a material, a scene or a
context.
"""
