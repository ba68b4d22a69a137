"""Integrations with other libraries; each submodule imports its library, ``import glphong`` imports none."""
