"""Running a campaign on Dask, resumably: every sample is one isolated run in the results store.

The client (this process) plans every sample's :class:`~clearbench.harness.run.spec.RunSpec`
(validating all of them before anything runs), skips the samples whose run key is already in
the store, and submits the rest to a Dask cluster: a ``LocalCluster`` on this machine by default,
or an existing scheduler given by address (e.g. one started by dask-jobqueue on SLURM, PBS or
OAR). On a worker, a task runs its sample with the harness's own :class:`Runner` in a private
temporary store, and returns the run's row and trajectory. The Runner's run process, with the
run's wall-clock limit (a crash, hang or divergence is a recorded status), is kept warm between
the tasks of a Dask worker and replaced after ``runs_per_worker`` runs, a crash or a timeout:
samples after a worker's first do not pay a fresh interpreter's start, imports and kernel
loading. The client alone writes to the campaign's store, one transaction per sample, as
results arrive.

Hence a campaign killed at any point (``kill -9`` of the client, a lost Dask worker) resumes
with no sample lost or recorded twice: a sample is either in the store, complete, or it is run
again on the next call. Dask itself reschedules the task of a lost worker; a task that kills its
workers repeatedly is recorded as a crashed run with Dask's message.

Every recorded sample appends a line to ``<store>/campaigns/<name>.jsonl`` (sample index, key,
status, wall times, completion time, session), from which the report takes samples per hour.
The store comes first: a sample a killed client stored but did not log is logged by the next
call, marked ``recovered`` (:meth:`CampaignLog.recover`).
"""

from __future__ import annotations

import ctypes
import json
import logging
import multiprocessing
import signal
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable
from dataclasses import asdict, dataclass
from datetime import UTC, datetime

import numpy as np

from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.run.engine_choice import RunInputError, resolve_engine
from clearbench.harness.run.messages import MeasuredMessage, RanMessage
from clearbench.harness.run.runner import MANY_RUNS_PER_WORKER, Runner
from clearbench.harness.run.spec import DEFAULT_TIMEOUT, RunSpec, make_run_spec
from clearbench.harness.run.store import ResultsStore, RunRecord, machine_info, revision_info
from clearbench.harness.studies.campaign.definition import CampaignDefinition, CampaignError
from clearbench.harness.studies.campaign.designs import sample_inputs, scene_parameters

LOG = logging.getLogger(__name__)

#: Prefix of the ``campaign`` column of the runs a campaign records.
CAMPAIGN_TAG = "campaign:"


@dataclass(frozen=True)
class CampaignSample:
    """One sample: its index, its input values (d,) [inputs' units] and its run."""

    index: int
    inputs: np.ndarray
    spec: RunSpec


def plan_samples(definition: CampaignDefinition, start: int = 0,
                 count: int | None = None) -> list[CampaignSample]:
    """The samples ``start .. start + count - 1`` with their validated runs.

    Raises
    ------
    CampaignError
        An engine, scene, parameter or output that cannot run, naming the campaign field.
    """
    return plan_points(definition, sample_inputs(definition, start, count), start)


def plan_points(definition: CampaignDefinition, values: np.ndarray,
                start: int = 0) -> list[CampaignSample]:
    """Samples at given input values (m, d) [inputs' units], indexed from ``start`` (a
    metamodel's confirmation runs), with their validated runs (see :func:`plan_samples`)."""
    try:
        choice = resolve_engine(definition.engine)
    except RunInputError as error:
        raise CampaignError("engine", definition.engine, error.reason) from None
    samples = []
    for offset, row in enumerate(values):
        index = start + offset
        parameters = scene_parameters(definition, row)
        try:
            spec = make_run_spec(
                definition.scene, definition.engine, scene_parameters=parameters,
                time_step=definition.time_step, horizon=definition.horizon,
                record_every=definition.record_every,
                timeout=definition.timeout or DEFAULT_TIMEOUT, engine_choice=choice,
                campaign=CAMPAIGN_TAG + definition.name)
        except RunInputError as error:
            raise CampaignError(f"sample {index} ({error.field})", error.value,
                                error.reason) from None
        samples.append(CampaignSample(index, row, spec))
    if samples:
        _check_outputs(definition, samples[0].spec)
    return samples


