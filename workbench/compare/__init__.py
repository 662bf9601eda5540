"""Comparison of methods: metrics and error maps; the report, study and stress modes build on it."""
from .metrics import error_map, metrics  # noqa: F401
