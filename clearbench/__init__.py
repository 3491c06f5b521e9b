"""clearbench: a cross-validation harness for rigid-body contact simulators.

The sub-packages live in top-level folders of the repository and are installed under this
namespace: ``clearbench.kernels`` (the pure-math floor: quaternions, frames, gap kernels,
time profiles),
``clearbench.scenarios`` (engine-neutral scenes, geometry, analytic references),
``clearbench.ref_solver`` (our nonsmooth Moreau--Jean solver), ``clearbench.adapters`` (one
subpackage per engine) and ``clearbench.harness`` (runner, metrics, store, report, CLI).

Which sources determine what (:func:`source_digest`):

- a trajectory: the physics sources, :data:`PHYSICS_SUBPACKAGES` (kernels, scenarios,
  ref_solver, adapters), with the scene, the engine, its settings and its package's version
  (the run key, :attr:`clearbench.harness.run.spec.RunSpec.key`);
- a run's measurement (figures, expectations, status after the harness's checks): the
  trajectory and the measuring sources, :data:`MEASURING_SOURCES` (the measurement key);
- numba's compiled kernels: the physics sources too. Importing the package points numba's
  on-disk cache (``NUMBA_CACHE_DIR``, unless the user set it) at a directory named after
  their state and numba's code-generation settings, when set (:func:`numba_cache_dir`).
  numba keys a cached kernel on its own file only: a kernel that inlines a function from
  another module would otherwise keep running the old code after that module is edited (it
  did once, and hid a fix). The harness holds no kernel.

An edit of the harness's report, CLI or studies code therefore reruns no engine and
re-measures nothing; an edit of the measuring code re-measures the stored trajectories.
"""

import functools
import hashlib
import importlib.util
import json
import os
import shutil
from pathlib import Path

__version__ = "0.1.0"

#: The sub-packages whose sources determine a trajectory (with the scene, the engine, its
#: settings and version): the part of every run key that is code, and what numba's cache
#: directory is named after (they hold every kernel and what kernels inline). The harness is
#: not among them: its run phase only hands the spec to the engine (``harness/run/worker.py``).
PHYSICS_SUBPACKAGES = ("clearbench.kernels", "clearbench.scenarios", "clearbench.ref_solver",
                       "clearbench.adapters")

#: The sources that determine a run's measurement from its trajectory, beyond the physics
#: sources (the scene's geometry and expectations, the gap kernels): the measuring package
#: and the worker module whose measuring phase decides the run's status.
MEASURING_SOURCES = ("clearbench.harness.measure", "clearbench.harness.run.worker")


def _source_files(sources: tuple[str, ...]):
    """(name, path relative to its package, path) of every module of ``sources`` (packages
    with their own sub-packages, or single modules), in a fixed order."""
    for name in sources:
        spec = importlib.util.find_spec(name)
        if spec is None:
            continue
        if spec.submodule_search_locations is None:  # a module
            if spec.origin:
                path = Path(spec.origin)
                yield name, path.name, path
            continue
        for location in spec.submodule_search_locations:
            root = Path(location)
            for path in sorted(root.rglob("*.py")):
                yield name, path.relative_to(root).as_posix(), path


@functools.cache
def _sources_fingerprint() -> str:
    """Digest of the path, size and modification time of every source file of
    :data:`PHYSICS_SUBPACKAGES` [hex, 16 chars], computed once per process (every cache
    directory a process names is of one state)."""
    digest = hashlib.sha1(__version__.encode())
    for _, _, path in _source_files(PHYSICS_SUBPACKAGES):
        stat = path.stat()
        digest.update(f"{path}:{stat.st_size}:{stat.st_mtime_ns}\n".encode())
    return digest.hexdigest()[:16]


