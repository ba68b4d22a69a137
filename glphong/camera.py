"""Perspective camera with OpenGL conventions (DESIGN section 2).

The camera looks down -Z of its own frame; +Y is up in the image; the world is
right-handed.  ``pose`` maps camera coordinates to world coordinates.
"""
import numpy as np

from . import _validate

__all__ = ["PerspectiveCamera"]


class PerspectiveCamera:
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
        self.pose = _validate.rigid_pose("pose", np.eye(4) if pose is None else pose)
        self.znear = _validate.scalar("znear", znear, low=0.0, low_inclusive=False)
        self.zfar = _validate.scalar("zfar", zfar, low=0.0, low_inclusive=False)
        if not self.zfar > self.znear:
            raise ValueError(f"zfar must be greater than znear, in ({self.znear!r}, {_validate.FLT_MAX:g}] "
                             f"(got zfar={self.zfar!r})")

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
        eye = np.asarray(_validate.vec3("eye", eye))
        target = np.asarray(_validate.vec3("target", target))
        up = np.asarray(_validate.vec3("up", up, nonzero=True))
        back = eye - target
        if not np.any(back):
            raise ValueError("target must differ from eye")
        # scaled normalisation (DESIGN section 3): no underflow for tiny vectors
        z = back / np.max(np.abs(back))
        z /= np.linalg.norm(z)
        x = np.cross(up / np.max(np.abs(up)), z)
        if not np.linalg.norm(x) > 1e-12:
            raise ValueError("up must not be parallel to the viewing direction target - eye")
        x /= np.linalg.norm(x)
        pose = np.eye(4)
        pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = x, np.cross(z, x), z, eye
        return cls(yfov, pose=pose, znear=znear, zfar=zfar)

    @property
    def position(self):
        """Camera centre in world space [m], (3,) float64."""
        return self.pose[:3, 3].copy()

    def view_matrix(self):
        """World-to-camera transform, (4, 4) float64."""
        r, t = self.pose[:3, :3], self.pose[:3, 3]
        view = np.eye(4)
        view[:3, :3] = r.T
        view[:3, 3] = -r.T @ t
        return view

    def projection_matrix(self, aspect):
        """OpenGL perspective projection for ``aspect = width / height``, (4, 4) float64."""
        f = 1.0 / np.tan(self.yfov / 2.0)
        n, far = self.znear, self.zfar
        return np.array([
            [f / aspect, 0.0, 0.0, 0.0],
            [0.0, f, 0.0, 0.0],
            [0.0, 0.0, (far + n) / (n - far), 2.0 * far * n / (n - far)],
            [0.0, 0.0, -1.0, 0.0],
        ])

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
        origin : (3,) float64 ndarray
            The camera centre [m].
        directions : (R, width, S, 3) float64 ndarray
            Unit ray directions; R is the number of rows selected.
        """
        offsets = np.array([[0.5, 0.5]]) if offsets is None else np.asarray(offsets, dtype=np.float64)
        if offsets.ndim != 2 or offsets.shape[1] != 2:
            raise ValueError(f"offsets must have shape (S, 2) (got {offsets.shape})")
        t = np.tan(self.yfov / 2.0)
        aspect = width / height
        j = np.arange(height)[rows if rows is not None else slice(None)]
        i = np.arange(width)
        x = ((i[None, :, None] + offsets[None, None, :, 0]) / width * 2.0 - 1.0) * t * aspect
        y = (1.0 - (j[:, None, None] + offsets[None, None, :, 1]) / height * 2.0) * t
        x, y = np.broadcast_arrays(x, y)
        d = np.stack([x, y, -np.ones_like(x)], axis=-1) @ self.pose[:3, :3].T
        return self.position, d / np.linalg.norm(d, axis=-1, keepdims=True)

    def pixel_rays(self, width, height):
        """World-space rays through the pixel centres, row 0 at the top of the image.

        Returns
        -------
        origin : (3,) float64
            The camera centre [m].
        directions : (height, width, 3) float64
            Unit ray directions.
        """
        origin, directions = self.sample_rays(width, height)
        return origin, directions[:, :, 0]

    def __repr__(self):
        return f"PerspectiveCamera(yfov={self.yfov:.6g}, position={tuple(self.position)}, znear={self.znear:g}, zfar={self.zfar:g})"
