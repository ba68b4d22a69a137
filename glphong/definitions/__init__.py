"""The definition mechanism (docs/design.md sections 8 and 11): what a material model and a light kind are made of.

A definition is a class with a name, parameters (`params.Param`), GLSL, a numpy twin, a band, an oracle and stability
cases (`cases.Case`), checked when its class is created and registered by name (`definition.Definition`,
`registry.Registry`, `checks`, `source`).  Two sorts are built on it: material models (`material.MaterialModel`,
`material_checks`; their surface inputs `surface`, tables `table`, Fresnel slots `fresnel`, JSON form `as_json`) and
light kinds (`light.LightModel`, `light_checks`).  The built-in models live in `glphong.materials` and the built-in
kinds in `glphong.lights`, one module each, defined exactly as a user's are.
"""
