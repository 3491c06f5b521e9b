"""Side-by-side timing of a baseline revision and this one, in one session (``--against REV``).

On a machine shared with other work, two wall times measured at different moments cannot be
compared: only a ratio measured together can. :func:`side_by_side` runs the same reference
cases in two long-lived worker processes, one importing the baseline revision and one this
revision, alternately (baseline then current, then current then baseline, ...), and keeps every
time; :class:`Pair` gives the best of each side and their ratio.

The baseline is an export of the revision (``git archive``) under
``$XDG_CACHE_HOME/clearbench-against/<commit>/``, with its own virtual environment that sees the
export's packages (through a ``clearbench`` folder of links, the same namespace mapping as
``pyproject.toml``) and this environment's third-party packages, and its own numba cache. It is
built once per commit and reused.
"""

from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import tempfile
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

WORKER = Path(__file__).with_name("against_worker.py")


@dataclass(frozen=True)
class Case:
    """One benchmark case: a scene (with factory parameters), a preset, a horizon and a time
    step [scene time unit; None: the scene's]."""

    scene: str
    preset: str = "default"
    horizon: float | None = None
    parameters: dict = field(default_factory=dict)
    time_step: float | None = None

    def request(self) -> str:
        return json.dumps({"scene": self.scene, "parameters": self.parameters,
                           "preset": self.preset, "horizon": self.horizon,
                           "time_step": self.time_step}) + "\n"


@dataclass(frozen=True)
class Pair:
    """Every measurement of one case on both sides (dicts of :mod:`.against_worker`)."""

    case: Case
    baseline: list[dict]
    current: list[dict]

    @property
    def error(self) -> str | None:
        """The first error a side reported for this case (a run that raised, e.g. on a scene
        the baseline revision does not have), or None; a case with an error has no ratio."""
        for side, runs in (("baseline", self.baseline), ("this revision", self.current)):
            for run in runs:
                if "error" in run:
                    return f"{side}: {run['error']}"
        return None

    @staticmethod
    def _best(runs: list[dict]) -> dict:
        return min(runs, key=lambda run: run["stepping_seconds"])

    @property
    def best_baseline(self) -> dict:
        return self._best(self.baseline)

    @property
    def best_current(self) -> dict:
        return self._best(self.current)

    @property
    def speedup(self) -> float:
        """Best baseline stepping time over best current one (> 1: this revision is faster)."""
        return self.best_baseline["stepping_seconds"] / self.best_current["stepping_seconds"]


def repository_root() -> Path:
    """Top of the git work tree this package was imported from."""
    here = Path(__file__).resolve().parent
    out = subprocess.run(["git", "-C", str(here), "rev-parse", "--show-toplevel"],
                         capture_output=True, text=True, check=True)
    return Path(out.stdout.strip())


def resolve(revision: str, root: Path | None = None) -> str:
    """Full commit hash of ``revision`` (ValueError when git does not know it)."""
    root = root or repository_root()
    out = subprocess.run(["git", "-C", str(root), "rev-parse", "--verify", "--quiet",
                          f"{revision}^{{commit}}"], capture_output=True, text=True)
    if out.returncode != 0:
        raise ValueError(f"git does not know the revision {revision!r}")
    return out.stdout.strip()


def cache_root() -> Path:
    base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
    return base / "clearbench-against"


def _namespace_links(source: Path, shim: Path) -> None:
    """``shim/clearbench/<sub>`` -> ``source/<folder>`` for the top-level package mappings of
    the export's pyproject.toml (the files of ``source/clearbench`` linked one by one); relative
    links, so that the folder can be moved into place after it is built."""
    mapping = tomllib.loads((source / "pyproject.toml").read_text())["tool"]["setuptools"]
    package = shim / "clearbench"
    package.mkdir(parents=True)
    for name, folder in mapping.get("package-dir", {}).items():
        parts = name.split(".")
        if parts == ["clearbench"]:
            for item in (source / folder).iterdir():
                (package / item.name).symlink_to(os.path.relpath(item, package))
        elif len(parts) == 2 and parts[0] == "clearbench":
            (package / parts[1]).symlink_to(os.path.relpath(source / folder, package))


def baseline_environment(commit: str, root: Path | None = None) -> tuple[Path, dict]:
    """(python, environment) of the baseline ``commit``, built on first use (module docstring)."""
    root = root or repository_root()
    home = cache_root() / commit
    python = home / "venv" / "bin" / "python"
    if not (home / "ready").exists():
        cache_root().mkdir(parents=True, exist_ok=True)
        build = Path(tempfile.mkdtemp(prefix=f"{commit[:12]}-", dir=cache_root()))
        archive = subprocess.run(["git", "-C", str(root), "archive", "--format=tar", commit],
                                 capture_output=True, check=True).stdout
        source = build / "src"
        source.mkdir()
        with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
            tar.extractall(source, filter="data")
        _namespace_links(source, build / "shim")
        subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(build / "venv")],
                       check=True)
        purelib = subprocess.run(
            [str(build / "venv" / "bin" / "python"), "-c",
             "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
            capture_output=True, text=True, check=True).stdout.strip()
        (Path(purelib) / "clearbench_against.pth").write_text(
            f"{home / 'shim'}\n{sysconfig.get_paths()['purelib']}\n")
        (build / "ready").write_text(commit + "\n")
        if home.exists():
            shutil.rmtree(home)
        build.rename(home)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(home / "numba"))
    return python, env


class _Worker:
    """A worker process of :mod:`.against_worker` (one revision's interpreter)."""

    def __init__(self, python: Path | str, env: dict | None):
        self.process = subprocess.Popen([str(python), "-P", str(WORKER)], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True, env=env)

    def measure(self, case: Case) -> dict:
        """The worker's reply for ``case``: its measurement, or ``{"error": message}`` when
        the case raised there (RuntimeError when the worker process ended)."""
        self.process.stdin.write(case.request())
        self.process.stdin.flush()
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError(f"worker ended before answering {case}")
        return json.loads(line)

    def close(self) -> None:
        self.process.stdin.write("\n")
        self.process.stdin.close()
        self.process.wait(timeout=60)


def side_by_side(cases: list[Case], revision: str, repeat: int = 2, report=None) -> list[Pair]:
    """Measure every case ``repeat`` times on the baseline ``revision`` and on this revision,
    alternately, in one session; ``report(pair)`` is called as each case completes. A case that
    raises on either side is measured no further (its :attr:`Pair.error` says why)."""
    root = repository_root()
    python, env = baseline_environment(resolve(revision, root), root)
    baseline = _Worker(python, env)
    current = _Worker(sys.executable, None)
    pairs = []
    try:
        for case in cases:
            runs: dict[str, list[dict]] = {"baseline": [], "current": []}
            for i in range(repeat):
                order = (("baseline", baseline), ("current", current))
                for side, worker in order if i % 2 == 0 else order[::-1]:
                    runs[side].append(worker.measure(case))
                if any("error" in run for side_runs in runs.values() for run in side_runs):
                    break
            pair = Pair(case, runs["baseline"], runs["current"])
            pairs.append(pair)
            if report is not None:
                report(pair)
    finally:
        for worker in (baseline, current):
            worker.close()
    return pairs
