"""A framebuffer with a 32-bit float depth attachment (``GL_DEPTH_COMPONENT32F``).

moderngl's ``depth_texture`` is fixed 24-bit; the float format is made here with the few raw
GL calls it needs (through ``eglGetProcAddress``, in the current moderngl context) and the
framebuffer is handed back to moderngl with ``ctx.detect_framebuffer``.
"""
from __future__ import annotations

import ctypes
from functools import lru_cache

from ..core.errors import WorkbenchError

GL_TEXTURE_2D = 0x0DE1
GL_DEPTH_COMPONENT32F = 0x8CAC
GL_DEPTH_COMPONENT = 0x1902
GL_FLOAT = 0x1406
GL_TEXTURE_MIN_FILTER, GL_TEXTURE_MAG_FILTER, GL_NEAREST = 0x2801, 0x2800, 0x2600
GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_DEPTH_ATTACHMENT = 0x8D40, 0x8CE0, 0x8D00
GL_FRAMEBUFFER_COMPLETE = 0x8CD5

_u, _i, _p = ctypes.c_uint, ctypes.c_int, ctypes.c_void_p


@lru_cache(maxsize=None)
def _gl():
    """The GL entry points used here (resolved once)."""
    egl = ctypes.CDLL("libEGL.so.1")
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]

    def fn(name, restype, *argtypes):
        addr = egl.eglGetProcAddress(name.encode())
        if not addr:
            raise WorkbenchError(f"OpenGL function {name} not available")
        return ctypes.CFUNCTYPE(restype, *argtypes)(addr)

    pu = ctypes.POINTER(_u)
    return {
        "GenTextures": fn("glGenTextures", None, _i, pu),
        "DeleteTextures": fn("glDeleteTextures", None, _i, pu),
        "BindTexture": fn("glBindTexture", None, _u, _u),
        "TexImage2D": fn("glTexImage2D", None, _u, _i, _i, _i, _i, _i, _u, _u, _p),
        "TexParameteri": fn("glTexParameteri", None, _u, _u, _i),
        "GenFramebuffers": fn("glGenFramebuffers", None, _i, pu),
        "DeleteFramebuffers": fn("glDeleteFramebuffers", None, _i, pu),
        "BindFramebuffer": fn("glBindFramebuffer", None, _u, _u),
        "FramebufferTexture2D": fn("glFramebufferTexture2D", None, _u, _u, _u, _u, _i),
        "CheckFramebufferStatus": fn("glCheckFramebufferStatus", _u, _u),
    }


class FloatDepthFramebuffer:
    """Colour texture (a moderngl texture) + float32 depth texture; ``.fbo`` is the moderngl
    Framebuffer, :meth:`release` deletes the GL objects."""

    def __init__(self, ctx, color):
        g = _gl()
        w, h = color.size
        tex, fbo = _u(), _u()
        g["GenTextures"](1, ctypes.byref(tex))
        g["BindTexture"](GL_TEXTURE_2D, tex.value)
        g["TexImage2D"](GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, w, h, 0, GL_DEPTH_COMPONENT, GL_FLOAT, None)
        g["TexParameteri"](GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST)
        g["TexParameteri"](GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST)
        g["BindTexture"](GL_TEXTURE_2D, 0)
        g["GenFramebuffers"](1, ctypes.byref(fbo))
        g["BindFramebuffer"](GL_FRAMEBUFFER, fbo.value)
        g["FramebufferTexture2D"](GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color.glo, 0)
        g["FramebufferTexture2D"](GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, tex.value, 0)
        status = g["CheckFramebufferStatus"](GL_FRAMEBUFFER)
        g["BindFramebuffer"](GL_FRAMEBUFFER, 0)
        self._tex, self._fbo, self.color = tex, fbo, color
        if status != GL_FRAMEBUFFER_COMPLETE:
            self.release()
            raise WorkbenchError(f"float depth framebuffer incomplete (status {status:#x})")
        self.fbo = ctx.detect_framebuffer(fbo.value)

    def depth_texture(self, ctx):
        """The depth texture as a moderngl texture (sampled by the volume pass; the wrapper
        does not own it: :meth:`release` deletes it)."""
        return ctx.external_texture(self._tex.value, tuple(self.color.size), 1, 0, "f4")

    def release(self) -> None:
        g = _gl()
        g["DeleteFramebuffers"](1, ctypes.byref(self._fbo))
        g["DeleteTextures"](1, ctypes.byref(self._tex))
        self.color.release()
