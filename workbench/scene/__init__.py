"""Scenes as pure data: the model, the TOML reader, the needs manifest and the bundled library."""
from .model import (  # noqa: F401
    AreaLight, Box, Bump, Camera, CSG, DirectionalLight, Environment, Material, Mesh, Opacity,
    Plane, PointLight, Polygon, Quadric, Scene, SceneObject, Sphere, Texture,
)
from .io import SceneError, load_scene  # noqa: F401
