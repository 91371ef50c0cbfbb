"""OpenGL contexts, headless: which backend draws (`render.backend`) and a current context
of it. The draw itself (`renderer.draw`) knows nothing of how its context was made.

  - `egl`: through EGL, headless (no X server): a GPU's driver, or Mesa's software device;
  - `osmesa`: Mesa's OSMesa on the CPU (llvmpipe);
  - `auto`: EGL when an EGL device other than Mesa's software rasteriser exists, else OSMesa.

PyOpenGL binds one platform per process, when OpenGL is first imported: the backend is
chosen before that (`PYOPENGL_PLATFORM`), and a process already bound to the other one is
refused with a clear message. The two contexts are made through PyOpenGL's own EGL and
OSMesa bindings (>= 3.1.5: 3.1.0, which pyrender 0.1.45 pins, has no OSMesaCreateContextAttribs
and cannot upload half floats; docs/rendering.md says why pyrender is no longer used).
"""

from __future__ import annotations

import ctypes
import os
import sys

import numpy as np

BACKENDS = ("auto", "egl", "osmesa")
_EGL_EXTENSIONS = 0x3055  # EGL_EXTENSIONS, for eglQueryDeviceStringEXT


def check_pyopengl() -> None:
    import OpenGL

    version = tuple(int(p) for p in OpenGL.__version__.split(".")[:3] if p.isdigit())
    if version < (3, 1, 5):
        raise RuntimeError(
            f"PyOpenGL {OpenGL.__version__} has no OSMesaCreateContextAttribs and cannot upload half floats; "
            "install PyOpenGL>=3.1.5"
        )


def egl_devices() -> list[bytes]:
    """The extension string of each EGL device, in EGL's order ([] without libEGL or its
    device query). Read through ctypes, so that asking does not bind PyOpenGL's platform."""
    try:
        egl = ctypes.CDLL("libEGL.so.1")
    except OSError:
        return []
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    query_at, string_at = (
        egl.eglGetProcAddress(b"eglQueryDevicesEXT"),
        egl.eglGetProcAddress(b"eglQueryDeviceStringEXT"),
    )
    if not query_at or not string_at:
        return []
    query = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(ctypes.c_int))(query_at)
    string = ctypes.CFUNCTYPE(ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int)(string_at)
    n = ctypes.c_int(0)
    if not query(0, None, ctypes.byref(n)) or n.value < 1:
        return []
    devices = (ctypes.c_void_p * n.value)()
    if not query(n.value, devices, ctypes.byref(n)):
        return []
    return [string(devices[k], _EGL_EXTENSIONS) or b"" for k in range(n.value)]


def hardware_egl_device(extensions: list[bytes]) -> int | None:
    """Index of the first EGL device that is not Mesa's software rasteriser, or None."""
    for k, ext in enumerate(extensions):
        if b"EGL_MESA_device_software" not in ext.split():
            return k
    return None


def resolve_backend(backend: str) -> str:
    """`egl` or `osmesa` for a `render.backend` value (`auto`: EGL on a GPU, else OSMesa)."""
    if backend not in BACKENDS:
        raise ValueError(f"render.backend: expected one of {', '.join(BACKENDS)}, got {backend!r}")
    if backend == "auto":
        return "egl" if hardware_egl_device(egl_devices()) is not None else "osmesa"
    return backend


def _bind_platform(backend: str) -> None:
    """Make PyOpenGL use `backend`'s platform (before its first import), or refuse."""
    if "OpenGL.platform" not in sys.modules:
        os.environ["PYOPENGL_PLATFORM"] = backend
    check_pyopengl()
    import OpenGL.platform

    bound = type(OpenGL.platform.PLATFORM).__name__
    if not bound.lower().startswith(backend):
        raise RuntimeError(
            f"render backend {backend!r}: OpenGL in this process is already bound to {bound} "
            "(PyOpenGL uses one platform per process); render in a fresh process, or set "
            f"PYOPENGL_PLATFORM={backend} before anything imports OpenGL"
        )


def gl_context(backend: str, width: int, height: int) -> EGLContext | OSMesaContext:
    """A current OpenGL context of `backend` (`egl` or `osmesa`: resolve_backend)."""
    _bind_platform(backend)
    return OSMesaContext(width, height) if backend == "osmesa" else EGLContext()


