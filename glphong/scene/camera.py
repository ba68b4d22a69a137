"""Cameras with OpenGL conventions (docs/design.md section 2): perspective, from OpenCV intrinsics, orthographic.

A camera looks down -Z of its own frame; +Y is up in the image; the world is
right-handed.  ``pose`` maps camera coordinates to world coordinates.
"""
import abc

import numpy as np

from glphong.core import validate as _validate

__all__ = ["Camera", "PerspectiveCamera", "OrthographicCamera", "IntrinsicsCamera", "opencv_pose"]


def _look_at_pose(eye, target, up):
    """The camera-to-world pose of a camera at ``eye`` looking at ``target`` with ``up`` roughly up."""
    eye = np.asarray(_validate.vec3("eye", eye))
    target = np.asarray(_validate.vec3("target", target))
    up = np.asarray(_validate.vec3("up", up, nonzero=True))
    back = eye - target
    if not np.any(back):
        raise ValueError("target must differ from eye")
    # scaled normalisation (docs/design.md section 3): no underflow for tiny vectors
    z = back / np.max(np.abs(back))
    z /= np.linalg.norm(z)
    x = np.cross(up / np.max(np.abs(up)), z)
    if not np.linalg.norm(x) > 1e-12:
        raise ValueError("up must not be parallel to the viewing direction target - eye")
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = x, np.cross(z, x), z, eye
    return pose


