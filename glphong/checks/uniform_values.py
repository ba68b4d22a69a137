"""A program's uniforms that keep the parameter values read from them (issue 40, docs/speed.md "Verify against the
render"): `glphong.checks.verify.twin_and_band` shades an object's pixels in chunks, and a term's or a light's
`ParamValues` do not depend on the pixels, only its per-fragment surface inputs do."""
import numpy as np

__all__ = ["UniformValues", "values_from"]


class UniformValues(dict):
    """A program's uniforms (name to ndarray, as `glphong.checks.reference.shade_inputs` yields them) with ``kept``:
    the `ParamValues` `values_from` has read from them, by owner and arguments."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.kept = {}


def values_from(owner, uniforms, *args, **kwargs):
    """``owner.values_from_uniforms(uniforms, *args, **kwargs)`` (a material term's or a light kind's `ParamValues`),
    computed once per owner and arguments where ``uniforms`` is a `UniformValues` and no per-fragment ``inputs`` are
    given; computed on every call otherwise."""
    cache = uniforms.kept if isinstance(uniforms, UniformValues) else None
    if cache is None or kwargs.get("inputs"):
        return owner.values_from_uniforms(uniforms, *args, **kwargs)
    name = (id(owner), args, np.dtype(kwargs.get("dtype", np.float64)), kwargs.get("inputs") is not None,
            tuple((k, v) for k, v in sorted(kwargs.items()) if k not in ("dtype", "inputs")))
    if name not in cache:  # the owner kept with its values: its id names no other object while the cache lives
        cache[name] = owner, owner.values_from_uniforms(uniforms, *args, **kwargs)
    return cache[name][1]
