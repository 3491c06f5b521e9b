"""Run a Siconos worker script under Debian's Python, isolated, with a time limit.

Siconos 4.4 (Debian ``python3-siconos``) imports only under /usr/bin/python3 with Debian's numpy
and an environment free of PYTHONPATH / virtual-environment variables, so every Siconos call
goes through a worker process. Inputs and outputs are .npz files; the worker's stdout is
ignored (Siconos prints noise there). A crash, a hang or a missing Siconos becomes a status.
"""

from __future__ import annotations

import enum
import functools
import json
import os
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import clearbench

#: Interpreter that has Debian's python3-siconos.
SICONOS_PYTHON = "/usr/bin/python3"

#: Environment variables passed to the worker (everything else is dropped).
_KEPT_VARIABLES = ("HOME", "LANG", "LC_ALL", "TMPDIR")


class WorkerStatus(enum.Enum):
    """How a worker run ended."""

    OK = "ok"
    FAILED = "failed"  # the worker reported an exception
    CRASHED = "crashed"  # killed by a signal or exited without an output file
    TIMED_OUT = "timed_out"
    UNAVAILABLE = "unavailable"  # Siconos cannot be imported here


@dataclass(frozen=True)
class WorkerOutcome:
    """Result of :func:`run_worker`: status, the output arrays, wall time of the process (s)."""

    status: WorkerStatus
    outputs: dict = field(default_factory=dict)
    process_time: float = 0.0
    returncode: int | None = None
    message: str = ""


def clean_environment() -> dict[str, str]:
    """A minimal environment for Debian's Python (no PYTHONPATH, no venv, no pyenv)."""
    env = {"PATH": "/usr/bin:/bin"}
    for name in _KEPT_VARIABLES:
        if name in os.environ:
            env[name] = os.environ[name]
    env.setdefault("HOME", tempfile.gettempdir())
    env["OMP_NUM_THREADS"] = "1"
    return env


def interpreter_imports(modules: str) -> tuple[bool, str]:
    """(True, "") when :data:`SICONOS_PYTHON` imports ``modules`` (``import`` syntax, e.g.
    ``"siconos.kernel, siconos.numerics"``) in the clean environment, else (False, why);
    never raises."""
    if not Path(SICONOS_PYTHON).exists():
        return False, f"Siconos unavailable: {SICONOS_PYTHON} not found"
    try:
        completed = subprocess.run(
            [SICONOS_PYTHON, "-c", f"import {modules}"], env=clean_environment(),
            capture_output=True, text=True, timeout=120,
        )
    except (OSError, subprocess.TimeoutExpired) as error:
        return False, f"Siconos unavailable: {error}"
    if completed.returncode != 0:
        last = (completed.stderr.strip().splitlines() or ["import failed"])[-1]
        return False, (f"Siconos unavailable ({last}); install Debian's python3-siconos "
                       "(`make siconos` as root)")
    return True, ""


#: What a run imports in Debian's interpreter.
SICONOS_MODULES = "siconos.kernel, siconos.mechanics.joints, siconos.numerics"
#: dpkg's file list of the installed ``python3-siconos``: rewritten by every install, upgrade
#: or removal of the package, so its size and modification time key the probe's answer.
DPKG_LIST = Path("/var/lib/dpkg/info/python3-siconos.list")


def _install_state() -> str | None:
    """Size and modification time of :data:`DPKG_LIST` and of the interpreter (None when
    dpkg did not install the package: then every call probes)."""
    try:
        stats = [DPKG_LIST.stat(), Path(SICONOS_PYTHON).stat()]
    except OSError:
        return None
    return ";".join(f"{s.st_size}:{s.st_mtime_ns}" for s in stats)


def _probe() -> tuple[bool, str]:
    available, why = interpreter_imports(SICONOS_MODULES)
    if not available:
        return False, why
    try:
        version = subprocess.run(
            ["dpkg-query", "-W", "-f=${Version}", "python3-siconos"],
            capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        version = ""
    return True, f"Debian python3-siconos {version}".strip() + f" under {SICONOS_PYTHON}"


@functools.cache
def siconos_availability() -> tuple[bool, str]:
    """(available, message): whether Debian's interpreter imports the Siconos kernel, joints
    and numerics, and the package's version. A probe starts that interpreter and imports
    Siconos (about a second); a positive answer is kept in the user's cache directory,
    keyed by the package's install state (:func:`_install_state`), so that listing engines
    and starting runs do not pay it each time. Never raises."""
    state = _install_state()
    path = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "clearbench" \
        / "siconos-availability.json"
    if state is not None:
        try:
            kept = json.loads(path.read_text())
            if kept.get("state") == state:
                return True, str(kept["detail"])
        except (OSError, ValueError, KeyError):
            pass
    available, detail = _probe()
    if available and state is not None:
        try:
            clearbench.write_json(path, {"state": state, "detail": detail})
        except OSError:  # an unwritable cache costs the probe next time
            pass
    return available, detail


def siconos_available() -> bool:
    """True if Debian's python3-siconos can be imported by :data:`SICONOS_PYTHON`."""
    return siconos_availability()[0]


def run_worker(script: str | Path, inputs: dict, timeout: float = 600.0) -> WorkerOutcome:
    """Run ``SICONOS_PYTHON script INPUT.npz OUTPUT.npz`` with a clean environment.

    Parameters
    ----------
    script : path of the worker script (of clearbench it may import only the kernels, by path:
        ``worker/project_kernels.py``).
    inputs : dict of arrays / scalars / strings saved to INPUT.npz.
    timeout : wall-clock limit of the process, seconds.
    """
    available, message = siconos_availability()
    if not available:
        return WorkerOutcome(WorkerStatus.UNAVAILABLE, message=message)
    with tempfile.TemporaryDirectory(prefix="clearbench-siconos-") as folder:
        input_path = Path(folder) / "input.npz"
        output_path = Path(folder) / "output.npz"
        np.savez(input_path, **inputs)
        start = time.perf_counter()
        try:
            completed = subprocess.run(
                [SICONOS_PYTHON, str(script), str(input_path), str(output_path)],
                env=clean_environment(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                text=True, timeout=timeout, cwd=folder,
            )
        except subprocess.TimeoutExpired:
            return WorkerOutcome(WorkerStatus.TIMED_OUT, process_time=time.perf_counter() - start,
                                 message=f"no answer within {timeout:g} s")
        elapsed = time.perf_counter() - start
        stderr_tail = "\n".join(completed.stderr.strip().splitlines()[-5:])
        if not output_path.exists():
            return WorkerOutcome(WorkerStatus.CRASHED, process_time=elapsed,
                                 returncode=completed.returncode,
                                 message=f"exit status {completed.returncode}: {stderr_tail}")
        with np.load(output_path, allow_pickle=False) as data:
            outputs = {key: data[key] for key in data.files}
    ok = bool(outputs.get("ok", False))
    return WorkerOutcome(
        WorkerStatus.OK if ok else WorkerStatus.FAILED, outputs=outputs, process_time=elapsed,
        returncode=completed.returncode, message=str(outputs.get("message", "")),
    )