def source_digest(sources: tuple[str, ...] = PHYSICS_SUBPACKAGES) -> str:
    """sha256 of the sources of ``sources`` (packages or modules: relative path and content of
    every module) [hex, 16 chars], computed once per process and selection; the same on every
    clone of the same revision. The physics sources' digest is part of every run key, the
    measuring sources' of every measurement key (see the module docstring)."""
    if sources not in _SOURCE_DIGESTS:
        digest = hashlib.sha256(__version__.encode())
        for name, relative, path in _source_files(sources):
            digest.update(f"{name}/{relative}\n".encode())
            digest.update(path.read_bytes())
        _SOURCE_DIGESTS[sources] = digest.hexdigest()[:16]
    return _SOURCE_DIGESTS[sources]


_SOURCE_DIGESTS: dict[tuple[str, ...], str] = {}

#: Cache directories of earlier source states kept besides the current one.
_KEEP_CACHES = 4


#: numba settings that change the machine code it generates. numba keys a cached kernel on the
#: CPU name and features but not on the optimisation level: a process run with ``NUMBA_OPT=0``
#: would load the optimised code compiled before. A run with any of these set gets a cache
#: directory of its own.
NUMBA_CODEGEN_VARIABLES = ("NUMBA_OPT", "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES",
                           "NUMBA_FASTMATH", "NUMBA_LOOP_VECTORIZE", "NUMBA_SLP_VECTORIZE")

#: ``NUMBA_CACHE_DIR`` as the user gave it (None: chosen by :func:`numba_cache_dir`).
USER_NUMBA_CACHE_DIR = os.environ.get("NUMBA_CACHE_DIR") or None


def _checkout_cache_root() -> Path:
    # One folder per checkout: the pruning below must not delete the live cache of another
    # checkout (worktrees working side by side recompiled every kernel, or crashed on a cache
    # file removed under them, when they shared one folder).
    checkout = hashlib.sha1(str(Path(__file__).resolve().parent.parent).encode()).hexdigest()
    return Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) \
        / "clearbench-numba-checkouts" / checkout[:12]


def write_json(path: Path, data, **dumps_options) -> None:
    """Write ``data`` as JSON to ``path`` (its folder made) all at once: into a temporary file
    beside it, renamed over it, so that a reader or a process killed mid-write never leaves a
    torn file, and concurrent writers each leave a whole one. ``dumps_options`` go to
    :func:`json.dumps`. Raises OSError where the folder cannot be written."""
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    partial.write_text(json.dumps(data, **dumps_options), encoding="utf-8")
    partial.replace(path)


def checkout_cache_dir() -> Path:
    """The cache directory of this checkout and the state of its physics sources (those of
    :data:`PHYSICS_SUBPACKAGES`): numba's kernels and what is derived from those sources
    alone (the features of the registered scenes) live there; older states' are pruned."""
    return _checkout_cache_root() / _sources_fingerprint()


def numba_cache_dir(environ=None) -> Path:
    """numba's cache directory for this checkout, the state of its sources and the numba
    code-generation settings of ``environ`` (default ``os.environ``;
    :data:`NUMBA_CODEGEN_VARIABLES`): a sub-directory per combination of those that are set."""
    environ = os.environ if environ is None else environ
    current = checkout_cache_dir()
    codegen = [f"{name}={environ[name]}" for name in NUMBA_CODEGEN_VARIABLES
               if environ.get(name)]
    if codegen:
        slug = hashlib.sha1(";".join(codegen).encode()).hexdigest()[:12]
        current = current / f"codegen-{slug}"
    return current


def _set_numba_cache_dir() -> None:
    if USER_NUMBA_CACHE_DIR:
        return
    current = numba_cache_dir()
    os.environ["NUMBA_CACHE_DIR"] = str(current)
    root = _checkout_cache_root()
    try:
        older = sorted((d for d in root.iterdir() if d.name != current.relative_to(root).parts[0]),
                       key=lambda d: d.stat().st_mtime, reverse=True)
    except OSError:  # no cache yet
        return
    for stale in older[_KEEP_CACHES:]:
        shutil.rmtree(stale, ignore_errors=True)


_set_numba_cache_dir()
