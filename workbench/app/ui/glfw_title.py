"""The window's title through imgui-bundle's own GLFW library (hello_imgui sets it once at
start; the window changes it on a scene switch and scripts read it back)."""
from __future__ import annotations

from pathlib import Path


def glfw_library():
    """The window's GLFW library (imgui-bundle's), with the title functions typed."""
    import ctypes

    import imgui_bundle
    glfw = ctypes.CDLL(str(Path(imgui_bundle.__file__).parent / "libglfw.so.3"))
    glfw.glfwGetCurrentContext.restype = ctypes.c_void_p
    glfw.glfwSetWindowTitle.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
    glfw.glfwGetWindowTitle.argtypes = [ctypes.c_void_p]
    glfw.glfwGetWindowTitle.restype = ctypes.c_char_p
    return glfw


def shown_title() -> str:
    """The title the window has now (GLFW's), for scripts and tests."""
    glfw = glfw_library()
    return (glfw.glfwGetWindowTitle(glfw.glfwGetCurrentContext()) or b"").decode()


def window_size() -> tuple[int, int]:
    """The window's size now (GLFW's, screen coordinates: pixels on X11)."""
    import ctypes
    glfw = glfw_library()
    glfw.glfwGetWindowSize.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int),
                                       ctypes.POINTER(ctypes.c_int)]
    w, h = ctypes.c_int(), ctypes.c_int()
    glfw.glfwGetWindowSize(glfw.glfwGetCurrentContext(), ctypes.byref(w), ctypes.byref(h))
    return w.value, h.value


def window_title(state) -> str:
    """The window's title: the scene shown (``state`` an :class:`~.state.AppState`)."""
    return f"workbench ui: {state.scene_path.stem}"
