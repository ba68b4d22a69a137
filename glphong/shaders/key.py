"""Program keys, in one import: the key types, their vocabulary and their builders (docs/design.md sections 5 and 8).

Each job has its own module; this one gathers their public names for the code and the users that read keys:

- `glphong.shaders.keys`: `ProgramKey`, `TermKey`, `LightKey`, `EncodeKey` (what a program contains);
- `glphong.shaders.options`: the outputs, formulations, numerics pieces and their defines, G-buffer planes, limits;
- `glphong.shaders.builders`: `program_key`, `light_keys`, `term_keys`, `gbuffer_key`, `uber_key`, `response_key`,
  `shadow_key`, `lod_slots`;
- `glphong.shaders.defines`: the ``#define`` lines; `glphong.shaders.stages`: each kind of program's chunks in
  order; `glphong.shaders.prose`: what `glphong describe` says of a key.
"""
from glphong.shaders.builders import (gbuffer_key, light_keys, lod_slots, program_key, response_key, shadow_key,
                                      term_keys, uber_key)
from glphong.shaders.generated import material_chunk, model_chunk_label
from glphong.shaders.keys import EncodeKey, LightKey, ProgramKey, TermKey
from glphong.shaders.options import (FORMULATIONS, GBUFFER_PLANES, INPUT_MODES, MAX_TEXTURED_INPUTS, NUMERICS_DEFINES,
                                     NUMERICS_PIECES, OUTPUTS, SHADOW_PASSES, UBER_MAX_LIGHTS)

__all__ = ["ProgramKey", "TermKey", "LightKey", "EncodeKey", "program_key", "gbuffer_key", "uber_key", "response_key",
           "light_keys", "term_keys", "shadow_key", "lod_slots", "UBER_MAX_LIGHTS", "material_chunk",
           "model_chunk_label", "OUTPUTS", "SHADOW_PASSES", "FORMULATIONS", "NUMERICS_DEFINES", "NUMERICS_PIECES",
           "GBUFFER_PLANES", "INPUT_MODES", "MAX_TEXTURED_INPUTS"]
