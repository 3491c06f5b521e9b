"""Run many :class:`~.spec.RunSpec` in isolated worker processes, in parallel, into a store.

Each run executes in a worker process started with the ``spawn`` context (by default a fresh
one per run: ``runs_per_worker=1``). The parent waits on the workers' pipes and process
sentinels, so that

- a worker that dies (segfault, abort, out of memory) gives a ``crashed`` run with the signal;
- a worker past its wall-clock limit is killed (its whole process group) and gives ``timed_out``;
- an exception in an engine gives ``crashed`` with the exception; non-finite values ``diverged``;

and the parent carries on with the rest of the sweep. A run is written to the results store only
once complete (outcome and metrics), in one transaction, under its deterministic key; runs whose
key is already in the store are skipped (served from it), except crashed ones, which are run
again (:data:`~.store.RERUN_STATUSES`), so a sweep interrupted even by ``kill -9`` resumes
without losing or duplicating runs. A stored run whose measurement key differs (the measuring
code changed, :attr:`~.spec.RunSpec.measure_key`) is served too, after a worker measured its
stored trajectory again. The messages between the parent, its workers and the store are the
dataclasses of :mod:`.messages`.
"""

from __future__ import annotations

import dataclasses
import logging
import multiprocessing
import multiprocessing.connection
import os
import signal
import time
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import clearbench
from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.run.messages import MeasuredMessage, RanMessage, WorkerRequest
from clearbench.harness.run.spec import RunSpec
from clearbench.harness.run.store import ResultsStore, RunRecord, machine_info, revision_info
from clearbench.harness.run.worker import worker_main

LOG = logging.getLogger(__name__)

#: Wall-clock limit of the measuring phase of one run [s].
MEASURE_TIMEOUT = 600.0
#: Seconds to wait for a worker to exit after it was asked to.
EXIT_GRACE = 5.0
#: Runs a worker process serves before it is replaced (a crashed or timed-out one always is)
#: where many runs are made (compare, demo, regress, campaigns): a fresh process per run spends
#: about 1.5 s starting, importing its engine and loading the compiled kernels (more on a loaded
#: machine), while a run in a reused worker gives the same trajectory bit for bit
#: (docs/harness.md, "Isolation").
MANY_RUNS_PER_WORKER = 20


