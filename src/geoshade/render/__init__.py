"""The only package that imports moderngl: contexts, shaders, camera, targets and visuals."""

from geoshade.render.camera import Camera
from geoshade.render.context import capabilities, create_context, get_context

__all__ = ["Camera", "capabilities", "create_context", "get_context"]
