"""The one factory for OpenGL contexts (headless EGL, or the window's current context).

>>> from geoshade.render.context import get_context, capabilities  # doctest: +SKIP
>>> caps = capabilities(get_context())                               # doctest: +SKIP
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os

import moderngl

from geoshade.errors import GLUnavailableError
from geoshade.io.paths import check_address_space

MIN_GL = 430  # tessellation + geometry + compute + SSBO
_SHARED: moderngl.Context | None = None

# GL enums moderngl's ctx.info does not report
_GL_MAX_TESS_GEN_LEVEL = 0x8E7E
_GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS = 0x8DE1
_GL_MAX_SHADER_STORAGE_BLOCK_SIZE = 0x90DE
_GL_GPU_MEM_INFO_TOTAL_AVAILABLE_MEMORY_NVX = 0x9048
_GL_GPU_MEM_INFO_CURRENT_AVAILABLE_VIDMEM_NVX = 0x9049
_GL_TEXTURE_FREE_MEMORY_ATI = 0x87FC

_HINT = (
    "geoshade needs OpenGL >= 4.3 (tessellation, geometry and compute shaders). On a headless "
    "Linux machine install Mesa's EGL driver: apt-get install -y libegl1 libgl1 libegl-mesa0 "
    "libgl1-mesa-dri"
)


def create_context(window: bool = False, require: int = MIN_GL) -> moderngl.Context:
    """Create an OpenGL context.

    Parameters
    ----------
    window : bool
        False (default): a standalone headless EGL context. True: wrap the context that a window
        toolkit (Qt, GLFW, moderngl-window) has made current.
    require : int
        Minimum OpenGL version as ``major*100 + minor*10``.

    Raises
    ------
    GLUnavailableError
        With one line saying what is missing and how to install it; also when the environment
        sets ``GEOSHADE_GL=off`` (what tests and CI use to act as a machine without EGL).
        ``GEOSHADE_GL_BACKEND`` picks moderngl's headless back end (``egl`` by default).
    """

    check_address_space(what="a headless OpenGL context")  # not SIGSEGV under a low ulimit -v
    try:
        if os.environ.get("GEOSHADE_GL", "").strip().lower() == "off":  # a machine without EGL
            raise RuntimeError("GEOSHADE_GL=off")
        if window:
            ctx = moderngl.create_context(require=require)
        else:
            backend = os.environ.get("GEOSHADE_GL_BACKEND", "egl")
            ctx = moderngl.create_context(standalone=True, backend=backend, require=require)
    except Exception as exc:  # moderngl/glcontext raise plain Exceptions
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise GLUnavailableError(f"no OpenGL >= {require // 100}.{require % 100 // 10} context: "
                                 f"{msg}. {_HINT}") from None
    if ctx.version_code < require:
        v = ctx.version_code
        ctx.release()
        raise GLUnavailableError(f"OpenGL {v // 100}.{v % 100 // 10} found, >= "
                                 f"{require // 100}.{require % 100 // 10} needed. {_HINT}")
    return ctx


def get_context() -> moderngl.Context:
    """The process-wide headless context (created on first use)."""
    global _SHARED
    if _SHARED is None:
        _SHARED = create_context()
    return _SHARED


def _gl_get_integer():
    """A ``glGetIntegerv`` callable resolved for the current context, or None."""
    proto = ctypes.CFUNCTYPE(None, ctypes.c_uint, ctypes.POINTER(ctypes.c_int))
    for lib, getter in (("EGL", "eglGetProcAddress"), ("GL", "glXGetProcAddress")):
        path = ctypes.util.find_library(lib)
        if not path:
            continue
        try:
            so = ctypes.CDLL(path)
            fn = getattr(so, getter)
        except (OSError, AttributeError):
            continue
        fn.restype = ctypes.c_void_p
        fn.argtypes = [ctypes.c_char_p]
        ptr = fn(b"glGetIntegerv")
        if ptr:
            return proto(ptr)
    return None


def _query_int(ctx: moderngl.Context, enum: int, default: int | None) -> int | None:
    getter = _gl_get_integer()
    if getter is None:
        return default
    val = ctypes.c_int(-1)
    getter(enum, ctypes.byref(val))
    err = ctx.error  # clears GL_INVALID_ENUM for unsupported queries
    return default if err != "GL_NO_ERROR" or val.value < 0 else int(val.value)


def is_software(ctx: moderngl.Context) -> bool:
    """True for CPU rasterisers (llvmpipe, softpipe, swrast)."""
    r = ctx.info.get("GL_RENDERER", "").lower()
    return any(s in r for s in ("llvmpipe", "softpipe", "swrast", "software"))


def gpu_memory_bytes(ctx: moderngl.Context) -> int | None:
    """Free video memory in bytes where the driver says (NVIDIA, AMD); None if unknown."""
    ext = ctx.extensions
    if "GL_NVX_gpu_memory_info" in ext:
        kb = _query_int(ctx, _GL_GPU_MEM_INFO_CURRENT_AVAILABLE_VIDMEM_NVX, None)
        return None if kb is None else kb * 1024
    if "GL_ATI_meminfo" in ext:
        kb = _query_int(ctx, _GL_TEXTURE_FREE_MEMORY_ATI, None)
        return None if kb is None else kb * 1024
    return None


def capabilities(ctx: moderngl.Context) -> dict:
    """The limits that matter to geoshade, as a JSON-friendly dict."""
    info = ctx.info
    return {
        "renderer": info.get("GL_RENDERER"),
        "vendor": info.get("GL_VENDOR"),
        "version": info.get("GL_VERSION"),
        "version_code": ctx.version_code,
        "software": is_software(ctx),
        "max_tess_gen_level": _query_int(ctx, _GL_MAX_TESS_GEN_LEVEL, 64),
        "max_geometry_output_vertices": info.get("GL_MAX_GEOMETRY_OUTPUT_VERTICES"),
        "max_geometry_total_output_components": _query_int(
            ctx, _GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS, 1024),
        "max_3d_texture_size": info.get("GL_MAX_3D_TEXTURE_SIZE"),
        "max_texture_size": info.get("GL_MAX_TEXTURE_SIZE"),
        "max_ssbo_bytes": info.get("GL_MAX_SHADER_STORAGE_BLOCK_SIZE"),
        "max_texture_buffer_size": info.get("GL_MAX_TEXTURE_BUFFER_SIZE"),
        "gpu_memory_free_bytes": gpu_memory_bytes(ctx),
    }


def format_capabilities(caps: dict) -> str:
    """Human-readable lines for ``geoshade info --gl``."""
    mem = caps.get("gpu_memory_free_bytes")
    lines = [
        f"renderer:                {caps['renderer']} ({caps['vendor']})",
        f"OpenGL:                  {caps['version']}",
        f"software rasteriser:     {'yes' if caps['software'] else 'no'}",
        f"max tessellation level:  {caps['max_tess_gen_level']}",
        f"max geometry output:     {caps['max_geometry_output_vertices']} vertices, "
        f"{caps['max_geometry_total_output_components']} components",
        f"max 3D texture size:     {caps['max_3d_texture_size']}",
        f"max SSBO block size:     {caps['max_ssbo_bytes']} bytes",
        f"free GPU memory:         {'unknown' if mem is None else f'{mem / 2**30:.2f} GiB'}",
    ]
    return "\n".join(lines)
