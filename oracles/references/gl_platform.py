"""The GL platform the pyrender oracle draws on: which (OSMesa or EGL), whether it loads here, and
what to install when it does not.

``PYOPENGL_PLATFORM`` is ``osmesa`` (the default, set here when unset) or
``egl`` (Mesa's EGL on the CPU, or a vendor's driver on a GPU);
:func:`select_gl` sets it (``crosscheck --gl``). It must be chosen before
PyOpenGL is imported. :func:`gl_library_problem` (and pyrender_oracle.gl_available) says in one line what is missing
and its fix (never ``pip install pyrender2`` for a missing system library).
"""

from __future__ import annotations

import os
import sys

from wirecheck.core.errors import InputError

#: The OpenGL platforms the oracle draws on (``PYOPENGL_PLATFORM``); the first is the default.
GL_PLATFORMS = ("osmesa", "egl")


class GLUnavailable(RuntimeError):
    """The pixel oracle cannot draw here: the message is one line naming the missing piece and its fix."""


INSTALL_HINT = {
    "osmesa": "apt-get install -y libosmesa6",
    "egl": "apt-get install -y libegl1 libegl-mesa0 libgl1-mesa-dri",
}


def gl_platform() -> str:
    """The platform pyrender draws on: ``PYOPENGL_PLATFORM``, set to ``osmesa`` when unset."""
    os.environ.setdefault("PYOPENGL_PLATFORM", GL_PLATFORMS[0])
    return os.environ["PYOPENGL_PLATFORM"]


def select_gl(name: str | None) -> str:
    """Set ``PYOPENGL_PLATFORM`` to ``name`` (None: keep it, default osmesa); return the platform.

    Raises InputError for a platform other than :data:`GL_PLATFORMS`, or when
    PyOpenGL was already loaded in this process for another one (it reads the
    variable once, at import).
    """
    if name is None:
        return gl_platform()
    if name not in GL_PLATFORMS:
        raise InputError(f"--gl {name!r}: expected one of {', '.join(GL_PLATFORMS)}")
    current = os.environ.get("PYOPENGL_PLATFORM")
    if "OpenGL.platform" in sys.modules and current != name:
        raise InputError(
            f"--gl {name}: OpenGL is already loaded in this process for {current!r}; "
            f"set PYOPENGL_PLATFORM={name} before it starts"
        )
    os.environ["PYOPENGL_PLATFORM"] = name
    return name


def gl_library_problem(platform: str) -> str | None:
    """One line saying why pyrender cannot draw on ``platform`` (with the install hint); None when it may.

    The platform must be one of :data:`GL_PLATFORMS`, its GL library must load
    and pyrender must import. On EGL that is not enough (libEGL may load with no
    usable device): :func:`oracles.references.pyrender_oracle.gl_available` then
    makes a 1x1 context.
    """
    if platform not in GL_PLATFORMS:
        return (
            f"PYOPENGL_PLATFORM={platform!r}; the pyrender oracle draws on {' or '.join(repr(p) for p in GL_PLATFORMS)}"
        )
    missing = _missing_gl_library(platform)
    if missing is not None:
        return missing
    try:
        import pyrender  # noqa: F401
    except Exception as exc:
        if "glGetError" in str(exc) or str(exc).startswith("Library "):  # a GL library PyOpenGL could not load
            return (
                f"OpenGL's library cannot be loaded on {platform} ({type(exc).__name__}: {exc}); "
                f"install it with: {INSTALL_HINT[platform]}"
            )
        return (
            f"pyrender cannot be imported ({type(exc).__name__}: {exc}); "
            "install it with: pip install 'pyrender2>=0.2,<1'"
        )
    return None


def _missing_gl_library(platform: str) -> str | None:
    """One line naming the GL library PyOpenGL cannot load on ``platform``, with its fix; None if all load.

    PyOpenGL leaves a missing library None and pyrender's import then fails with ``'NoneType' object
    has no attribute 'glGetError'``: so libOSMesa (with ``OSMesaCreateContextAttribs``, Mesa >= 11.2),
    or libEGL and libGL, are looked at here, before pyrender is imported."""
    hint = INSTALL_HINT[platform]
    try:
        from OpenGL import platform as gl_platform_module

        loaded = gl_platform_module.PLATFORM
    except Exception as exc:  # ImportError, OSError: the platform module itself cannot load
        return f"OpenGL cannot load its {platform} platform ({type(exc).__name__}: {exc}); install it with: {hint}"
    if platform == "osmesa":
        try:
            from OpenGL import osmesa  # noqa: F401 - PyOpenGL's binding: fails on some versions without the library
        except Exception as exc:  # ImportError, OSError, AttributeError
            msg = " ".join(f"{type(exc).__name__}: {exc}".split())[:200]
            return f"libOSMesa cannot be loaded ({msg}); install it with: {hint}"
        lib = _loaded(loaded, "GL")
        if lib is None:
            return f"libOSMesa cannot be loaded (no libOSMesa.so found); install it with: {hint}"
        if not hasattr(lib, "OSMesaCreateContextAttribs"):
            return (
                f"libOSMesa ({getattr(lib, '_name', '?')}) lacks OSMesaCreateContextAttribs (Mesa "
                f"before 11.2: no core-profile context for pyrender); install a newer one with: {hint}"
            )
        return None
    if _loaded(loaded, "EGL") is None:
        return f"libEGL cannot be loaded (no libEGL.so found: Mesa's EGL); install it with: {hint}"
    gl = _loaded(loaded, "GL")
    if gl is None or "GLES" in str(getattr(gl, "_name", "")):  # PyOpenGL falls back to GLES: not enough
        return (
            "libGL / libOpenGL cannot be loaded (no libGL.so found); install it with: "
            "apt-get install -y libgl1 libopengl0"
        )
    return None


def _loaded(platform_object, name: str):
    """``platform_object.<name>`` (a ctypes library, loaded on first access), or None when it cannot load."""
    try:
        return getattr(platform_object, name)
    except Exception:  # ImportError, OSError: PyOpenGL's lazy properties raise on some versions
        return None
