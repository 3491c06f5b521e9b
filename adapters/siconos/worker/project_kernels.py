"""The project's kernels (``clearbench.kernels``) for the worker, in either interpreter.

Within clearbench (the adapter side, the tests) this is a plain import. In the worker, run by
Debian's ``/usr/bin/python3`` where clearbench is not installed, the kernels folder is imported
by path as ``clearbench.kernels`` under an empty ``clearbench`` parent package: the kernels'
own imports (``clearbench.kernels.frames``) resolve, and nothing else of the project runs (its
other subpackages need numba, scipy and the rest of the project's environment). The folder is
found from this file's place: ``adapters/siconos/worker/`` -> ``../../../kernels``, in the
source tree (``adapters/`` and ``kernels/`` side by side) and in an installed ``clearbench/``
alike. Without numba the kernels run as plain Python (``kernels/jit.py``).
"""

import importlib.util
import os
import sys
import types

#: The project's kernels folder (``clearbench.kernels``).
KERNELS_FOLDER = os.path.normpath(os.path.join(
    os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, os.pardir, "kernels"))


def _import_kernels_by_path():
    """Register :data:`KERNELS_FOLDER` as the package ``clearbench.kernels``."""
    parent = types.ModuleType("clearbench")
    parent.__path__ = []  # an empty namespace: only the kernels are registered in it
    sys.modules["clearbench"] = parent
    spec = importlib.util.spec_from_file_location(
        "clearbench.kernels", os.path.join(KERNELS_FOLDER, "__init__.py"),
        submodule_search_locations=[KERNELS_FOLDER])
    package = importlib.util.module_from_spec(spec)
    sys.modules["clearbench.kernels"] = package
    spec.loader.exec_module(package)
    parent.kernels = package


if importlib.util.find_spec("clearbench") is None:  # Debian's Python: clearbench not installed
    _import_kernels_by_path()

from clearbench.kernels import gaps, quaternion, time_profiles  # noqa: E402

__all__ = ["KERNELS_FOLDER", "gaps", "quaternion", "time_profiles"]
