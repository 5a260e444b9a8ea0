"""pyrender's shader program cache keyed by a context's address, so that a frame compiles nothing.

pyrender's ``ShaderProgramCache.get_program`` keys its programs by
``(OpenGL.contextdata.getContext(), shader names, defines)``. On OSMesa (and
EGL) PyOpenGL returns the current context as a *new* ctypes pointer object
each call (``OSMesaContext_pointer``), which compares by identity: two
pointers to the same context are not equal. So the key never matches, and
every frame compiles and links a fresh shader program that is never deleted:
~0.4-0.8 MB of driver memory and a few milliseconds per frame (a 341-mesh
dataset run peaked at 15 GB). :func:`stabilise_program_cache` keys the cache
by the context's address (an ``int``) instead: one program per shader
variant for the renderer's whole life, freed by pyrender's own
``Renderer.delete`` (``ShaderProgramCache.clear``).
"""

from __future__ import annotations

import ctypes
import os

__all__ = ["context_key", "stabilise_program_cache"]


def context_key(context):
    """A hashable key equal for every handle to the same GL context: its address, for a ctypes pointer."""
    if isinstance(context, (ctypes._Pointer, ctypes.c_void_p)):
        return ("context", ctypes.cast(context, ctypes.c_void_p).value or 0)
    return context


def _stable_class():
    from OpenGL import contextdata
    from pyrender.shader_program import ShaderProgram, ShaderProgramCache

    class AddressKeyedProgramCache(ShaderProgramCache):
        """``ShaderProgramCache`` whose key holds the context's address, not a pointer object."""

        def get_program(self, vertex_shader, fragment_shader, geometry_shader=None, defines=None):
            # pyrender's get_program, with context_key() around the context (module docstring)
            defines = {} if defines is None else defines
            files = [x for x in (vertex_shader, fragment_shader, geometry_shader) if x is not None]
            names = [os.path.split(fn)[1] for fn in files]
            key = tuple(
                [context_key(contextdata.getContext())]
                + sorted([(s, 1) for s in names] + [(d, defines[d]) for d in defines])
            )
            if key not in self._program_cache:
                paths = [os.path.join(self.shader_dir, fn) for fn in files]
                if len(paths) == 2:
                    paths.append(None)
                vs, fs, gs = paths
                self._program_cache[key] = ShaderProgram(
                    vertex_shader=vs, fragment_shader=fs, geometry_shader=gs, defines=defines
                )
            return self._program_cache[key]

    return AddressKeyedProgramCache


_CLASS = []


def stabilise_program_cache(renderer) -> None:
    """Make pyrender ``Renderer`` ``renderer``'s program cache key by context address (module docstring).

    Only this instance is changed (its cache's class); programs already cached
    stay, under their old keys, and are deleted with the others.
    """
    if not _CLASS:
        _CLASS.append(_stable_class())
    cache = getattr(renderer, "_program_cache", None)
    if cache is not None and type(cache).__name__ == "ShaderProgramCache":
        cache.__class__ = _CLASS[0]
