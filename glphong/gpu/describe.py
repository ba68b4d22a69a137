"""Introspection: which programs a scene compiles, what each contains and what it leaves out."""
from dataclasses import dataclass

import numpy as np

from glphong.shaders.assembly import assemble, effective_source
from glphong.scene.culling import culling_decision
from glphong.shaders.numerics import allowed_pieces, numerics_decisions, with_numerics
from glphong.scene.scene import Scene
from glphong.shaders.generated import model_chunk_label
from glphong.shaders.binding import binding

__all__ = ["ProgramDescription", "describe", "format_descriptions"]


@dataclass(frozen=True)
class ProgramDescription:
    """One distinct program of a scene.

    Attributes
    ----------
    key : glphong.shaders.key.ProgramKey
    objects : tuple of str
        Names of the objects drawn with it.
    vertex_chunks, fragment_chunks : tuple of str
        Chunk files assembled, in order.
    defines : list of (str, str)
        The generated ``#define`` lines.
    left_out : list of str
        What the program does not contain.
    vertex_source, fragment_source : str
        The generated sources, as compiled.
    culling : tuple of str
        Per drawn object, whether its back faces are culled and why (`glphong.scene.culling`).
    numerics : tuple of str
        With ``numerics='auto'``: per drawn object and piece of arithmetic, whether it is specialised and why
        (`glphong.shaders.numerics`); empty otherwise.
    """

    key: object
    objects: tuple
    vertex_chunks: tuple
    fragment_chunks: tuple
    defines: list
    left_out: list
    vertex_source: str
    fragment_source: str
    culling: tuple = ()
    numerics: tuple = ()

    @property
    def effective_fragment_source(self):
        """The fragment source without inactive ``#if`` blocks and comments."""
        return effective_source(self.fragment_source)


def describe(scenes, renderer=None, gbuffer=False):
    """The distinct programs that rendering ``scenes`` compiles.

    Parameters
    ----------
    scenes : Scene or sequence of Scene
    renderer : glphong.Renderer, optional
        Describe the keys this renderer uses (its formulation, numerics and specialisation); by
        default those of a default renderer (specialised, stable formulation, ``numerics='auto'``).
    gbuffer : bool
        Include the G-buffer programs.

    Returns
    -------
    list of ProgramDescription
        In order of first use.
    """

    scenes = [scenes] if isinstance(scenes, Scene) else list(scenes)
    outputs = ("radiance", "gbuffer") if gbuffer else ("radiance",)

    users, absent, culling, numerics = {}, {}, {}, {}
    for scene in scenes:
        for obj in scene.objects:
            for output in outputs:
                key = renderer.program_key(scene, obj, output) if renderer else binding(scene).program_key(obj, output)
                auto = renderer is None or renderer.numerics == "auto"
                decisions = numerics_decisions(scene, obj, allowed_pieces(key)) if auto else ()
                if renderer is None:
                    key = with_numerics(key, scene, obj, decisions)
                users.setdefault(key, []).append(obj.name)
                if key.output in ("radiance", "display"):
                    numerics.setdefault(key, []).extend(
                        f"{obj.name}: {d.piece}: {'specialised' if d.specialised else 'stable'} ({d.reason})"
                        for d in decisions)
                decision = "drawn: culling='off'" if renderer is not None and renderer.culling == "off" else \
                    culling_decision(obj, scene.camera)[1]
                culling.setdefault(key, []).append(f"{obj.name}: {decision}")
                present = {t.name for t in key.terms}
                for term in obj.material.components:
                    if term.name not in present and output != "gbuffer":
                        zero = [p for p in term.vanishes_with if not np.any(getattr(term, p))]
                        reason = ((", ".join(f"{p} = 0" for p in zero) or "every scale parameter is 0") if term.vanishes()
                                  else "no light reaches it and it does not answer L_a")
                        absent.setdefault(key, {}).setdefault(type(term), reason)
    out = []
    for key, names in users.items():
        defines, generated = key.defines(), key.generated_chunks()
        fragment = assemble(key.fragment_chunks(), defines, generated) if key.fragment_chunks() else ""
        out.append(ProgramDescription(key, tuple(dict.fromkeys(names)), key.vertex_chunks(), key.fragment_chunks(),
                                      defines, key.left_out(list(absent.get(key, {}).items())),
                                      assemble(key.vertex_chunks(), defines, generated), fragment,
                                      tuple(culling[key]), tuple(numerics.get(key, ()))))
    return out


def _term_lines(key):
    """One line per term of ``key``: the model, where its GLSL comes from, the library chunks it calls and its
    structural defines."""

    out = []
    for t in key.terms:
        extra = [f"calls {', '.join(c + '.glsl' for c in t.uses)}"] if t.uses else []
        extra += [f"{t.name.upper()}_{n}={v}" for n, v in t.defines]
        out.append(f"{t.name}: {model_chunk_label(t.name)} ({t.chunk})" + (f"; {'; '.join(extra)}" if extra else ""))
    return out


def format_descriptions(descriptions, source=False):
    """Readable text of `describe`'s result; ``source=True`` adds each effective fragment source."""
    lines = [f"{len(descriptions)} distinct program(s)"]
    for i, d in enumerate(descriptions, 1):
        users = ", ".join(d.objects[:6]) + (f" and {len(d.objects) - 6} more" if len(d.objects) > 6 else "")
        lines += [f"\n[{i}] {d.key.describe()}", f"    drawn objects: {users}",
                  f"    vertex chunks:   {' '.join(d.vertex_chunks)}",
                  f"    fragment chunks: {' '.join(d.fragment_chunks)}",
                  "    defines:         " + " ".join(f"{n}={v}" for n, v in d.defines)]
        if d.key.terms:
            lines.append("    model chunks:")
            lines += [f"      - {line}" for line in _term_lines(d.key)]
        lines += [
                  "    left out:"]
        lines += [f"      - {item}" for item in d.left_out]
        if d.culling:
            lines.append("    back faces:")
            lines += [f"      - {item}" for item in d.culling[:6]]
            lines += [f"      - and {len(d.culling) - 6} more objects" for _ in (1,) if len(d.culling) > 6]
        if d.numerics:
            lines.append("    numerics (auto):")
            lines += [f"      - {item}" for item in d.numerics[:15]]
            lines += [f"      - and {len(d.numerics) - 15} more" for _ in (1,) if len(d.numerics) > 15]
        if source and d.fragment_source:
            lines.append("    effective fragment source:")
            lines += [f"      | {line}" for line in d.effective_fragment_source.splitlines()]
    return "\n".join(lines)
