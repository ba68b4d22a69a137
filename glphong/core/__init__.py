"""The foundation every other layer stands on: argument validation (`validate`), radiometry
(`radiometry`), images and the sRGB curve (`imaging`), reading files from outside (`filesafety`), the MERL
table layout (`merl`), timing (`timing`), the shipped GLSL files (`glsl_files`) and the version.  Nothing
here imports another part of glphong.
"""