class Camera(abc.ABC):
    """What every camera has: a rigid pose (OpenGL frame: looking down its -Z, +Y up), clip distances, and
    rays through image positions.  Subclasses give the projection and the image-plane mapping.

    Parameters
    ----------
    pose : (4, 4) array_like, optional
        Camera-to-world rigid transform (default identity: at the origin looking down -Z).
    znear, zfar : float, optional
        Clip distances [m], 0 < znear < zfar (defaults 0.05 and 100).
    """

    def __init__(self, pose=None, znear=0.05, zfar=100.0):
        self.pose = _validate.rigid_pose("pose", np.eye(4) if pose is None else pose)
        self.znear = _validate.scalar("znear", znear, low=0.0, low_inclusive=False)
        self.zfar = _validate.scalar("zfar", zfar, low=0.0, low_inclusive=False)
        if not self.zfar > self.znear:
            raise ValueError(f"zfar must be greater than znear, in ({self.znear!r}, {_validate.FLT_MAX:g}] "
                             f"(got zfar={self.zfar!r})")

    @property
    def position(self):
        """Camera centre in world space [m], (3,) float64."""
        return self.pose[:3, 3].copy()

    @property
    def eye(self):
        """The homogeneous eye ``(e, w)``, (4,) float64: the view vector at a point ``x`` is
        ``normalize(e - w x)`` (``u_eye`` of the shaders).  A perspective camera's is its centre with
        ``w = 1``; an orthographic camera's its backward axis with ``w = 0`` (parallel views)."""
        return np.append(self.position, 1.0)

    def view_matrix(self):
        """World-to-camera transform, (4, 4) float64."""
        r, t = self.pose[:3, :3], self.pose[:3, 3]
        view = np.eye(4)
        view[:3, :3] = r.T
        view[:3, 3] = -r.T @ t
        return view

    @abc.abstractmethod
    def projection_matrix(self, aspect):
        """The OpenGL projection for ``aspect = width / height``, (4, 4) float64."""

    @abc.abstractmethod
    def _image_plane(self, xp, yp, width, height):
        """Camera-space ``(x, y)`` of image positions ``(xp, yp)`` [px from the top-left corner]: on the
        plane ``z = -1`` (perspective) or ``z = 0`` (orthographic)."""

    def _camera_rays(self, x, y):
        """Camera-space ``(origins, directions)`` of the rays through image-plane points: from the centre
        through ``(x, y, -1)`` (the default, perspective)."""
        return np.zeros(3), np.stack([x, y, -np.ones_like(x)], axis=-1)

    def sample_rays(self, width, height, offsets=None, rows=None):
        """World-space rays through sub-pixel positions.

        Parameters
        ----------
        width, height : int
            Image size [px].
        offsets : (S, 2) array_like, optional
            Sub-pixel positions ``(ox, oy)`` in pixel units from the pixel's top-left corner,
            ``ox`` rightwards, ``oy`` downwards (row 0 is the top row).  Default: the centre
            ``[(0.5, 0.5)]``.
        rows : slice or array_like of int, optional
            Only these image rows (default all).

        Returns
        -------
        origins : (3,) or (R, width, S, 3) float64 ndarray
            The camera centre [m] (perspective), or one origin per ray on the camera's plane
            (orthographic).
        directions : (R, width, S, 3) float64 ndarray
            Unit ray directions; R is the number of rows selected.
        """
        offsets = np.array([[0.5, 0.5]]) if offsets is None else np.asarray(offsets, dtype=np.float64)
        if offsets.ndim != 2 or offsets.shape[1] != 2:
            raise ValueError(f"offsets must have shape (S, 2) (got {offsets.shape})")
        j = np.arange(height)[rows if rows is not None else slice(None)]
        i = np.arange(width)
        x, y = self._image_plane(i[None, :, None] + offsets[None, None, :, 0], j[:, None, None] + offsets[None, None, :, 1],
                                 width, height)
        x, y = np.broadcast_arrays(x, y)
        origins, d = self._camera_rays(x, y)
        d = d @ self.pose[:3, :3].T
        return origins @ self.pose[:3, :3].T + self.pose[:3, 3], d / np.linalg.norm(d, axis=-1, keepdims=True)

    def pixel_rays(self, width, height):
        """World-space rays through the pixel centres, row 0 at the top of the image.

        Returns
        -------
        origins : (3,) or (height, width, 3) float64
            The camera centre [m], or one origin per pixel (orthographic).
        directions : (height, width, 3) float64
            Unit ray directions.
        """
        origins, directions = self.sample_rays(width, height)
        return (origins if origins.ndim == 1 else origins[:, :, 0]), directions[:, :, 0]

    def _frustum(self, sx, sy, ox, oy):
        """The projection ``x_ndc = sx x / -z + ox``, ``y_ndc = sy y / -z + oy`` with the depth rows of
        `znear` and `zfar`, (4, 4) float64."""
        n, far = self.znear, self.zfar
        return np.array([
            [sx, 0.0, -ox, 0.0],
            [0.0, sy, -oy, 0.0],
            [0.0, 0.0, (far + n) / (n - far), 2.0 * far * n / (n - far)],
            [0.0, 0.0, -1.0, 0.0],
        ])


class PerspectiveCamera(Camera):
    """A pinhole camera.

    Parameters
    ----------
    yfov : float
        Vertical field of view [rad], in (0, pi).
    pose : (4, 4) array_like, optional
        Camera-to-world rigid transform (default identity: at the origin looking down -Z).
    znear, zfar : float, optional
        Clip distances [m], 0 < znear < zfar (defaults 0.05 and 100).
    """

    def __init__(self, yfov, pose=None, znear=0.05, zfar=100.0):
        self.yfov = _validate.scalar("yfov", yfov, low=0.0, high=np.pi, low_inclusive=False, high_inclusive=False)
        super().__init__(pose, znear, zfar)

    @classmethod
    def look_at(cls, eye, target, up=(0.0, 1.0, 0.0), yfov=np.pi / 4, znear=0.05, zfar=100.0):
        """A camera at ``eye`` looking at ``target``.

        Parameters
        ----------
        eye, target : (3,) array_like
            Camera centre and the point it looks at [m]; must differ.
        up : (3,) array_like
            Approximate up direction; must not be parallel to ``target - eye``.
        yfov : float
            Vertical field of view [rad].
        znear, zfar : float
            Clip distances [m].
        """
        return cls(yfov, pose=_look_at_pose(eye, target, up), znear=znear, zfar=zfar)

    def projection_matrix(self, aspect):
        """OpenGL perspective projection for ``aspect = width / height``, (4, 4) float64."""
        f = 1.0 / np.tan(self.yfov / 2.0)
        return self._frustum(f / aspect, f, 0.0, 0.0)

    def _image_plane(self, xp, yp, width, height):
        t = np.tan(self.yfov / 2.0)
        return (xp / width * 2.0 - 1.0) * t * (width / height), (1.0 - yp / height * 2.0) * t

    def __repr__(self):
        return f"PerspectiveCamera(yfov={self.yfov:.6g}, position={tuple(self.position)}, znear={self.znear:g}, zfar={self.zfar:g})"


