"""The ``pybullet`` module, imported without its banner.

PyBullet's C code prints "pybullet build time: ..." when the module is first imported (to
standard error in pybullet 3.2.7; to standard output in some builds), which pollutes CLI output
(``clearbench list``, every ``bench`` and ``run`` that touches PyBullet). The first import here
runs with file descriptors 1 and 2 sent to ``/dev/null``; the C library's buffers are flushed
before they come back, so the banner is dropped instead of surfacing later. Python errors of the
import still propagate as exceptions. Every PyBullet module of the adapter imports ``pb`` from
here.
"""

from __future__ import annotations

import ctypes
import os
import sys


def _import_quietly():
    """``import pybullet`` with descriptors 1 and 2 silenced during the import (ImportError
    passes)."""
    if "pybullet" in sys.modules:
        return sys.modules["pybullet"]
    sys.stdout.flush()
    sys.stderr.flush()
    libc = ctypes.CDLL(None)
    saved = {fd: os.dup(fd) for fd in (1, 2)}
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        for fd in saved:
            os.dup2(devnull, fd)
        import pybullet
    finally:
        libc.fflush(None)  # a banner on stdout sits in C's buffer when 1 is a pipe or file
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)
        os.close(devnull)
    return pybullet


pb = _import_quietly()

__all__ = ["pb"]