def default_jobs() -> int:
    """Cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


@dataclass
class RunJob:
    """A spec to run, and the trajectory its error is measured against (if any).

    A ``warm_up`` job fills numba's cache of its engine for the jobs after it: it is started
    before any other job of its engine, one at a time, while the other workers run other
    engines' jobs; its result is not stored nor counted (:meth:`Runner.run_all`). A
    ``remeasure`` job (made by :meth:`Runner.run_all`) measures the stored trajectory of its
    run again and runs nothing."""

    spec: RunSpec
    reference_key: str | None = None
    warm_up: bool = False
    remeasure: bool = False


@dataclass
class _Slot:
    process: multiprocessing.process.BaseProcess
    conn: multiprocessing.connection.Connection
    runs_done: int = 0
    job: RunJob | None = None
    phase: str = ""
    deadline: float = 0.0
    started: float = 0.0
    ran: RanMessage | None = None
    trajectory_tmp: Path | None = None


@dataclass
class SweepOutcome:
    """What :func:`run_all` did: keys run now, keys served from the store (``skipped``; those
    of them whose stored trajectory was measured again also in ``remeasured``), records
    written (runs made now)."""

    ran: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    records: list[RunRecord] = field(default_factory=list)
    remeasured: list[str] = field(default_factory=list)

    def extend(self, other: SweepOutcome) -> None:
        """Add what ``other`` did."""
        self.ran += other.ran
        self.skipped += other.skipped
        self.records += other.records
        self.remeasured += other.remeasured

    def summary(self) -> str:
        """``"N runs done, M reused from the store (K measured again)"``."""
        again = f" ({len(self.remeasured)} measured again)" if self.remeasured else ""
        return (f"{len(self.ran)} runs done, {len(self.skipped)} reused from the store"
                + again)


def _signal_name(exitcode: int | None) -> str:
    if exitcode is None:
        return "unknown exit"
    if exitcode < 0:
        try:
            return f"killed by signal {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"killed by signal {-exitcode}"
    return f"exited with status {exitcode}"


class Runner:
    """Runs jobs in ``jobs`` parallel worker processes into ``store``.

    Parameters
    ----------
    store : ResultsStore
    jobs : int
        Parallel workers (default: the cores this process may use).
    runs_per_worker : int
        Runs a worker serves before it is replaced (1: a fresh process per run). A worker that
        crashed or timed out is always replaced.
    progress : bool
        Show a tqdm progress bar on stderr.
    measure_timeout : float
        Wall-clock limit of the measuring phase [s].
    environment : mapping of str to str, optional
        Variables set in the workers' environment over this process's own (e.g.
        ``{"NUMBA_CPU_NAME": "generic"}``; :func:`worker_environment`). None: the workers
        inherit this process's environment unchanged.
    on_finished : callable, optional
        Called after each run is recorded as ``on_finished(done, total, spec, record)``:
        ``done`` runs of the ``total`` this :meth:`run_all` call runs (those served from the
        store not counted). The CLI prints a progress line with it.
    keep_workers : bool
        Keep the worker processes between :meth:`run_all` calls (each still replaced after
        ``runs_per_worker`` runs, a crash or a timeout), until :meth:`close`: a caller that
        runs one job per call (a campaign's Dask task) keeps its workers warm. The ``store``
        attribute may be changed between calls.
    """

    def __init__(self, store: ResultsStore, jobs: int | None = None, runs_per_worker: int = 1,
                 progress: bool = False, measure_timeout: float = MEASURE_TIMEOUT,
                 environment: Mapping[str, str] | None = None,
                 on_finished: Callable[[int, int, RunSpec, RunRecord], None] | None = None,
                 keep_workers: bool = False):
        self.store = store
        self.keep_workers = keep_workers
        # Trajectory files of runs a killed sweep left half written (``.KEY.PID.tmp.npz``).
        store.clean_partial_files()
        self.environment = worker_environment(environment)
        self.jobs = max(1, int(jobs or default_jobs()))
        self.runs_per_worker = max(1, int(runs_per_worker))
        self.progress = progress
        self.on_finished = on_finished
        self.measure_timeout = measure_timeout
        self._context = multiprocessing.get_context("spawn")
        self._slots: list[_Slot] = []
        self._revision = revision_info()
        self._machine = machine_info()

    # ------------------------------------------------------------------ workers
    def _start_worker(self) -> _Slot:
        parent_conn, child_conn = self._context.Pipe(duplex=True)
        process = self._context.Process(target=worker_main, args=(child_conn, os.getpid()),
                                        daemon=True, name="clearbench-worker")
        with _environment_set(self.environment):   # a spawned process copies os.environ
            process.start()
        child_conn.close()
        return _Slot(process, parent_conn)

    def _kill(self, slot: _Slot) -> None:
        pid = slot.process.pid
        if pid is not None and slot.process.is_alive():
            try:
                os.killpg(pid, signal.SIGKILL)  # the worker leads its own process group
            except (ProcessLookupError, PermissionError):
                slot.process.kill()
        slot.process.join(EXIT_GRACE)
        slot.conn.close()

    def _retire(self, slot: _Slot) -> None:
        try:
            slot.conn.send(None)
        except (BrokenPipeError, OSError):
            pass
        slot.process.join(EXIT_GRACE)
        if slot.process.is_alive():
            self._kill(slot)
        else:
            slot.conn.close()

    def close(self) -> None:
        """Stop every worker."""
        for slot in self._slots:
            if slot.job is not None:
                self._kill(slot)
            else:
                self._retire(slot)
        self._slots = []

    # ------------------------------------------------------------------ running
    def run_all(self, jobs: Iterable[RunJob | RunSpec], rerun: bool = False) -> SweepOutcome:
        """Run every job whose key is not yet in the store, or stored as crashed
        (:data:`~.store.RERUN_STATUSES`; every job with ``rerun``).

        Jobs with the same key are run once. Returns what was run and what was skipped (served
        from the store; a stored run whose measurement key differs is measured again from its
        trajectory first). Warm-up jobs (:class:`RunJob`) run first for their engine, always,
        and are not stored: from an empty cache one worker compiles an engine's kernels once,
        instead of every worker compiling the same kernels side by side, and the other
        workers go on with other engines' runs meanwhile.
        """
        outcome = SweepOutcome()
        queue: deque[RunJob] = deque()
        seen: set[str] = set()
        stored = self.store.reusable()
        for job in jobs:
            job = job if isinstance(job, RunJob) else RunJob(job)
            key = job.spec.key
            if key in seen:
                continue
            seen.add(key)
            if job.warm_up:
                queue.append(job)
            elif key in stored and not rerun:
                outcome.skipped.append(key)
                if stored[key] != job.spec.measure_key:
                    queue.append(dataclasses.replace(job, remeasure=True))
            else:
                queue.append(job)
        if not queue:
            return outcome
        bar = None
        if self.progress:
            from tqdm import tqdm  # lazy: only for an interactive progress bar

            bar = tqdm(total=len(queue), unit="run", desc="runs", leave=False)
        completed = False
        try:
            self._loop(queue, outcome, bar)
            completed = True
        finally:
            if bar is not None:
                bar.close()
            if not (completed and self.keep_workers):
                self.close()
        return outcome

    def _dispatch(self, slot: _Slot, job: RunJob) -> None:
        spec = job.spec
        if job.remeasure:
            tmp = None
            trajectory = self.store.trajectory_path(spec.key)
        else:
            tmp = self.store.trajectory_dir / f".{spec.key}.{os.getpid()}.tmp.npz"
            trajectory = tmp
        reference = ""
        if job.reference_key:
            path = self.store.trajectory_path(job.reference_key)
            reference = str(path) if path.exists() else ""
        request = WorkerRequest.of(
            spec, str(trajectory), reference_path=reference,
            reference_label=f"reference run {job.reference_key}" if reference else "",
            measure_only=job.remeasure)
        slot.job, slot.ran, slot.trajectory_tmp = job, None, tmp
        slot.phase = "measure" if job.remeasure else "run"
        slot.started = time.monotonic()
        slot.deadline = slot.started + (self.measure_timeout if job.remeasure else spec.timeout)
        slot.conn.send(request)

    def _loop(self, queue: deque, outcome: SweepOutcome, bar) -> None:
        total = sum(not (job.warm_up or job.remeasure) for job in queue)
        while queue or any(s.job is not None for s in self._slots):
            # fill idle slots
            while queue and (len(self._slots) < self.jobs
                             or any(s.job is None for s in self._slots)):
                job = self._next_ready(queue)
                if job is None:
                    break
                idle = next((s for s in self._slots if s.job is None), None)
                if idle is None:
                    idle = self._start_worker()
                    self._slots.append(idle)
                self._dispatch(idle, job)
            busy = [s for s in self._slots if s.job is not None]
            now = time.monotonic()
            wait_for = max(0.0, min(s.deadline for s in busy) - now)
            handles = [s.conn for s in busy] + [s.process.sentinel for s in busy]
            multiprocessing.connection.wait(handles, timeout=min(wait_for, 1.0))
            for slot in busy:
                job = slot.job
                finished = self._service(slot)
                if finished is not None and job.warm_up:
                    self._finish_warm_up(slot, finished)
                elif finished is not None and job.remeasure:
                    self._finish_remeasure(slot, finished, outcome)
                elif finished is not None:
                    record = self._finish(slot, finished, outcome)
                    if self.on_finished is not None:
                        self.on_finished(len(outcome.ran), total, finished.spec, record)
                    if bar is not None:
                        bar.update(1)
                        bar.set_postfix_str(f"{finished.spec.label}: {record.status}",
                                            refresh=False)

    def _next_ready(self, queue: deque) -> RunJob | None:
        """Take out of ``queue`` the first job that may start: a warm-up job while no other
        warm-up of its engine runs, else a job whose engine has no warm-up queued or running
        and whose reference run (the trajectory its error is measured against) is not still
        queued or running in this batch; None when every queued job waits for one that is
        running. So one batch may hold warm-ups, fine references and the runs measured against
        them, in any order of workers."""
        running_jobs = [s.job for s in self._slots if s.job is not None]
        warming = {job.spec.engine.name for job in running_jobs if job.warm_up}
        gated = warming | {job.spec.engine.name for job in queue if job.warm_up}
        first = queue[0]
        if not first.warm_up and first.reference_key is None \
                and first.spec.engine.name not in gated:
            return queue.popleft()  # the common case, without hashing every queued key
        running = [job.spec.key for job in running_jobs]
        waiting = {job.spec.key for job in queue}.union(running)
        for index, job in enumerate(queue):
            engine = job.spec.engine.name
            if job.warm_up:
                ready = engine not in warming
            else:
                ready = engine not in gated and (job.reference_key is None
                                                 or job.reference_key not in waiting)
            if ready:
                del queue[index]
                return job
        return None if running else queue.popleft()

    def _finish_warm_up(self, slot: _Slot, finished: _Finished) -> None:
        """A warm-up job is over: its worker goes on serving, its result is dropped (a
        warm-up that failed is logged; the jobs it gated compile for themselves)."""
        self._release(slot, finished)
        tmp = finished.trajectory_tmp
        if tmp is not None and tmp.exists():
            tmp.unlink()
        if finished.ran.status != RunStatus.OK.value:
            LOG.warning("warm-up %s: %s %s", finished.spec.label, finished.ran.status,
                        finished.ran.message)

    def _finish_remeasure(self, slot: _Slot, finished: _Finished,
                          outcome: SweepOutcome) -> None:
        """A stored run was measured again: its row takes the new measurement."""
        self._release(slot, finished)
        spec = finished.spec
        row = self.store.get(spec.key)
        if row is None:  # removed meanwhile: nothing to update
            return
        self.store.remeasure(RunRecord.from_row(row).measured(finished.measured,
                                                             spec.measure_key))
        outcome.remeasured.append(spec.key)

    def _service(self, slot: _Slot):
        """Advance ``slot``; return a _Finished when its run is complete."""
        job = slot.job
        assert job is not None
        try:
            while slot.conn.poll():
                message = slot.conn.recv()
                if isinstance(message, RanMessage):
                    slot.ran = message
                    slot.phase = "measure"
                    slot.deadline = time.monotonic() + self.measure_timeout
                elif isinstance(message, MeasuredMessage):
                    slot.runs_done += 1
                    return _Finished(job.spec, slot.ran or RanMessage(), message,
                                     slot.trajectory_tmp, worker_ok=True)
        except (EOFError, OSError):
            pass  # the worker died; handled below
        if not slot.process.is_alive() or slot.conn.closed:
            slot.process.join(EXIT_GRACE)
            why = _signal_name(slot.process.exitcode)
            return self._abandon(slot, RunStatus.CRASHED, f"worker {why}")
        if time.monotonic() > slot.deadline:
            limit = job.spec.timeout if slot.phase == "run" else self.measure_timeout
            self._kill(slot)
            return self._abandon(slot, RunStatus.TIMED_OUT,
                                 f"wall-clock limit of {limit:g} s reached", killed=True)
        return None

    def _abandon(self, slot: _Slot, status: RunStatus, message: str, killed: bool = False):
        """The worker died or was killed: the run is over, the worker is replaced."""
        if not killed:
            self._kill(slot)
        elapsed = time.monotonic() - slot.started
        if slot.phase == "run":
            ran = RanMessage(status=status.value, message=message, worker_seconds=elapsed)
            measured = MeasuredMessage()
        else:  # the run finished (or was stored); its measuring died
            ran = slot.ran or RanMessage()
            measured = MeasuredMessage(metrics_error=f"measuring {status.value}: {message}")
        finished = _Finished(slot.job.spec, ran, measured, slot.trajectory_tmp, worker_ok=False)
        self._slots.remove(slot)
        return finished

    def _release(self, slot: _Slot, finished: _Finished) -> None:
        """The slot of a finished job serves the next one, or its worker retires after
        ``runs_per_worker`` runs (a worker that died was removed already)."""
        if finished.worker_ok:
            slot.job = None
            if slot.runs_done >= self.runs_per_worker:
                self._retire(slot)
                self._slots.remove(slot)

    def _finish(self, slot: _Slot, finished: _Finished, outcome: SweepOutcome) -> RunRecord:
        spec = finished.spec
        self._release(slot, finished)
        record = RunRecord.from_messages(spec, finished.ran, finished.measured,
                                         self._revision, self._machine)
        tmp = finished.trajectory_tmp
        saved = finished.ran.trajectory_saved and tmp is not None and tmp.exists()
        # Replacing: a rerun, or a run stored as crashed that was run again.
        self.store.record(record, trajectory_file=tmp if saved else None, replace=True,
                          scene=spec.scene)
        if tmp is not None and tmp.exists():
            tmp.unlink()
        outcome.ran.append(spec.key)
        outcome.records.append(record)
        LOG.info("%s: %s %s", spec.label, record.status, record.message)
        return record


def worker_environment(overrides: Mapping[str, str] | None) -> dict[str, str]:
    """The variables to set in a worker's environment for ``overrides``: those, plus a numba
    cache directory of their own when they change numba's code generation (numba would
    otherwise serve kernels compiled under other settings; :func:`clearbench.numba_cache_dir`),
    unless the user chose the cache directory."""
    environment = {str(name): str(value) for name, value in (overrides or {}).items()}
    if (any(name in clearbench.NUMBA_CODEGEN_VARIABLES for name in environment)
            and not clearbench.USER_NUMBA_CACHE_DIR and "NUMBA_CACHE_DIR" not in environment):
        environment["NUMBA_CACHE_DIR"] = str(clearbench.numba_cache_dir(
            {**os.environ, **environment}))
    return environment


@contextmanager
def _environment_set(variables: Mapping[str, str]):
    """``os.environ`` with ``variables`` set, restored on exit."""
    saved = {name: os.environ.get(name) for name in variables}
    os.environ.update(variables)
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


@dataclass
class _Finished:
    spec: RunSpec
    ran: RanMessage
    measured: MeasuredMessage
    trajectory_tmp: Path | None
    worker_ok: bool