class OrthographicCamera(Camera):
    """A parallel-projection camera: every view ray runs along the camera's -Z.

    Parameters
    ----------
    ymag : float
        Half the height of the view [m], > 0; the half width is ``ymag * width / height`` (glTF's and
        pyrender's ``ymag``, with ``xmag`` from the image's aspect).
    pose : (4, 4) array_like, optional
        Camera-to-world rigid transform; the view is centred on its position.
    znear, zfar : float, optional
        Clip distances [m] along the viewing axis, 0 < znear < zfar.

    Notes
    -----
    Shading sees one view direction everywhere: the shaders' homogeneous eye ``u_eye = (b, 0)`` with ``b``
    the camera's backward axis (`Camera.eye`), so the view vector ``normalize(e - w x)`` is ``b``.
    """

    def __init__(self, ymag, pose=None, znear=0.05, zfar=100.0):
        self.ymag = _validate.scalar("ymag", ymag, low=0.0, low_inclusive=False)
        super().__init__(pose, znear, zfar)

    @classmethod
    def look_at(cls, eye, target, up=(0.0, 1.0, 0.0), ymag=1.0, znear=0.05, zfar=100.0):
        """An orthographic camera at ``eye`` looking at ``target`` (see `PerspectiveCamera.look_at`)."""
        return cls(ymag, pose=_look_at_pose(eye, target, up), znear=znear, zfar=zfar)

    @property
    def eye(self):
        return np.append(self.pose[:3, 2], 0.0)

    def projection_matrix(self, aspect):
        """OpenGL orthographic projection for ``aspect = width / height``, (4, 4) float64."""
        n, far = self.znear, self.zfar
        return np.array([
            [1.0 / (self.ymag * aspect), 0.0, 0.0, 0.0],
            [0.0, 1.0 / self.ymag, 0.0, 0.0],
            [0.0, 0.0, 2.0 / (n - far), (far + n) / (n - far)],
            [0.0, 0.0, 0.0, 1.0],
        ])

    def _image_plane(self, xp, yp, width, height):
        return (xp / width * 2.0 - 1.0) * self.ymag * (width / height), (1.0 - yp / height * 2.0) * self.ymag

    def _camera_rays(self, x, y):
        origins = np.stack([x, y, np.zeros_like(x)], axis=-1)
        return origins, np.broadcast_to([0.0, 0.0, -1.0], origins.shape).copy()

    def __repr__(self):
        return f"OrthographicCamera(ymag={self.ymag:.6g}, position={tuple(self.position)}, znear={self.znear:g}, zfar={self.zfar:g})"