def _check_outputs(definition: CampaignDefinition, spec: RunSpec) -> None:
    names = [output.name for output in spec.scene.outputs]
    for index, output in enumerate(definition.outputs):
        if output.output not in names:
            raise CampaignError(f"outputs[{index}].output", output.output,
                                f"not an output of scene {spec.scene.name}; its outputs: "
                                + ", ".join(names))
        if output.window and output.window >= spec.horizon:
            raise CampaignError(f"outputs[{index}].window", output.window,
                                f"must be shorter than the run ({spec.horizon:g})")


# ---------------------------------------------------------------------- the worker side
#: This Dask worker's Runners, kept between tasks: one per worker thread (a Runner serves one
#: call at a time) and number of runs per run process.
_WARM_RUNNERS: dict[tuple[int, int], Runner] = {}


def execute_run(spec: RunSpec, runs_per_worker: int = MANY_RUNS_PER_WORKER) -> dict:
    """Run one sample on a Dask worker; return its store row and trajectory file's bytes.

    The run goes through the harness's :class:`Runner` in a private temporary store: a run
    process with the run's wall-clock limit, so the engine's failures are statuses. The run
    process serves ``runs_per_worker`` samples of this Dask worker (1: a fresh one per sample).
    """
    if multiprocessing.current_process().daemon:
        raise RuntimeError("this Dask worker is a daemonic process, which may not start the "
                           "run's own process: start the workers with the Dask setting "
                           "distributed.worker.daemon = False (environment variable "
                           "DASK_DISTRIBUTED__WORKER__DAEMON=False)")
    with tempfile.TemporaryDirectory(prefix="clearbench-campaign-") as folder:
        store = ResultsStore(folder)
        key = (threading.get_ident(), runs_per_worker)
        runner = _WARM_RUNNERS.get(key)
        if runner is None:
            runner = _WARM_RUNNERS[key] = Runner(store, jobs=1, runs_per_worker=runs_per_worker,
                                                 progress=False, keep_workers=True)
        runner.store = store
        runner.run_all([spec])
        row = store.get(spec.key)
        path = store.trajectory_path(spec.key)
        data = path.read_bytes() if path.exists() else None
    return {"row": row, "trajectory": data}


