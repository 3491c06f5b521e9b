"""numba's ``njit`` when numba imports, else a decorator that leaves the function as it is.

Every kernel module takes ``njit`` from here, so that the kernels also import, and run as plain
Python on numpy arrays, in an interpreter without numba: the Siconos worker runs under Debian's
``/usr/bin/python3`` (numpy, no numba) and uses the gap, frame, quaternion and time-profile
kernels from this folder (``adapters/siconos/worker/geometry.py``). With numba, ``njit`` IS
``numba.njit``: the compiled code, its options (``cache``, ``inline``, ``error_model``) and its
results are those of a direct ``from numba import njit``.

Plain Python differs from the compiled code only where the kernels rely on numba's semantics:
with the default ``error_model="python"`` both raise ZeroDivisionError on a float division by
zero; a function compiled with ``error_model="numpy"`` returns inf / nan there, which plain
Python does on numpy scalars only. Transcendental functions may differ in the last ulp between
libm and LLVM's intrinsics (``tests/test_kernels_without_numba.py`` states the bounds).
"""

from __future__ import annotations

try:
    from numba import njit
except ImportError:  # no numba in this interpreter: the kernels run as plain Python
    NUMBA_AVAILABLE = False

    def njit(*args, **options):
        """Stand-in for ``numba.njit`` with its call forms: ``@njit``, ``@njit(**options)``,
        ``@njit(signature, **options)``; returns the decorated function unchanged."""
        if len(args) == 1 and callable(args[0]) and not options:
            return args[0]

        def decorate(function):
            return function

        return decorate
else:
    NUMBA_AVAILABLE = True

__all__ = ["NUMBA_AVAILABLE", "njit"]