class IntrinsicsCamera(PerspectiveCamera):
    """A pinhole camera from calibrated intrinsics, in OpenCV's convention.

    A camera-space point ``(X, Y, Z)`` of OpenCV's frame (``+Z`` forward, ``+Y`` down, ``+X`` right) lands
    at pixel ``u = fx X / Z + cx``, ``v = fy Y / Z + cy``, with integer ``(u, v)`` the centre of column
    ``u`` and row ``v`` (row 0 at the top), as OpenCV's ``projectPoints`` and its calibration give them.
    glphong's camera frame is OpenGL's (looking down ``-Z``, ``+Y`` up): ``X = x``, ``Y = -y``, ``Z = -z``;
    `opencv_pose` turns OpenCV extrinsics ``[R | t]`` into the ``pose`` this class takes.

    Parameters
    ----------
    fx, fy : float
        Focal lengths [px], > 0.
    cx, cy : float
        Principal point [px], OpenCV's convention (pixel centres at integers).
    width, height : int
        The image size the intrinsics belong to.  Rendering at another size with the same aspect
        scales them; another aspect is refused.
    pose : (4, 4) array_like, optional
        Camera-to-world rigid transform of glphong's (OpenGL) camera frame.
    znear, zfar : float
        Clip distances [m].

    Notes
    -----
    pyrender's ``IntrinsicsCamera`` measures ``cx``, ``cy`` from the image's corner (its projection
    has ``1 - 2 cx / width``): the same camera there has ``cx + 0.5``, ``cy + 0.5``.
    """

    def __init__(self, fx, fy, cx, cy, width, height, pose=None, znear=0.05, zfar=100.0):
        self.fx = _validate.scalar("fx", fx, low=0.0, low_inclusive=False)
        self.fy = _validate.scalar("fy", fy, low=0.0, low_inclusive=False)
        self.cx = _validate.scalar("cx", cx, low=-np.inf)
        self.cy = _validate.scalar("cy", cy, low=-np.inf)
        self.width = _validate.positive_int("width", width, 1, 16384)
        self.height = _validate.positive_int("height", height, 1, 16384)
        # the vertical field of view of a centred image of this height (for reference and peers)
        super().__init__(2.0 * np.arctan(self.height / (2.0 * self.fy)), pose=pose, znear=znear, zfar=zfar)

    def projection_matrix(self, aspect):
        """The off-axis projection of the intrinsics (``aspect`` must be ``width / height``), (4, 4) float64."""
        expected = self.width / self.height
        if abs(aspect - expected) > 1e-9 * expected:
            raise ValueError(f"this IntrinsicsCamera belongs to {self.width}x{self.height} images (aspect "
                             f"{expected:.6g}); render it at that aspect (got {aspect:.6g})")
        w, h = self.width, self.height
        return self._frustum(2.0 * self.fx / w, 2.0 * self.fy / h, 2.0 * (self.cx + 0.5) / w - 1.0,
                             1.0 - 2.0 * (self.cy + 0.5) / h)

    def _image_plane(self, xp, yp, width, height):
        u = xp * (self.width / width) - 0.5  # OpenCV pixel coordinates: centres at integers
        v = yp * (self.height / height) - 0.5
        return (u - self.cx) / self.fx, -(v - self.cy) / self.fy

    def __repr__(self):
        return (f"IntrinsicsCamera(fx={self.fx:g}, fy={self.fy:g}, cx={self.cx:g}, cy={self.cy:g}, "
                f"width={self.width}, height={self.height}, position={tuple(self.position)})")


def opencv_pose(rotation, translation):
    """glphong's camera pose from OpenCV extrinsics: ``x_cam = R x_world + t`` (OpenCV frame, +Z forward).

    Parameters
    ----------
    rotation : (3, 3) array_like
        ``R``, a rotation matrix (e.g. from ``cv2.Rodrigues(rvec)``).
    translation : (3,) array_like
        ``t`` [m].

    Returns
    -------
    (4, 4) float64 ndarray
        The camera-to-world pose of the OpenGL camera frame (``+Y`` up, looking down ``-Z``).
    """
    r = np.asarray(rotation, dtype=np.float64)
    t = np.asarray(translation, dtype=np.float64).reshape(3)
    if r.shape != (3, 3) or not np.allclose(r @ r.T, np.eye(3), atol=1e-6) or np.linalg.det(r) < 0:
        raise ValueError(f"rotation must be a (3, 3) rotation matrix (got shape {r.shape})")
    world_to_camera = np.eye(4)
    world_to_camera[:3, :3], world_to_camera[:3, 3] = r, t
    return np.linalg.inv(world_to_camera) @ np.diag([1.0, -1.0, -1.0, 1.0])
