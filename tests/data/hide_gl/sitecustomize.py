"""Makes the dynamic loader "miss" GL libraries in this interpreter (tests/test_gl_missing.py).

Python imports ``sitecustomize`` at start-up from ``PYTHONPATH``: with this folder there, every
``ctypes.CDLL`` of a library whose file name starts with ``lib<NAME>.`` for a NAME in
``$WIRECHECK_HIDE_LIBS`` (comma-separated; e.g. ``OSMesa`` or ``EGL``) raises the OSError the
loader raises for a library that is not installed. PyOpenGL loads its libraries through
``ctypes.CDLL``, so this is a machine without them, as far as wirecheck can tell.
"""

import ctypes
import os

_HIDDEN = [name for name in os.environ.get("WIRECHECK_HIDE_LIBS", "").split(",") if name]
_init = ctypes.CDLL.__init__


def _refuse(self, name, *args, **kwargs):
    if name and any(os.path.basename(str(name)).startswith(f"lib{h}.") for h in _HIDDEN):
        raise OSError(f"{name}: cannot open shared object file: No such file or directory")
    _init(self, name, *args, **kwargs)


ctypes.CDLL.__init__ = _refuse
