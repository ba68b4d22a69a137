"""The generic band of a light kind's irradiance (`LightModel.band`): its first-order sensitivity to float32 rounding
of its inputs (docs/design.md section 4)."""
import numpy as np

from glphong.definitions.params import ParamValues
from glphong.twin.band import EPS
from glphong.twin.functions import perpendiculars

__all__ = ["sensitivity_band"]


def sensitivity_band(evaluate, x, p, params, constants, directions=(), rows=1 << 16, factors=(), offset=None,
                     one_sided=False, base=None):
    """The generic band: ``evaluate(x, p, *directions)`` (N, 3) and its first-order sensitivity to its inputs, each
    perturbed by a few ulps as float32 arithmetic perturbs them, added worst-case (`LightModel.band`).

    ``x`` (N, 3) and every 'vec3' uniform of ``params`` are scaled componentwise by ``1 +- D eps`` (each entry of a
    uniform with several per light), every 'direction' uniform and each of ``directions`` ((N, 3) unit vectors: a
    normal, a reflected view) rotated by ``D eps`` about two axes, every scalar and rgb uniform scaled by
    ``1 +- A eps``.  The moves of ``x`` and of the directions are stacked along the rows, up to ``rows`` rows to a
    call of ``evaluate`` (a twin is row by row, so the values are the same as one call per move, and a light with
    a normal and a reflected view costs one call for those 14 moves); the uniforms' moves, which the rows share, take
    a call each.  Returns ``(low, high)``, each (N, 3).

    Shortcuts where the twin's form allows them (the area lights': docs/speed.md, "Verify against the render"):
    ``factors`` names uniforms the result is proportional to (a radiance): their moves scale the result by ``1 +- A
    eps`` without a call.  ``offset`` names a 'vec3' uniform ``c`` the twin reads only through ``c - x`` (a
    light's centre): ``x`` then moves by ``D eps (|x_i| + |c_i|)`` along each axis, the float32 difference's error
    from both, and ``c`` does not move on its own (each of its moves is one of ``x``'s, shorter).  ``one_sided``: a
    twin continuous in its inputs and smooth wherever its value is not 0 (an integral of a non-negative integrand
    that vanishes where the domain is clipped) moves by ``-delta`` to first order where a move the other way moves
    it by ``delta``: each move is made one way only and its ``|delta|`` taken both ways, except on the rows where
    the value may reach 0 within a move (a channel at 0, or one that a move changed by more than 1 % of itself: a
    light seen edge-on, a polygon on the horizon), where both ways are made.  ``base``: ``evaluate(x, p,
    *directions)`` where the caller has it already (not evaluated again).
    """
    base = np.asarray(evaluate(x, p, *directions) if base is None else base, dtype=np.float64)
    up, down = np.zeros_like(base), np.zeros_like(base)
    d = constants.D * EPS
    reach = None if offset is None else np.abs(np.asarray(getattr(p, offset), dtype=np.float64))

    def spread(values, rows_):
        with np.errstate(all="ignore"):
            delta = np.nan_to_num(values - base[rows_], nan=0.0)
        high, low = (delta, delta) if not one_sided else (np.abs(delta), -np.abs(delta))
        if isinstance(rows_, slice):  # every row: in place
            np.maximum(up, high, out=up)
            np.minimum(down, low, out=down)
        else:
            up[rows_], down[rows_] = np.maximum(up[rows_], high), np.minimum(down[rows_], low)

    def moves(signs, rows_):
        """Every move of the given signs on the rows ``rows_`` (an index array or ``slice(None)``)."""
        x_, dirs = np.asarray(x, dtype=np.float64)[rows_], tuple(v[rows_] for v in directions)
        own = []  # (x, directions) of each move of the rows' own inputs
        for axis in range(3):
            for sign in signs:
                moved = np.array(x_)
                if reach is None:
                    moved[:, axis] *= 1.0 + sign * d
                else:
                    moved[:, axis] += sign * d * (np.abs(moved[:, axis]) + reach[axis])
                own.append((moved, dirs))
        for i, v in enumerate(dirs):
            for axis in perpendiculars(v):
                for s in signs:
                    turned = v + s * d * axis
                    turned = turned / np.linalg.norm(turned, axis=-1, keepdims=True)
                    own.append((x_, dirs[:i] + (turned,) + dirs[i + 1:]))
        group = max(1, rows // max(len(x_), 1))
        for start in range(0, len(own), group):
            chunk = own[start:start + group]
            stacked = [np.concatenate([m[0] for m in chunk])] + \
                [np.concatenate([m[1][j] for m in chunk]) for j in range(len(dirs))]
            with np.errstate(all="ignore"):
                values = np.asarray(evaluate(stacked[0], p, *stacked[1:]), dtype=np.float64)
            for value in values.reshape((len(chunk), len(x_)) + base.shape[1:]):
                spread(value, rows_)
        for param in params:
            if param.name == offset:
                continue
            if param.name in factors:
                for s in signs:
                    spread(base[rows_] * (1.0 + s * constants.A * EPS), rows_)
                continue
            value = np.asarray(getattr(p, param.name), dtype=np.float64)
            variants = []
            if param.kind == "vec3":
                for index in np.ndindex(value.shape):
                    for s in signs:
                        moved = value.copy()
                        moved[index] *= 1.0 + s * d
                        variants.append(moved)
            elif param.kind == "direction":
                variants = [(value + s * d * axis) / np.linalg.norm(value + s * d * axis)
                            for axis in perpendiculars(value) for s in signs]
            else:
                variants = [value * (1.0 + s * constants.A * EPS) for s in signs]
            for v in variants:
                with np.errstate(all="ignore"):
                    spread(np.asarray(evaluate(x_, ParamValues({**p.__dict__, param.name: v}), *dirs),
                                      dtype=np.float64), rows_)

    moves((1.0,) if one_sided else (1.0, -1.0), slice(None))
    if one_sided:  # both ways where the value may be held at 0 within a move: 0, or moved by 1 % of itself
        with np.errstate(invalid="ignore"):
            held = np.nonzero(np.any((base == 0.0) | (up > 1e-2 * np.abs(base)), axis=-1))[0]
        if len(held):
            moves((-1.0,), held)
    return base + down, base + up