def _die_with_parent() -> None:
    """Ask Linux to kill this process when its parent dies (a LocalCluster's nannies and
    workers must not outlive a client killed with SIGKILL)."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # pragma: no cover - not Linux
        pass


# ---------------------------------------------------------------------- the client side
def local_cluster(workers: int):
    """A LocalCluster of ``workers`` single-threaded worker processes that may start child
    processes (each run has its own) and die with this process (their nannies live in it)."""
    import dask  # lazily: only campaigns need Dask
    from distributed import LocalCluster, WorkerPlugin

    class _WorkerDiesWithClient(WorkerPlugin):
        name = "clearbench-worker-dies-with-client"

        def setup(self, worker):
            _die_with_parent()

    # the scheduler runs in this process: its INFO lines are not the user's business
    logging.getLogger("distributed").setLevel(max(logging.WARNING, LOG.getEffectiveLevel()))
    # for the cluster's whole life: a nanny restarting a lost worker reads it again
    dask.config.set({"distributed.worker.daemon": False})
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=logging.ERROR)
    return cluster, (_WorkerDiesWithClient(),)


class CampaignLog:
    """Append-only JSON-lines log of a campaign's sessions and recorded samples."""

    def __init__(self, store: ResultsStore, name: str):
        self.path = store.directory / "campaigns" / f"{name}.jsonl"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.session = uuid.uuid4().hex[:12]
        self.started = time.monotonic()

    def write(self, **entry) -> None:
        entry = {"session": self.session, "utc": datetime.now(UTC).isoformat(),
                 "elapsed_s": round(time.monotonic() - self.started, 3), **entry}
        line = (json.dumps(entry, sort_keys=True) + "\n").encode("utf-8")
        with self.path.open("a+b") as stream:
            end = stream.seek(0, 2)
            if end:
                # a session killed in the middle of a line left it unterminated: start anew
                stream.seek(end - 1)
                if stream.read(1) != b"\n":
                    line = b"\n" + line
            stream.write(line)   # appended at the end whatever the read position
            stream.flush()

    def entries(self) -> list[dict]:
        """Every entry, in order; a line that is not JSON (cut by a kill) is left out."""
        return read_log(self.path)

    def recover(self, samples: list[CampaignSample], store: ResultsStore,
                label: Callable[[CampaignSample], int | str]) -> int:
        """Log the samples of this campaign that the store holds and the log lacks: a session
        killed after storing a sample and before logging it (or in the middle of its line).
        Their entries say ``recovered``: they count as samples, not in the rate (their
        session's time is unknown). Returns how many were added."""
        logged = {e.get("key") for e in self.entries() if e.get("event") == "sample"}
        added = 0
        for sample in samples:
            if sample.spec.key in logged:
                continue
            row = store.get(sample.spec.key)
            if row is None or row["campaign"] != sample.spec.campaign:
                continue
            self.write(event="sample", recovered=True, sample=label(sample), key=row["key"],
                       status=row["status"], worker_seconds=row["worker_seconds"],
                       stepping_seconds=row["stepping_seconds"])
            added += 1
        return added