class EGLContext:
    """OpenGL 4.1 core on an EGL device (no surface: the draw renders into its own
    framebuffer): the first device that is not Mesa's software rasteriser, else the first."""

    def __init__(self):
        from OpenGL import EGL as egl
        from OpenGL.EGL.EXT.device_base import eglQueryDevicesEXT
        from OpenGL.EGL.EXT.platform_base import eglGetPlatformDisplayEXT
        from OpenGL.EGL.EXT.platform_device import EGL_PLATFORM_DEVICE_EXT
        from OpenGL.raw.EGL._types import EGLDeviceEXT

        count = egl.EGLint()
        if not eglQueryDevicesEXT(0, None, ctypes.pointer(count)) or count.value < 1:
            raise RuntimeError(
                "render backend 'egl': no EGL device (install libegl1 with a driver: "
                "libegl-mesa0 for the CPU, the GPU vendor's for a GPU)"
            )
        devices = (EGLDeviceEXT * count.value)()
        eglQueryDevicesEXT(count.value, devices, ctypes.pointer(count))
        device = devices[hardware_egl_device(egl_devices()) or 0]
        self._egl = egl
        self._display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, None)
        major, minor, n_configs = egl.EGLint(), egl.EGLint(), egl.EGLint()
        config = egl.EGLConfig()
        # EGL_SURFACE_TYPE defaults to windows, which a device display has none of.
        wanted = (egl.EGLint * 5)(
            egl.EGL_SURFACE_TYPE, egl.EGL_PBUFFER_BIT, egl.EGL_RENDERABLE_TYPE, egl.EGL_OPENGL_BIT, egl.EGL_NONE
        )
        version = (egl.EGLint * 7)(
            egl.EGL_CONTEXT_MAJOR_VERSION, 4, egl.EGL_CONTEXT_MINOR_VERSION, 1,
            egl.EGL_CONTEXT_OPENGL_PROFILE_MASK, egl.EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, egl.EGL_NONE,
        )  # fmt: skip
        if not (
            egl.eglInitialize(self._display, major, minor)
            and egl.eglChooseConfig(self._display, wanted, ctypes.pointer(config), 1, n_configs)
            and n_configs.value > 0
            and egl.eglBindAPI(egl.EGL_OPENGL_API)
        ):
            raise RuntimeError("render backend 'egl': the EGL device has no OpenGL configuration")
        self._context = egl.eglCreateContext(self._display, config, egl.EGL_NO_CONTEXT, version)
        if not self._context:
            raise RuntimeError("render backend 'egl': no OpenGL 4.1 core context on the EGL device")
        self.make_current()

    def make_current(self) -> None:
        egl = self._egl
        if not egl.eglMakeCurrent(self._display, egl.EGL_NO_SURFACE, egl.EGL_NO_SURFACE, self._context):
            raise RuntimeError("render backend 'egl': eglMakeCurrent failed")

    def delete_context(self) -> None:
        self._egl.eglDestroyContext(self._display, self._context)
        self._egl.eglTerminate(self._display)


class OSMesaContext:
    """OpenGL 3.3 core in Mesa's OSMesa (llvmpipe), current on a width x height RGBA
    buffer of its own (the draw renders into its own framebuffer)."""

    def __init__(self, width: int, height: int):
        from OpenGL import osmesa

        attributes = (ctypes.c_int * 11)(
            osmesa.OSMESA_FORMAT, osmesa.OSMESA_RGBA, osmesa.OSMESA_DEPTH_BITS, 24,
            osmesa.OSMESA_PROFILE, osmesa.OSMESA_CORE_PROFILE,
            osmesa.OSMESA_CONTEXT_MAJOR_VERSION, 3, osmesa.OSMESA_CONTEXT_MINOR_VERSION, 3, 0,
        )  # fmt: skip
        self._osmesa = osmesa
        self._context = osmesa.OSMesaCreateContextAttribs(attributes, None)
        if not self._context:
            raise RuntimeError("render backend 'osmesa': no OpenGL 3.3 core context (is libOSMesa Mesa's?)")
        self._buffer = np.zeros((height, width, 4), np.uint8)
        self._size = (width, height)
        self.make_current()

    def make_current(self) -> None:
        from OpenGL import GL as gl

        if not self._osmesa.OSMesaMakeCurrent(self._context, self._buffer, gl.GL_UNSIGNED_BYTE, *self._size):
            raise RuntimeError("render backend 'osmesa': OSMesaMakeCurrent failed")

    def delete_context(self) -> None:
        self._osmesa.OSMesaDestroyContext(self._context)
