"""GLSL sources of glphong, shipped inside the wheel as ``glphong.glsl``."""
