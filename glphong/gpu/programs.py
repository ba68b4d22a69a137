"""GLSL programs: compilation, strict uniform binding and caching.

A program's source is generated from its `ProgramKey` alone (`glphong.shaders.assembly.assemble`: a
``#version`` line, the key's ``#define`` lines, then the key's chunks, each preceded by a ``#line``
marker numbered so that a compile error names the chunk file and line, `name_chunks`).
"""
import re
import time

import moderngl
import numpy as np

from glphong.shaders.assembly import assemble, name_chunks
from glphong.shaders.generated import terms_behind, transmits
from glphong.gpu.shadows import ShadowMap
from glphong.gpu.textures import TextureStore
from glphong.lights import light_for_key
from glphong.definitions.registry import model_for_key
from glphong.definitions.surface import TextureImage
from glphong.definitions.table import TableData

__all__ = ["ProgramCache", "Program", "ShaderCompileError", "UniformError"]


class ShaderCompileError(RuntimeError):
    """A generated program failed to compile or link; the message names chunk files and lines."""


class UniformError(ValueError):
    """Uniform values do not match what a program declares (missing, unknown or wrong size)."""


class Program:
    """One compiled program and its strict uniform binding.

    Parameters
    ----------
    mgl : moderngl.Context
    key : glphong.shaders.key.ProgramKey
    textures : glphong.gpu.textures.TextureStore, optional
        Where the textures of `TableData` uniform values are uploaded (the cache's store).
    """

    def __init__(self, mgl, key, textures=None):
        self.key = key
        self.textures = textures
        defines, generated = key.defines(), key.generated_chunks()
        self.vertex_source = assemble(key.vertex_chunks(), defines, generated)
        self.fragment_source = assemble(key.fragment_chunks(), defines, generated, key.extensions()) \
            if key.fragment_chunks() else None
        try:
            self.gl_program = mgl.program(vertex_shader=self.vertex_source, fragment_shader=self.fragment_source,
                                          varyings=key.varyings())
        except moderngl.Error as exc:
            stage = key.fragment_chunks() if "fragment" in str(exc).lower() else key.vertex_chunks()
            log = name_chunks(str(exc), stage, generated)
            raise ShaderCompileError(f"program {key.describe()!r} failed to build:\n{log}") from None
        self.active = {name: self.gl_program[name] for name in self.gl_program if isinstance(self.gl_program[name], moderngl.Uniform)}
        # a model's uniforms are declared from its params; one its GLSL does not read for this key (a
        # structural define left it out) is not active, and a value given for it is not an error

        self.optional = {model_for_key(t.name, t.source_hash).uniform_name(p.name)
                         for t in getattr(key, "terms", ()) for p in model_for_key(t.name, t.source_hash).uniform_params()}
        # an extended light's uniforms that only its sampled method reads are not active where every term has a
        # closed form (docs/design.md section 13)
        self.optional |= {light_for_key(k.name, k.source_hash).uniform_name(p.name) for k in getattr(key, "lights", ())
                          if k.extended for p in light_for_key(k.name, k.source_hash).uniform_params()}
        # with the textbook view vector (numerics='auto'), a term that declares the view but never reads it leaves the
        # eye unread: the stable form's validity no longer gates the lights
        self.optional |= {"u_eye"} if "view" in getattr(key, "numerics", ()) else set()
        # the transmission pass's background (glphong.gpu.transmission), given to every program that pass draws: only
        # one that `transmits` declares it (glsl/transmission_thin.glsl), not KHR_materials_diffuse_transmission's alone
        if terms_behind(getattr(key, "terms", ())) and not transmits(key):  # what the terms' models declare
            self.optional |= {"u_transmission_background", "u_transmission_levels"}
        #: the bytes last written to each uniform (`write` skips unchanged ones)
        self._written = {}
        #: sampler uniforms in texture-unit order
        self.samplers = tuple(name for name, u in self.active.items() if u.fmt.endswith("i") and "sampler" in
                              _uniform_type(self.vertex_source, self.fragment_source, name))

    def bind(self, values, drop_unused=False):
        """Set every active uniform from ``values``; anything else is an error.

        Parameters
        ----------
        values : dict of str to array_like
            float32 data per uniform name: shape ``()``, ``(k,)``, ``(k, k)`` (row-major
            matrices, transposed here to GL's column-major) or ``(N, 3)`` for arrays; for a
            sampler, a `glphong.materials.TableData` (its texture is uploaded once per context
            and bound to the sampler's unit) or a texture unit the caller bound.
        drop_unused : bool
            Ignore given uniforms that are not active instead of raising: only for the
            naive formulation, whose never-failing ``safe_normalize`` lets the compiler
            remove inputs the stable program reads (e.g. ``u_eye`` of a Lambert program).

        Raises
        ------
        UniformError
            An active uniform is missing, a given name is not an active uniform of the
            program (the key leaves out every uniform it does not use), or the data size
            does not match.
        """
        pack = self.pack(values, drop_unused)
        self.check_complete(pack)
        self.write(pack)

    def pack(self, values, drop_unused=False):
        """``values`` (some of the active uniforms, as in `bind`) checked and packed for `write`.

        Returns
        -------
        tuple of (name, moderngl.Uniform, bytes or TableData)
            The bytes GL receives (matrices transposed), or a table for a sampler.

        Raises
        ------
        UniformError
            A name that is not an active uniform (unless ``drop_unused``, or a model uniform a
            structural define compiled out), or a size that does not match.
        """

        unknown = sorted(n for n in values if n not in self.active and not drop_unused and n not in self.optional)
        if unknown:
            missing = sorted(set(self.active) - set(values))
            raise UniformError(f"program {self.key.describe()!r}: missing uniforms {missing}, unknown uniforms {unknown}")
        out = []
        for name, value in values.items():
            uniform = self.active.get(name)
            if uniform is None:
                continue
            if isinstance(value, (TableData, TextureImage, ShadowMap)):
                if name not in self.samplers or self.textures is None:
                    raise UniformError(f"uniform {name} of program {self.key.describe()!r} is not a sampler of a "
                                       "program with a texture store: it cannot take a table")
                out.append((name, uniform, value))
                continue
            # float uniforms take float32; samplers and int uniforms ('1i' formats) take int32
            data = np.asarray(value, dtype=np.int32 if uniform.fmt.endswith("i") else np.float32)
            if data.ndim == 2 and data.shape[0] == data.shape[1] and uniform.dimension == data.size:
                data = data.T
            expected = uniform.array_length * uniform.dimension
            if data.size != expected:
                raise UniformError(f"uniform {name} of program {self.key.describe()!r} takes {expected} floats (got shape {data.shape})")
            out.append((name, uniform, np.ascontiguousarray(data).tobytes()))
        return tuple(out)

    def check_complete(self, *packs):
        """Raise `UniformError` unless ``packs`` together set every active uniform (each once at most)."""
        names = [name for pack in packs for name, _, _ in pack]
        missing = sorted(set(self.active) - set(names))
        if missing or len(names) != len(set(names)):
            repeated = sorted({n for n in names if names.count(n) > 1})
            raise UniformError(f"program {self.key.describe()!r}: missing uniforms {missing}"
                               f"{', given twice ' + str(repeated) if repeated else ''}, unknown uniforms []")

    def write(self, pack):
        """Write a `pack` to GL, skipping uniforms whose bytes this program already holds (GL keeps a
        program's uniform values); a table's texture is bound to its sampler's unit every time (other
        programs use the units too)."""
        last = self._written
        for name, uniform, data in pack:
            if not isinstance(data, bytes):  # a table, or a texture drawn this frame (a shadow map)
                unit = self.samplers.index(name)
                if isinstance(data, ShadowMap):
                    data.use(unit)
                else:
                    self.textures.bind(data, unit)
                data = np.int32(unit).tobytes()
            if last.get(name) != data:
                uniform.write(data)
                last[name] = data

    def release(self):
        """Release the GL program."""
        self.gl_program.release()


