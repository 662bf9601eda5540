"""Core: vector math, transforms, tolerances and colour encoding (imports nothing else of the package)."""
