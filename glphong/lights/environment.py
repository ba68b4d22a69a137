"""The environment light: radiance ``L_i(w)`` from an equirectangular map (docs/design.md section 13; GLSL:
``glsl/lights/environment.glsl``; twin: `glphong.twin.environment`).

Each texel is a constant radiance over its exact solid angle; row 0 is the map's zenith +z, column 0 starts at its
+x and the azimuth runs toward +y (`glphong.twin.environment`), and ``rotation`` turns the map into the world
(``w_world = rotation @ w_map``; a y-up world's sky is ``rotation=glphong.lights.environment.Y_UP``).

The lecture's continuous version for it, three ways:

- Lambert (``k_d E(n)``): an irradiance cube map of ``resolution^2`` texels per face, each the map's exact irradiance
  at the texel's direction (the per-texel integrals of `glphong.twin.environment.irradiance`), blended bilinearly;
  or, with ``irradiance='sh'``, the spherical harmonics up to ``order`` convolved with the clamped cosine (order 2:
  Ramamoorthi and Hanrahan).
- The lecture's Phong lobe (``k_s max(r_v.w, 0)^q``): the spherical harmonics up to ``order`` convolved with the lobe
  (Funk-Hecke, the zonal weights ``2 pi c_l(q)`` in closed form, any ``q``), times the part of the lobe above the
  surface's horizon under a uniform sky (exact where the radiance is uniform across the horizon).
- Every other term: the map averaged onto ``samples x 2 samples`` texels, each a direction (its moment's) and an
  irradiance.

A small bright source (a sun) is taken out first (`glphong.twin.environment_bright`): the map is split exactly as
``min(L, T) + max(L - T, 0)`` at a ``threshold`` ``T`` (default automatic: 8 times the median radiance, raised so that
the texels above it cover at most 0.25 sr); the residual takes the ways above, the excess is cut into at most
``bright`` blocks, each integrated apart: Lambert by its exact moment where it is wholly above the horizon (a disc of
its solid angle where the horizon crosses it), the Phong lobe by the midpoint rule over the blocks.  A map with no
texel above ``T`` renders as before, and its programs carry no block.

`glphong.verify` shows each method's error against the exact integral (`exact`: adaptive quadrature over the map's
texels, `glphong.twin.environment_quadrature`) apart from the float32 band of the GPU against the twin.
"""
import hashlib
from pathlib import Path

import numpy as np

from glphong.core.filesafety import LIMITS, SceneFileError, read_bytes
from glphong.core.rgbe import read_hdr
from glphong.lights.extended import ExtendedLight, extended_cases
from glphong.definitions.light import GlslFile, Param
from glphong.materials.lambert import Lambert
from glphong.twin import environment as env
from glphong.twin import environment_bright as bright_blocks
from glphong.twin.band import EPS
from glphong.twin.environment_quadrature import environment_integral
from glphong.twin.environment_lobe import lobe_integral

__all__ = ["EnvironmentLight", "read_radiance_map", "Y_UP"]

#: ``rotation`` for a y-up world: the map's zenith (+z) to +y, its +x to +z
Y_UP = ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
#: the largest ``samples`` (2 samples^2 texels, two vec3 uniforms each)
MAX_SAMPLE_ROWS = 16

RESOLUTION = Param("resolution", "scalar", low=2.0, high=24.0, default=9.0,
                   doc="texels per side of each face of the irradiance cube map (an integer; odd puts a texel centre on "
                       "each axis)")
ORDER = Param("order", "scalar", low=0.0, high=24.0, default=4.0,
              doc="order of the spherical harmonics of the Phong lobe (and of the irradiance with irradiance='sh')")
ENV_SAMPLES = Param("samples", "scalar", low=1.0, high=float(MAX_SAMPLE_ROWS), default=4.0,
                    doc="rows of the averaged map whose 2 samples^2 texels carry the terms without a closed form")
