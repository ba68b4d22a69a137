"""Radiance RGBE images (``.hdr``): `glphong.core.rgbe`, where the reader lives so that the environment light (a layer
below the file formats) reads its maps with it; this module keeps the formats' name for it."""
from glphong.core.rgbe import CONVENTIONS, HdrImage, read_hdr, rgbe_decode, rgbe_encode, write_hdr  # noqa: F401

__all__ = ["HdrImage", "read_hdr", "write_hdr", "rgbe_decode", "rgbe_encode", "CONVENTIONS"]
