"""OpenGL contexts, headless: which backend draws (`render.backend`) and a current context
of it. The draw itself (`renderer.draw`) knows nothing of how its context was made.

  - `egl`: through EGL, headless (no X server): a GPU's driver, or Mesa's software device;
  - `osmesa`: Mesa's OSMesa on the CPU (llvmpipe);
  - `auto`: EGL when an EGL device other than Mesa's software rasteriser exists, else OSMesa.

PyOpenGL binds one platform per process, when OpenGL is first imported: the backend is
chosen before that (`PYOPENGL_PLATFORM`), and a process already bound to the other one is
refused with a clear message. pyrender provides the two contexts; its scene graph is not
used. pyrender pins PyOpenGL==3.1.0, whose OSMesa binding is broken (setup.sh installs
3.1.10; `check_pyopengl` refuses the old one), and uses NumPy 1's `np.infty` (restored).
"""

from __future__ import annotations

import ctypes
import os
import sys

import numpy as np

if not hasattr(np, "infty"):
    np.infty = np.inf  # pyrender 0.1.45 still uses the NumPy 1 alias

BACKENDS = ("auto", "egl", "osmesa")
_EGL_EXTENSIONS = 0x3055


def check_pyopengl() -> None:
    import OpenGL

    version = tuple(int(p) for p in OpenGL.__version__.split(".")[:3] if p.isdigit())
    if version < (3, 1, 5):
        raise RuntimeError(
            f"PyOpenGL {OpenGL.__version__} cannot drive OSMesa (pyrender pins 3.1.0); "
            "install PyOpenGL>=3.1.5 (bash setup.sh does)"
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


def gl_context(backend: str, width: int, height: int):
    """A current OpenGL context of `backend` (pyrender's platform object)."""
    _bind_platform(backend)
    if backend == "osmesa":
        from pyrender.platforms.osmesa import OSMesaPlatform

        platform = OSMesaPlatform(width, height)
    else:
        # pyrender imports pyglet for its viewer (unused here); pyglet's default windowing
        # needs X11's libraries, which a GPU server often lacks: its headless mode needs EGL only.
        os.environ.setdefault("PYGLET_HEADLESS", "true")
        from pyrender.platforms.egl import EGLPlatform, query_devices

        devices = query_devices()
        if not devices:
            raise RuntimeError(
                "render backend 'egl': no EGL device (install libegl1 with a driver: "
                "libegl-mesa0 for the CPU, the GPU vendor's for a GPU)"
            )
        platform = EGLPlatform(width, height, device=devices[hardware_egl_device(egl_devices()) or 0])
    platform.init_context()
    platform.make_current()
    return platform