#: the largest ``bright`` (seven vec4 uniform slots a block)
MAX_BRIGHT = 128
BRIGHT = Param("bright", "scalar", low=0.0, high=float(MAX_BRIGHT), default=32.0,
               doc="the most blocks the map's excess over threshold is cut into, integrated apart (0: none)")
THRESHOLD = Param("threshold", "scalar", low=0.0, optional=True, unit="W/(m^2 sr)",
                  doc="radiance above which a texel's excess is integrated apart (None: automatic)")

_UNIFORMS = (
    Param("irradiance", "rgb", low=0.0, unit="W/m^2", doc="the irradiance cube map, 6 R^2 texels"),
    Param("resolution", "scalar", low=2.0, doc="R"),
    Param("sh", "rgb", low=-float("inf"), unit="W/(m^2 sr)", doc="spherical-harmonic coefficients, index l^2 + l + m"),
    Param("frame", "vec3", low=-float("inf"), doc="rows of the world-to-map rotation"),
    Param("samples", "scalar", low=1.0, doc="rows s of the averaged map"),
    Param("sample_direction", "vec3", low=-float("inf"), doc="each averaged texel's direction (world)"),
    Param("sample_irradiance", "rgb", low=0.0, unit="W/m^2", doc="each averaged texel's Lbar |M|"),
    Param("bright_count", "scalar", low=0.0, doc="the light's bright blocks"),
    Param("bright_direction", "vec3", low=-float("inf"), doc="each block's centroid (world)"),
    Param("bright_radius", "scalar", low=0.0, unit="rad", doc="each block's disc radius sqrt(Omega/pi)"),
    Param("bright_moment", "vec3", low=-float("inf"), unit="W/m^2", doc="each block's moment per channel (3 a block)"),
    Param("bright_length", "rgb", low=0.0, unit="W/m^2", doc="each block's |moment| per channel"),
    Param("bright_power", "rgb", low=0.0, unit="W/m^2", doc="each block's power per channel"),
    Param("bright_total", "vec3", low=-float("inf"), unit="W/m^2", doc="the blocks' moments summed, per channel"),
    Param("bright_center", "vec3", low=-float("inf"), doc="the centre of the blocks' cap (world)"),
    Param("bright_cap", "vec3", low=-float("inf"), doc="(cos rho, sin rho, rho) of the blocks' cap"),
)