def read_log(path) -> list[dict]:
    """The entries of a campaign log (JSON lines); a line that is not JSON, which only a kill
    in the middle of a write leaves, is left out."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        return []
    entries = []
    for line in lines:
        try:
            entries.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return entries


@dataclass
class CampaignProgress:
    """What a call of :func:`run_campaign` did."""

    planned: int
    already: int
    recorded: int = 0
    statuses: dict | None = None


def _record(store: ResultsStore, sample: CampaignSample, result: dict) -> RunRecord:
    """Store a worker's ``result`` for ``sample``.

    Raises
    ------
    CampaignError
        The worker keyed the run otherwise than this client: it ran other sources (edited
        while the campaign ran, or another checkout on a remote worker). Its run is stored
        under its own key (a run of those sources), but this campaign cannot count it: left
        unchecked, the client would wait for a key that never comes (a resumed campaign runs
        the sample again and again; a metamodel's confirmation run stays pending).
    """
    row = dict(result["row"])
    row.pop("trajectory", None)
    record = RunRecord(**row, trajectory="")
    trajectory = None
    if result.get("trajectory") is not None:
        trajectory = store.trajectory_dir / f".{record.key}.campaign.tmp.npz"
        trajectory.write_bytes(result["trajectory"])
    store.record(record, trajectory_file=trajectory, scene=sample.spec.scene)
    if trajectory is not None:
        trajectory.unlink(missing_ok=True)
    if record.key != sample.spec.key:
        raise CampaignError(f"sample {sample.index}", record.key,
                            f"the worker's run key differs from this client's "
                            f"{sample.spec.key}: the worker runs other sources (edited while "
                            "the campaign ran, or another checkout); run every worker and the "
                            "client from one state of the code")
    return record


def _lost_run(sample: CampaignSample, error: BaseException) -> dict:
    """The row of a sample whose Dask task failed (e.g. it killed its workers every time)."""
    ran = RanMessage(status=RunStatus.CRASHED.value,
                     message=f"Dask task failed: {type(error).__name__}: {error}")
    record = RunRecord.from_messages(sample.spec, ran, MeasuredMessage(), revision_info(),
                                     machine_info())
    return {"row": asdict(record), "trajectory": None}


def run_campaign(definition: CampaignDefinition, store: ResultsStore, *,
                 scheduler: str | None = None, workers: int = 2, progress: bool = False,
                 on_recorded: Callable[[int, RunRecord], None] | None = None,
                 runs_per_worker: int = MANY_RUNS_PER_WORKER) -> CampaignProgress:
    """Run every sample of ``definition`` not yet in ``store``.

    Parameters
    ----------
    scheduler : address of a running Dask scheduler (``tcp://host:8786``); None starts a
        LocalCluster of ``workers`` processes on this machine for this call.
    progress : show a progress bar (rate and time left) on stderr.
    on_recorded : called with (sample index, record) after each sample is stored.
    runs_per_worker : samples a Dask worker's run process serves before it is replaced (1: a
        fresh process per sample); a crashed or timed-out one always is.
    """
    return run_samples(definition, plan_samples(definition), store, scheduler=scheduler,
                       workers=workers, progress=progress, on_recorded=on_recorded,
                       runs_per_worker=runs_per_worker)


def run_samples(definition: CampaignDefinition, samples: list[CampaignSample],
                store: ResultsStore, *, scheduler: str | None = None, workers: int = 2,
                progress: bool = False,
                on_recorded: Callable[[int, RunRecord], None] | None = None,
                label: Callable[[CampaignSample], int | str] | None = None,
                runs_per_worker: int = MANY_RUNS_PER_WORKER) -> CampaignProgress:
    """Run the ``samples`` of ``definition`` not yet in ``store`` on Dask (see
    :func:`run_campaign`); ``label`` names a sample in the campaign's log (default: its
    index)."""
    from distributed import Client, as_completed  # lazily: only campaigns need Dask

    stored = store.keys()
    todo = [s for s in samples if s.spec.key not in stored]
    outcome = CampaignProgress(planned=len(samples), already=len(samples) - len(todo),
                               statuses={})
    log = CampaignLog(store, definition.name)
    name_of = label or (lambda sample: sample.index)
    log.recover([s for s in samples if s.spec.key in stored], store, name_of)
    if not todo:
        return outcome
    cluster = plugins = None
    if scheduler is None:
        cluster, plugins = local_cluster(workers)
        client = Client(cluster)
        for plugin in plugins:
            client.register_plugin(plugin)
    else:
        client = Client(scheduler)
    log.write(event="start", campaign=definition.name, design=definition.design,
              engine=definition.engine, pending=len(todo), already=outcome.already,
              workers=len(client.scheduler_info().get("workers", {})),
              scheduler=scheduler or "LocalCluster")
    bar = None
    if progress:
        from tqdm import tqdm  # lazily: a progress bar only when asked

        bar = tqdm(total=len(samples), initial=outcome.already, unit="sample",
                   desc=definition.name, file=sys.stderr, smoothing=0.05)
    try:
        by_future = {client.submit(execute_run, s.spec, runs_per_worker,
                                   key=f"{definition.name}-{s.index}-{s.spec.key}", pure=False): s
                     for s in todo}
        for future in as_completed(by_future):
            sample = by_future.pop(future)
            try:
                result = future.result()
            except Exception as error:  # noqa: BLE001 - a lost task is a recorded outcome
                result = _lost_run(sample, error)
            record = _record(store, sample, result)
            outcome.recorded += 1
            outcome.statuses[record.status] = outcome.statuses.get(record.status, 0) + 1
            log.write(event="sample", sample=name_of(sample),
                      key=record.key, status=record.status,
                      worker_seconds=record.worker_seconds,
                      stepping_seconds=record.stepping_seconds)
            if bar is not None:
                bar.update(1)
            if on_recorded is not None:
                on_recorded(sample.index, record)
    finally:
        if bar is not None:
            bar.close()
        client.close()
        if cluster is not None:
            cluster.close()
    return outcome
