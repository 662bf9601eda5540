"""Renderers: a protocol, a registry by name, and the methods themselves (imported lazily)."""
from .base import RenderResult, Knob, available, get_renderer, render  # noqa: F401
