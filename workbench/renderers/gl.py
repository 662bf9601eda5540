"""The one module that creates OpenGL contexts.

* moderngl: standalone on EGL (Mesa llvmpipe with no display, no GPU).  There is no default
  framebuffer in a standalone context: every renderer draws into an FBO.
* pyrender: offscreen through PyOpenGL on EGL (``PYOPENGL_PLATFORM`` must be set before the
  first ``OpenGL`` import), OSMesa as a fallback.

A UI that owns a window context can install it with :func:`use_context` so that the raster
methods draw into that context instead.
"""
from __future__ import annotations

import os
import threading

from ..core.errors import WorkbenchError

_local = threading.local()


class GLUnavailable(WorkbenchError):
    """No OpenGL context could be created; the message names the missing piece."""


def use_context(ctx) -> None:
    """Make ``ctx`` (a moderngl context created elsewhere, e.g. by the UI) this thread's context."""
    _local.ctx, _local.owned = ctx, False


def context():
    """This thread's moderngl context (created on first use: standalone, EGL backend)."""
    ctx = getattr(_local, "ctx", None)
    if ctx is None:
        import moderngl
        try:
            ctx = moderngl.create_context(standalone=True, backend="egl", require=330)
        except Exception as e:  # glcontext raises plain Exceptions with the loader's text
            raise GLUnavailable(
                "cannot create a headless OpenGL context through EGL "
                f"({e}). Install Mesa's EGL and software rasteriser: "
                "apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri") from None
        _local.ctx, _local.owned = ctx, True
    return ctx


def end_thread() -> None:
    """Free what this thread holds of OpenGL before it ends: its standalone context (made by
    :func:`context`; one installed by :func:`use_context` is left alone) and EGL's state of the
    thread (``eglReleaseThread``, EGL 1.4 section 3.11).  A thread that ends without it leaks
    both: Mesa frees neither when a thread exits (measured here: about 2.5 MB per thread that
    made a context, so the window's background jobs, a thread each, grew its resident size with
    every radiosity render; issue #29, item 3)."""
    ctx = getattr(_local, "ctx", None)
    if ctx is None or not getattr(_local, "owned", False):
        return
    import ctypes
    _local.ctx, _local.owned = None, False
    ctx.release()
    try:
        ctypes.CDLL("libEGL.so.1").eglReleaseThread()
    except (OSError, AttributeError):  # no EGL library: the context was not an EGL one
        pass


def renderer_name(ctx=None) -> str:
    """GL_RENDERER of the context, logged with every timing."""
    ctx = ctx or context()
    return f"{ctx.info['GL_RENDERER']} (OpenGL {ctx.version_code // 100}.{ctx.version_code % 100 // 10})"


def check_errors(ctx=None) -> None:
    """Raise if the GL error flag is set (``ctx.error`` reads and clears glGetError)."""
    ctx = ctx or context()
    err = ctx.error
    if err != "GL_NO_ERROR":
        raise RuntimeError(f"OpenGL error: {err}")


def release_framebuffer(fbo) -> None:
    """Release an FBO without leaving it bound.

    moderngl remembers the bound framebuffer: release the bound one and the next FBO, which
    OpenGL may give the same name, is taken as already bound and never bound (draws then fail
    with GL_INVALID_OPERATION in a standalone context, which has no default framebuffer).  So
    a bound FBO is first swapped for a 1x1 parking framebuffer kept for the context's life."""
    ctx = fbo.ctx
    if ctx.fbo is fbo:
        park = getattr(ctx, "_workbench_park", None)
        if park is None:
            park = ctx.framebuffer(color_attachments=[ctx.renderbuffer((1, 1))])
            ctx._workbench_park = park
        park.use()
    fbo.release()


def object_bytes(obj) -> int:
    """Bytes a moderngl object holds in GL memory (llvmpipe's is the process's own): a buffer's
    size; a texture's texels (a cube map's six faces, a 3D texture's or array's layers) times
    components times bytes per component; a framebuffer's attachments; 0 for anything else
    (programs, vertex arrays)."""
    import math

    import moderngl
    if isinstance(obj, moderngl.Buffer):
        return int(obj.size)
    if isinstance(obj, moderngl.Framebuffer):
        return sum(object_bytes(a) for a in (*obj.color_attachments, obj.depth_attachment)
                   if a is not None)
    if isinstance(obj, (moderngl.Texture, moderngl.Texture3D, moderngl.TextureArray,
                        moderngl.TextureCube)):
        faces = 6 if isinstance(obj, moderngl.TextureCube) else 1
        return faces * math.prod(obj.size) * obj.components * int(obj.dtype[1:])
    return 0


def pyrender_platform() -> str:
    """Choose PyOpenGL's platform for pyrender before OpenGL is first imported: EGL when
    libEGL loads, else OSMesa.  Returns the platform name."""
    if "PYOPENGL_PLATFORM" not in os.environ:
        import ctypes.util
        os.environ["PYOPENGL_PLATFORM"] = "egl" if ctypes.util.find_library("EGL") else "osmesa"
    return os.environ["PYOPENGL_PLATFORM"]


def pyrender_offscreen(width: int, height: int):
    """A ``pyrender.OffscreenRenderer`` (EGL, OSMesa fallback)."""
    platform = pyrender_platform()
    try:
        import pyrender
        return pyrender.OffscreenRenderer(width, height)
    except Exception as e:
        raise GLUnavailable(f"pyrender cannot open an offscreen context on {platform!r} ({e}). "
                            "Install libegl1 libgl1-mesa-dri (or libosmesa6 with "
                            "PYOPENGL_PLATFORM=osmesa)") from None