def _uniform_type(vertex_source, fragment_source, name):
    """The declared GLSL type of uniform ``name`` in a program's sources ('' where not found)."""
    for source in (vertex_source, fragment_source or ""):
        m = re.search(rf"^\s*uniform\s+(\w+)\s+{re.escape(name)}\s*[;\[]", source, re.M)
        if m:
            return m.group(1)
    return ""


class ProgramCache:
    """Programs of one GL context, compiled once per `ProgramKey`, and the textures they sample.

    Attributes
    ----------
    textures : glphong.gpu.textures.TextureStore
        The tables the programs' samplers have read, uploaded once each.
    hits, misses : int
        Cache statistics since creation.
    compile_seconds : float
        Total wall time spent compiling and linking.
    """

    def __init__(self, mgl):
        self._mgl = mgl
        self._programs = {}
        self.textures = TextureStore(mgl)
        self.hits = 0
        self.misses = 0
        self.compile_seconds = 0.0

    def get(self, key):
        """The program for ``key``, compiled on first use."""
        program = self._programs.get(key)
        if program is not None:
            self.hits += 1
            return program
        self.misses += 1
        start = time.perf_counter()
        program = self._programs[key] = Program(self._mgl, key, self.textures)
        self.compile_seconds += time.perf_counter() - start
        return program

    def keys(self):
        """Keys of the compiled programs."""
        return tuple(self._programs)

    def __len__(self):
        return len(self._programs)

    def release(self):
        """Release every program and texture."""
        for program in self._programs.values():
            program.release()
        self._programs.clear()
        self.textures.release()
