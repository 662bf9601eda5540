"""Fixtures of the ray tracer's tests."""
from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def bvh_hit():
    """``kernels.walks.bvh_hit`` callable from Python (``workbench.core.jit_options.python_twin``), compiled once per
    test process."""
    from workbench.renderers.kernels import walks
    from workbench.core.jit_options import python_twin
    return python_twin(walks.bvh_hit)