def read_radiance_map(path, limits=None):
    """A radiance map from a file, (H, W, 3) float64 [W/(m^2 sr)]: a Radiance ``.hdr`` (glphong's reader,
    `glphong.core.rgbe`, its ``EXPOSURE`` divided out) or an OpenEXR ``.exr`` (the optional extra ``exr``)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".hdr", ".pic", ".rgbe"):
        image = read_hdr(path, limits=limits)
        return image.pixels.astype(np.float64) / image.exposure
    if suffix == ".exr":
        try:
            import OpenEXR  # noqa: PLC0415 - the optional extra
        except ImportError:
            raise ImportError(f"{path}: reading OpenEXR needs the optional extra 'exr' (pip install 'glphong[exr]', "
                              "which installs OpenEXR)") from None
        return _read_exr(OpenEXR, path, limits or LIMITS)
    raise ValueError(f"{path}: a radiance map is a .hdr (Radiance RGBE) or .exr (OpenEXR) file, or a float array")


def _read_exr(OpenEXR, path, limits):
    """An OpenEXR file's R, G, B as (H, W, 3) float64: a regular file within ``limits.file_bytes`` (`read_bytes`), its
    data window within ``limits.image_pixels`` read from the header before the pixels; a SceneFileError otherwise."""
    read_bytes(path, limits)  # a regular file of bounded size, or SceneFileError
    try:
        with OpenEXR.File(str(path), header_only=True) as exr:
            low, high = exr.header()["dataWindow"]
        pixels = (int(high[0]) - int(low[0]) + 1) * (int(high[1]) - int(low[1]) + 1)
        if pixels > limits.image_pixels or pixels <= 0:
            raise SceneFileError(path, f"header: data window of {pixels} pixels, beyond the limit of "
                                 f"{limits.image_pixels} (glphong.filesafety.Limits.image_pixels)")
        with OpenEXR.File(str(path)) as exr:
            channels = exr.channels()
            if "RGB" in channels or "RGBA" in channels:
                data = np.asarray(channels["RGB" if "RGB" in channels else "RGBA"].pixels, dtype=np.float64)[..., :3]
            elif all(c in channels for c in "RGB"):
                data = np.stack([np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)
            else:
                raise SceneFileError(path, f"channels {sorted(channels)}: expected R, G and B")
    except SceneFileError:
        raise
    except Exception as exc:  # the library's own errors on a malformed file
        raise SceneFileError(path, f"not a readable OpenEXR file ({type(exc).__name__}: {exc})") from None
    return data


def _rotation(value):
    if value is None:
        return np.eye(3)
    r = np.asarray(value, dtype=np.float64)
    if r.shape != (3, 3) or not np.all(np.isfinite(r)):
        raise ValueError(f"rotation must be a finite 3 x 3 matrix (got shape {r.shape})")
    if np.max(np.abs(r.T @ r - np.eye(3))) > 1e-6 or np.linalg.det(r) <= 0:
        raise ValueError("rotation must be a proper rotation (orthonormal columns, determinant +1, to 1e-6)")
    return r


class EnvironmentLight(ExtendedLight):
    """Radiance from an equirectangular map, each texel constant over its exact solid angle (module docstring).

    ``L_r(wo) = integral f_r(wi, wo) L_i(wi) (n.wi)^+ dwi`` over the sphere: Lambert by the irradiance
    ``E(n) = integral L_i(w) (n.w)^+ dw`` (an irradiance cube map of exact per-texel integrals, or the spherical
    harmonics convolved with the clamped cosine); the lecture's Phong lobe by the spherical harmonics convolved with
    the lobe; every other term over the map averaged onto ``samples x 2 samples`` texels.

    Parameters
    ----------
    image : (H, W) or (H, W, 3) array_like, or path-like
        Radiance [W/(m^2 sr)] per texel (finite, >= 0), or a ``.hdr`` / ``.exr`` file (`read_radiance_map`).
    rotation : (3, 3) array_like, optional
        Map to world, ``w_world = rotation @ w_map`` (default the identity: the map's zenith is +z).
    scale : float
        Multiplies the radiance.
    resolution : int
        Texels per side of the irradiance cube map's faces, 2 to 24 (default 9).
    order : int
        Order of the spherical harmonics, 0 to 24 (default 4).
    samples : int
        Rows of the averaged map for the other terms, 1 to 16 (default 4: 32 directions).
    irradiance : {'map', 'sh'}
        Lambert by the irradiance cube map (default) or by the spherical harmonics.
    method : {'auto', 'sampled'}
        As every extended light (`glphong.lights.ExtendedLight`).
    bright : int
        The most blocks the map's excess over ``threshold`` is cut into and integrated apart, 0 to 128 (default 32;
        0: none, the whole map by the ways above).
    threshold : float or None
        ``T`` [W/(m^2 sr)] (after ``scale``); None (default): `glphong.twin.environment_bright.bright_threshold`.
    """

    name = "environment"
    loop_order = 8
    params = (RESOLUTION, ORDER, ENV_SAMPLES, BRIGHT, THRESHOLD)
    uniforms = _UNIFORMS
    glsl = GlslFile("lights/environment.glsl")
    uses = ("angle",)
    integrals = ("irradiance", "lobe", "lobe_real")
    occludable = True
    uniform_lengths = {"irradiance": "MAP_TEXELS", "sh": "SH_COEFFICIENTS", "frame": 3,
                       "sample_direction": "SAMPLE_TEXELS", "sample_irradiance": "SAMPLE_TEXELS",
                       "bright_direction": "BRIGHT_BLOCKS", "bright_radius": "BRIGHT_BLOCKS",
                       "bright_moment": "BRIGHT_MOMENTS", "bright_length": "BRIGHT_BLOCKS",
                       "bright_power": "BRIGHT_BLOCKS", "bright_total": 3}
    conditional_uniforms = {"irradiance": "IRRADIANCE_MAP", "resolution": "IRRADIANCE_MAP", "sh": "SH", "frame": "SH",
                            "samples": "USES_SAMPLE", "sample_direction": "USES_SAMPLE",
                            "sample_irradiance": "USES_SAMPLE", "bright_count": "BRIGHT",
                            "bright_direction": "BRIGHT", "bright_radius": "BRIGHT",
                            "bright_moment": "BRIGHT_IRRADIANCE", "bright_length": "BRIGHT_IRRADIANCE",
                            "bright_power": "BRIGHT_LOBE", "bright_total": "BRIGHT_IRRADIANCE",
                            "bright_center": "BRIGHT", "bright_cap": "BRIGHT"}
    exact_uniforms = tuple(p.name for p in _UNIFORMS)
    optional_code = (("IRRADIANCE_MAP", "the irradiance cube map and its uniforms"),
                     ("SH", "the spherical harmonics and their uniforms"),
                     ("USES_SAMPLE", "the averaged map's directions and their uniforms"),
                     ("BRIGHT", "the bright blocks' directions and sizes (a map with texels above its threshold)"),
                     ("BRIGHT_IRRADIANCE", "the bright blocks' moments, for Lambert"),
                     ("BRIGHT_LOBE", "the bright blocks' powers, for the Phong lobe"))

    def __init__(self, image, rotation=None, scale=1.0, resolution=9, order=4, samples=4, irradiance="map",
                 method="auto", bright=32, threshold=None):
        if isinstance(image, (str, Path)):
            image = read_radiance_map(image)
        radiance = np.array(image, dtype=np.float64)
        if radiance.ndim == 3 and radiance.shape[2] == 1:
            radiance = radiance[..., 0]
        if radiance.ndim not in (2, 3) or (radiance.ndim == 3 and radiance.shape[2] != 3) or 0 in radiance.shape:
            raise ValueError(f"image must be (H, W) or (H, W, 3) radiance (got shape {radiance.shape})")
        if radiance.shape[0] * radiance.shape[1] > LIMITS.image_pixels:
            raise ValueError(f"image has {radiance.shape[0] * radiance.shape[1]} texels, beyond the limit "
                             f"{LIMITS.image_pixels} (glphong.filesafety.LIMITS.image_pixels)")
        scale = float(scale)
        if not (np.isfinite(scale) and scale >= 0):
            raise ValueError(f"scale must be finite and >= 0 (got {scale})")
        radiance = radiance * scale
        if not np.all(np.isfinite(radiance)) or np.any(radiance < 0):
            raise ValueError("image must hold finite radiance >= 0 (after scale)")
        if radiance.ndim == 2:
            radiance = np.repeat(radiance[..., None], 3, axis=-1)
        if irradiance not in ("map", "sh"):
            raise ValueError(f"irradiance must be 'map' (the irradiance cube map) or 'sh' (the spherical harmonics) "
                             f"(got {irradiance!r})")
        radiance.setflags(write=False)
        rotation = _rotation(rotation)
        rotation.setflags(write=False)
        object.__setattr__(self, "radiance", radiance)
        object.__setattr__(self, "rotation", rotation)
        object.__setattr__(self, "irradiance_method", irradiance)
        object.__setattr__(self, "_digest", hashlib.sha256(radiance.tobytes() + rotation.tobytes()).hexdigest()[:16])
        object.__setattr__(self, "_cache", {})
        super().__init__(resolution, order, samples, bright, threshold, method=method)

    def __setstate__(self, state):
        """Unpickled (a batch worker's copy): the map and the rotation read-only again, as constructed."""
        self.__dict__.update(state)
        for name in ("radiance", "rotation"):
            state[name].setflags(write=False)

    def check(self):
        super().check()
        for name in ("resolution", "order", "bright"):
            if not float(getattr(self, name)).is_integer():
                raise ValueError(f"{name} must be a whole number (got {getattr(self, name)!r})")

    def parameter_values(self):
        return super().parameter_values() | {"image": f"{self.radiance.shape[0]}x{self.radiance.shape[1]} "
                                                      f"sha256:{self._digest}", "irradiance": self.irradiance_method}

    def exact_texels(self):
        """The map's texels: its exact lobe and quadrature visit those within reach of each pixel."""
        return self.radiance.shape[0] * self.radiance.shape[1]

    def sample_count(self):
        """``2 samples^2`` averaged texels."""
        return 2 * int(self.samples) ** 2

    @classmethod
    def structural_defines(cls, lights):
        modes = {light.irradiance_method for light in lights}
        blocks = max(light.bright_count() for light in lights)
        if len(modes) > 1:
            raise ValueError("a scene's environment lights must agree on irradiance= ('map' or 'sh')")
        return (("MAP_TEXELS", str(6 * max(int(light.resolution) for light in lights) ** 2)),
                ("SH_ORDER", str(max(int(light.order) for light in lights))),
                ("SH_COEFFICIENTS", str(max(env.sh_count(light.order) for light in lights))),
                ("SAMPLE_TEXELS", str(max(light.sample_count() for light in lights))),
                ("MAX_SAMPLES", str(max(light.sample_count() for light in lights)))) \
            + ((("IRRADIANCE_BY_SH", "1"),) if modes == {"sh"} else ()) \
            + ((("BRIGHT_BLOCKS", str(blocks)), ("BRIGHT_MOMENTS", str(3 * blocks))) if blocks else ())

    @classmethod
    def usage_defines(cls, defines, uses):
        """Declare and upload only what the program's terms read: the irradiance cube map (or the harmonics) for
        Lambert, the harmonics for the Phong lobe, the averaged texels for the other terms; the bright blocks'
        moments for Lambert and their powers for the lobe, where the scene's maps have any."""
        by_sh = "IRRADIANCE_BY_SH" in dict(defines)
        out = []
        if "BRIGHT_BLOCKS" in dict(defines):
            lobe = "lobe" in uses or "lobe_real" in uses
            out += ([("BRIGHT", "1")] if "irradiance" in uses or lobe else []) \
                + ([("BRIGHT_IRRADIANCE", "1")] if "irradiance" in uses else []) \
                + ([("BRIGHT_LOBE", "1")] if lobe else [])
        if "irradiance" in uses:
            out.append(("IRRADIANCE_SH", "1") if by_sh else ("IRRADIANCE_MAP", "1"))
        if "lobe" in uses or "lobe_real" in uses or ("irradiance" in uses and by_sh):
            out.append(("SH", "1"))
        if "sample" in uses:
            out.append(("USES_SAMPLE", "1"))
        return tuple(out)

    # ---- what the GPU is given (computed once per light)
    def _data(self, what):
        cache = self._cache
        if what not in cache:
            if what == "bright":
                threshold = bright_blocks.bright_threshold(self.radiance) if self.threshold is None else self.threshold
                residual, blocks = bright_blocks.bright_blocks(self.radiance, float(threshold), int(self.bright))
                blocks["direction"] = blocks["direction"] @ self.rotation.T
                for name in ("moment", "total", "center"):
                    blocks[name] = blocks[name] @ self.rotation.T
                cache[what] = (residual, blocks, float(threshold))
            elif what == "irradiance":
                directions = env.cube_texel_directions(int(self.resolution))
                cache[what] = env.irradiance(self._data("bright")[0], directions @ self.rotation)
            elif what == "sh":
                cache[what] = env.sh_project(self._data("bright")[0], int(self.order))
            else:
                rows = int(self.samples)
                mean = env.downsample(self.radiance, rows).reshape(-1, 3)
                moments = env.texel_moments(rows, 2 * rows).reshape(-1, 3)
                length = np.linalg.norm(moments, axis=1)
                cache[what] = ((moments / length[:, None]) @ self.rotation.T, mean * length[:, None])
        return cache[what]

    def uniform_value(self, name):
        if name == "irradiance":
            return self._data("irradiance")[0]
        if name == "sh":
            return self._data("sh")
        if name == "frame":
            return self.rotation.T
        if name == "sample_direction":
            return self._data("samples")[0]
        if name == "sample_irradiance":
            return self._data("samples")[1]
        if name == "bright_count":
            return float(self.bright_count())
        if name.startswith("bright_"):
            value = self._data("bright")[1][name[len("bright_"):]]
            return value.reshape(-1, 3) if name in ("bright_moment", "bright_total") else value
        return getattr(self, name)

    def bright_count(self):
        """How many bright blocks the map's excess is cut into (0: no texel above the threshold, or ``bright=0``)."""
        return len(self._data("bright")[1]["radius"])

    def bright_threshold(self):
        """The threshold ``T`` in use [W/(m^2 sr)]: ``threshold``, or the automatic one."""
        return self._data("bright")[2]

    def irradiance_map_bound(self):
        """The largest bound on the irradiance cube map's texels' own quadrature error [W/m^2] (texels the
        horizon crosses, `glphong.twin.environment.irradiance`)."""
        return float(np.max(self._data("irradiance")[1]))

    # ---- the twin (environment.glsl, function by function)
    def irradiance(self, x, n, p):
        if "IRRADIANCE_MAP" in p.defines:
            smooth = env.environment_cube(n, p.irradiance, p.resolution)[0]
        else:
            smooth = env.environment_sh(n, 1.0, p.sh, p.frame, int(p.defines["SH_ORDER"]))[0]
        return smooth + self._bright_irradiance(n, p)[0] if "BRIGHT_IRRADIANCE" in p.defines else smooth

    def lobe(self, x, n, r, q, p):
        horizon = env.environment_horizon(q, np.clip(np.sum(n * r, axis=-1), -1.0, 1.0))
        smooth = env.environment_sh(r, q, p.sh, p.frame, int(p.defines["SH_ORDER"]))[0] * horizon[:, None]
        return smooth + self._bright_lobe(n, r, q, p)[0] if "BRIGHT_LOBE" in p.defines else smooth

    @staticmethod
    def _blocks(p):
        """The bright blocks' uniforms (float32 values, as the GPU reads them) by `bright_blocks`' names."""
        names = ("count", "direction", "radius", "moment", "length", "power", "total", "center", "cap")
        out = {name: getattr(p, "bright_" + name) for name in names if hasattr(p, "bright_" + name)}
        if "moment" in out:
            out["moment"] = out["moment"].reshape(-1, 3, 3)
        return out

    def _bright_irradiance(self, n, p):
        return bright_blocks.environment_bright_irradiance(n, self._blocks(p))

    def _bright_lobe(self, n, r, q, p):
        return bright_blocks.environment_bright_lobe(n, r, q, self._blocks(p))

    def sample(self, x, n, k, p):
        count = 2 * int(p.samples) ** 2
        i = min(k, len(p.sample_direction) - 1)
        shape = (len(x), 3)
        return (np.full(len(x), k < count), np.broadcast_to(p.sample_direction[i], shape),
                np.broadcast_to(p.sample_irradiance[i], shape))

    # ---- the bands: the twin reads the float32 uniforms the GPU reads; what is left is the arithmetic
    def irradiance_band(self, x, n, p, constants):
        """The sensitivity to the normal's rounding (a face or texel boundary crossed moves to the other side) plus
        the blend's float32 rounding: ``8 eps`` of the largest texel and the four texels' spread times ``4 (R + 2)
        eps`` (the texel coordinate's error in texels), or for the harmonics ``(16 + 8 L) eps`` of the sum of
        ``|terms|``; plus ``32 eps`` of the bright blocks' terms' sizes
        (`glphong.twin.environment_bright.environment_bright_irradiance`)."""
        low, high = super().irradiance_band(x, n, p, constants)
        if "IRRADIANCE_MAP" in p.defines:
            value, spread = env.environment_cube(n, p.irradiance, p.resolution)
            slack = 8 * EPS * np.max(np.abs(value), axis=1) + 4 * (float(p.resolution) + 2) * EPS * spread
            slack = slack + 8 * EPS * np.max(np.abs(p.irradiance))
        else:
            order = int(p.defines["SH_ORDER"])
            slack = (16 + 8 * order) * EPS * env.environment_sh(n, 1.0, p.sh, p.frame, order)[1]
        slack = slack[:, None] + (32 * EPS * self._bright_irradiance(n, p)[1] if "BRIGHT_IRRADIANCE" in p.defines
                                  else 0.0)
        return low - slack, high + slack

    def lobe_band(self, x, n, r, q, p, constants):
        """The sensitivity to the rounding of ``n`` and ``r``, plus ``(16 + 12 L) eps`` of the sum of the harmonics'
        ``|terms|`` (the recurrences' rounding, the lobe weights' ``c_l(q)`` included) times the horizon factor
        ``h``, plus the harmonics' value times ``h``'s own rounding, ``eps (64 + 2 (q + 1) |log s|) (1 - h)`` (the
        exponent of its weights is off by that many ulps of its size); plus ``16 eps`` of each bright block's term
        times ``1 + q (1 + |log x|)`` (`glphong.twin.environment_bright.environment_bright_lobe`)."""
        low, high = super().lobe_band(x, n, r, q, p, constants)
        order = int(p.defines["SH_ORDER"])
        value, magnitude = env.environment_sh(r, q, p.sh, p.frame, order)
        c = np.clip(np.sum(n * r, axis=-1), -1.0, 1.0)
        h = env.environment_horizon(q, c)
        s = np.maximum(np.sqrt(np.maximum(1.0 - c * c, 0.0)), 1e-30)
        slack = (16 + 12 * order) * EPS * magnitude * np.abs(h) + np.max(np.abs(value), axis=1) * EPS * (
            64 + 2 * (q + 1) * np.abs(np.log(s))) * np.where(c < 0.0, h, 1.0 - h)
        slack = slack[:, None] + (16 * EPS * self._bright_lobe(n, r, q, p)[1] if "BRIGHT_LOBE" in p.defines else 0.0)
        return low - slack, high + slack

    def sample_band(self, x, n, k, p, constants):
        """A uniform: exact."""
        e = self.sample(x, n, k, p)[2]
        return e, e

    # ---- the exact integral (the method error map's reference)
    def exact(self, x, n, p, integrand, clip=()):
        """``integral integrand L_i [n.w > 0] dw`` over the map's texels by `environment_integral` (rtol 1e-9),
        resolving the integrand's features down to about 0.02 rad (Phong lobes to ``q`` of a few hundred): the
        map itself is this light's (the uniforms carry only what the methods read)."""
        if not hasattr(self, "radiance"):
            raise TypeError("EnvironmentLight.exact needs the light itself (its map), not a bare twin")
        return environment_integral(n, self.radiance, integrand, rotation=self.rotation, clip=clip)

    def exact_twin(self):
        """What `glphong.checks.reference.exact_reflection` reads in this light's place: the exact irradiance of the
        map in closed form (`_ExactEnvironment`; the shader's cube map is not exact), and `exact` for the rest."""
        if not hasattr(self, "radiance"):
            raise TypeError("EnvironmentLight.exact_twin needs the light itself (its map), not a bare twin")
        return _ExactEnvironment(self)

    @classmethod
    def example(cls, **overrides):
        """A small sky (8 x 16 texels brightening toward the zenith, one bright texel for a sun)."""
        d = env.texel_directions(8, 16)
        sky = 0.5 + np.maximum(d[..., 2], 0.0)[..., None] * np.array([0.4, 0.5, 1.0])
        sky[1, 3] = (40.0, 36.0, 30.0)
        return cls(**({"image": sky} | overrides))

    @classmethod
    def stability_cases(cls):
        """Extreme maps at the normal +z (a texel centre of the odd-sized irradiance map, where the map holds the
        exact irradiance): a sun 1e6 times the sky, a map zero but for one texel, a sky of 1e30 and of 1e-30; and
        the Phong lobe seen along the normal under a constant sky for q from 1 to 1e3 (where the harmonics are
        exact; the quadrature chases the lobe's peak on the map's pole: 1e5 takes it 40 s, so that q is checked against
        its closed form in tests/lights/test_environment_light.py instead)."""
        up = (0.0, 0.0, 1.0)
        sky = np.ones((8, 16, 3))
        sun = sky.copy()
        sun[1, 3] = 1e6
        single = np.zeros((8, 16, 3))
        single[2, 5] = (3.0, 2.0, 1.0)
        return extended_cases("environment", (
            ("a sun of 1e6 times the sky", cls(sun, samples=1), up, Lambert(0.3)),
            ("zero but for one texel", cls(single, samples=1), up, Lambert(0.3)),
            ("a sky of 1e30", cls(sky * 1e30, samples=1), up, Lambert(0.3)),
            ("a sky of 1e-30", cls(sky * 1e-30, samples=1), up, Lambert(0.3)),
            ("constant sky, lobe q = 1", cls(sky, order=2, samples=1), 1.0),
            ("constant sky, lobe q = 20", cls(sky, order=2, samples=1), 20.0),
            ("constant sky, lobe q = 100", cls(sky, order=2, samples=1), 100.0),
            ("constant sky, lobe q = 2.5", cls(sky, order=2, samples=1), 2.5),
            ("constant sky, lobe q = 1e3", cls(sky, order=2, samples=1), 1e3)))


class _ExactEnvironment:
    """An environment light's exact integrals, in the twin's calling convention (`EnvironmentLight.exact_twin`): the
    irradiance ``E(n)`` of the map at the world normals, each texel wholly above the horizon ``L_k (n . M_k)`` and each
    one the horizon crosses in closed form (`glphong.twin.environment.irradiance` with ``crossed='closed'``: about
    1e-12 relative, against the quadrature's 1e-9), so a term of irradiance form is reflected exactly at the cost of
    the map's rows and crossed texels a normal, not its texels; the lecture's Phong lobe by `exact_lobe`
    (`glphong.twin.environment_lobe`: shared-node stencils, 1e-9 of the pixel); every other term by
    `EnvironmentLight.exact` (`glphong.checks.reference.exact_reflection` splits a material so)."""

    def __init__(self, light):
        self.light = light

    def closed_form_is_exact(self, form, q=None):
        return form in ("irradiance", "lobe", "lobe_real")

    def exact_lobe(self, n, r, q, rtol=1e-9, floor=None):
        """``integral max(r.w, 0)^q L(w) [n.w > 0] dw`` at world normals ``n`` and lobe axes ``r`` (N, 3):
        ``(value (N, 3), error estimate (N,), converged (N,))`` (`glphong.twin.environment_lobe.lobe_integral`;
        ``floor`` (N,) the scale under which an error does not matter)."""
        radiance = np.asarray(self.light.radiance, np.float64)
        radiance = np.repeat(radiance[..., None], 3, axis=-1) if radiance.ndim == 2 else radiance
        rotation = self.light.rotation
        return lobe_integral(radiance, np.asarray(r, np.float64) @ rotation, np.asarray(n, np.float64) @ rotation,
                             q, rtol, floor)

    def irradiance(self, x, n, p):
        return env.irradiance(self.light.radiance, np.asarray(n, np.float64) @ self.light.rotation,
                              crossed="closed")[0]

    def exact(self, x, n, p, integrand, clip=()):
        return self.light.exact(x, n, p, integrand, clip)
