"""The C-60 across engines: one set of figures per stored run of ``c60-on`` or ``c60-trip``,
whatever engine made it, measured by the shared C-60 analysis (:mod:`.analysis`) and the
shared series (:mod:`clearbench.harness.measure.series`), never by an engine's own opinion.

Units are the scenes' mm-g-ms: lengths [mm], times [ms], forces [N]; wall times [s].
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field

import numpy as np

from clearbench.adapters.harness_defaults import C60_ON, C60_TRIP
from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.c60 import analysis
from clearbench.harness.measure import series as metrics
from clearbench.harness.measure.geometry_check import UNSEEN_FIGURE
from clearbench.harness.measure.verdicts import judge
from clearbench.scenarios.c60 import model
from clearbench.scenarios.library.c60 import SETTLED_AFTER
from clearbench.scenarios.scene import Scene

#: The two scenes of the cross-engine comparison (named where the engines declare their
#: ladders for them).
ON_SCENE = C60_ON
TRIP_SCENE = C60_TRIP
C60_SCENES = (ON_SCENE, TRIP_SCENE)
#: The engine every other is measured against (ratios of wall time, errors of FC-1).
REFERENCE_LABEL = "reference[default]"
#: The body whose creep says whether the latch holds (the hook rests on the tripping bar
#: through the latch contacts C4 and C5).
LATCH_BODY = "hook"


@dataclass(frozen=True)
class C60RunFigures:
    """What the cross-engine table says about one run.

    ``functional_conditions``: FC-1 [N] and FC-2..FC-6 [mm], each output averaged over the
    last 1 ms of the run (:func:`.analysis.settled_outputs`), c60-on only.
    ``latch_creep``: largest displacement of the hook from its position at SETTLED_AFTER (3 ms)
    to the end of the run [mm], c60-on only; ``latched``: the scene's ``sticks`` criterion
    (:func:`clearbench.harness.measure.verdicts.judge`, stated in ``latch_criterion``) holds
    for that creep. FC and latch figures are left out (NaN) for a run that ended before the
    settled window.
    ``strike``, ``release``, ``opening``: trip events [ms] (:func:`.analysis.trip_events`),
    c60-trip only (NaN where the event did not happen in the run).
    ``penetration_max`` [mm] and the contact pair where it is largest;
    ``penetration_beyond_rebuild`` [mm]: the largest penetration less its pair's rebuild
    overlap (:func:`~clearbench.harness.measure.series.penetration_beyond_rebuild`: the sag of
    an engine's ring of spheres is its approximation, not penetration); ``clearance_excess``:
    per joint of the mechanism (J1..J7 and the needle bearing S3), the largest penetration of
    its ring pairs [mm], which is the journal's eccentricity beyond its radial clearance (the
    rings are contacts offset by the clearance, see :mod:`clearbench.scenarios.c60.model`).
    ``instrument_penetration`` [mm]: the same largest penetration read by the independent
    geometry instrument when the run was measured (the run's figure
    ``instrument_penetration_max``, :mod:`clearbench.harness.measure.geometry_check`);
    ``unseen_penetration`` [mm] and ``unseen_time`` [ms]: how far it exceeds the kernel's
    figure where it does (0: nowhere), and ``unseen_reason`` the verdict's words (pair,
    time, both figures). NaN for a run measured before the instrument existed.
    ``stepping_seconds``: wall time of stepping for the whole run [s];
    ``stepping_seconds_per_step`` [s]; ``ratio_to_reference``: stepping wall time per
    simulated ms over the reference engine's at its finest step on the same scene and horizon
    (the run every error is measured against; NaN when it is missing).
    """

    key: str
    scene_name: str
    label: str
    engine_version: str
    time_step: float
    horizon: float
    status: str
    message: str
    functional_conditions: dict = field(default_factory=dict)
    latch_creep: float = math.nan
    latched: bool | None = None
    latch_criterion: str = ""
    strike: float = math.nan
    release: float = math.nan
    opening: float = math.nan
    penetration_max: float = math.nan
    penetration_pair: str = ""
    penetration_beyond_rebuild: float = math.nan
    clearance_excess: dict = field(default_factory=dict)
    instrument_penetration: float = math.nan
    unseen_penetration: float = math.nan
    unseen_time: float = math.nan
    unseen_reason: str = ""
    stepping_seconds: float = math.nan
    stepping_seconds_per_step: float = math.nan
    stepping_seconds_per_simulated_ms: float = math.nan
    simulated_until: float = math.nan
    ratio_to_reference: float = math.nan
    problem: str = ""

    @property
    def fc1(self) -> float:
        return self.functional_conditions.get("FC-1", math.nan)

    @property
    def worst_joint(self) -> tuple[str, float]:
        """(joint, excess [mm]) of the joint whose clearance is exceeded most."""
        if not self.clearance_excess:
            return "", math.nan
        name = max(self.clearance_excess, key=self.clearance_excess.get)
        return name, self.clearance_excess[name]


#: A contact pair of a joint's rings is named ``<bodies>_<joint>_<ring>`` (``Rod_hook_J6_bot``).
JOINT_IN_NAME = re.compile(r"_(J\d|S\d)(?:_|$)")


def joint_excess(scene: Scene, depth: np.ndarray) -> dict[str, float]:
    """Per joint, the largest penetration [mm] of its ring pairs over the run.

    ``depth``: (T, P) penetration of the scene's expanded contact pairs (series.penetration).
    """
    out: dict[str, float] = {}
    for column, contact in enumerate(scene.expanded.contacts):
        match = JOINT_IN_NAME.search(contact.name)
        if match:
            worst = float(np.max(depth[:, column]))
            out[match.group(1)] = max(out.get(match.group(1), 0.0), worst)
    return dict(sorted(out.items()))


def trajectory_figures(scene: Scene, trajectory: Trajectory) -> dict:
    """The C-60 figures of one trajectory (keys of :class:`C60RunFigures`).

    A figure the trajectory cannot give (too short, a scene without the output) is NaN and the
    reason is returned under ``problem``."""
    out: dict = {"simulated_until": float(trajectory.times[-1]) if len(trajectory.times)
                 else math.nan}
    if len(trajectory.times) < 2:
        out["problem"] = "fewer than 2 recorded samples"
        return out
    depth = metrics.penetration(scene, trajectory)
    if depth.size:
        worst = np.unravel_index(int(np.argmax(depth)), depth.shape)
        out["penetration_max"] = float(depth[worst])
        out["penetration_pair"] = scene.expanded.contacts[worst[1]].name \
            if len(scene.expanded.contacts) == depth.shape[1] else ""
        out["penetration_beyond_rebuild"] = float(np.max(
            metrics.penetration_beyond_rebuild(scene, trajectory, depth)))
        out["clearance_excess"] = joint_excess(scene, depth)
    problems = []
    if scene.name == ON_SCENE:
        if trajectory.times[-1] > SETTLED_AFTER:
            settled = analysis.settled_outputs(scene, trajectory)
            out["functional_conditions"] = {fc: settled.get(output, math.nan) for fc, (output, _)
                                            in model.FUNCTIONAL_CONDITIONS.items()}
            creep = metrics.stiction(scene, trajectory, LATCH_BODY, SETTLED_AFTER).displacement
            out["latch_creep"] = creep
            out["latched"], out["latch_criterion"] = judge(scene, "sticks", LATCH_BODY,
                                                            {"displacement": creep})
        else:
            problems.append(f"ended at {trajectory.times[-1]:.3g} ms, before the settled "
                            f"window ({SETTLED_AFTER} ms on)")
    if scene.name == TRIP_SCENE:
        try:
            events = analysis.trip_events(scene, trajectory)
        except (ValueError, IndexError) as error:  # a run without C7 or contact forces
            problems.append(f"trip events not measurable: {error}")
        else:
            out.update(strike=events.strike, release=events.release, opening=events.opening)
    if problems:
        out["problem"] = "; ".join(problems)
    return out


def run_figures(row: dict, scene: Scene | None, trajectory: Trajectory | None,
                reference_rate: float = math.nan) -> C60RunFigures:
    """Figures of one store row (a dict of :meth:`ResultsStore.get` or a DataFrame row).

    ``reference_rate``: the reference engine's stepping wall time per simulated ms at its
    finest step on the same scene and horizon [s/ms] (NaN when not run)."""
    rate = float(row.get("stepping_seconds_per_simulated_second", math.nan))
    figures = json.loads(row.get("metrics") or "{}")
    unseen = float(figures.get(UNSEEN_FIGURE, math.nan))
    values = dict(
        key=row["key"], scene_name=row["scene_name"],
        label=row.get("label") or f"{row['engine']}[{row['preset']}]",
        engine_version=str(row.get("engine_version") or ""),
        time_step=float(row["time_step"]), horizon=float(row["horizon"]),
        status=row["status"], message=row.get("message") or "",
        stepping_seconds=float(row.get("stepping_seconds", math.nan)),
        stepping_seconds_per_step=float(row.get("stepping_seconds_per_step", math.nan)),
        stepping_seconds_per_simulated_ms=rate,
        ratio_to_reference=rate / reference_rate if reference_rate > 0 else math.nan,
        instrument_penetration=float(figures.get("instrument_penetration_max", math.nan)),
        unseen_penetration=unseen,
        unseen_time=float(figures.get(f"{UNSEEN_FIGURE}_time", math.nan)),
        unseen_reason=(row.get("verdict_reason") or "") if unseen > 0 else "")
    if scene is not None and trajectory is not None:
        values.update(trajectory_figures(scene, trajectory))
    elif row["status"] in ("ok", "diverged"):
        values["problem"] = "no trajectory in the store"
    return C60RunFigures(**values)


def c60_rows(frame):
    """The rows of a store DataFrame that belong to the C-60 comparison."""
    return frame[frame["scene_name"].isin(C60_SCENES)]


def collect(store, frame=None) -> list[C60RunFigures]:
    """Figures of every stored run of c60-on and c60-trip, ordered by scene, engine, step."""
    frame = store.dataframe(expand_metrics=False) if frame is None else frame
    rows = c60_rows(frame)
    if not len(rows):
        return []
    rates = {}   # (scene, horizon) -> the reference's rate at its finest step
    fine = rows[(rows["label"] == REFERENCE_LABEL) & (rows["status"] == "ok")]
    for _, r in fine.sort_values("time_step", ascending=False).iterrows():
        rates[(r["scene_name"], float(r["horizon"]))] = float(
            r["stepping_seconds_per_simulated_second"])
    out = []
    scenes: dict[str, Scene | None] = {}
    for _, series in rows.sort_values(["scene_name", "label", "time_step"]).iterrows():
        row = series.to_dict()
        if row["scene_hash"] not in scenes:
            scenes[row["scene_hash"]] = store.scene(row["scene_hash"])
        scene = scenes[row["scene_hash"]]
        trajectory = store.load_trajectory(row["key"]) if row.get("trajectory") else None
        if trajectory is not None and scene is not None \
                and trajectory.scene_hash != scene.content_hash:
            trajectory = None
        reference = rates.get((row["scene_name"], float(row["horizon"])), math.nan)
        out.append(run_figures(row, scene, trajectory, reference))
    return out


def capability_reasons(frame) -> dict[str, str]:
    """Engine label -> why it could not run the C-60 (from its unsupported runs' messages)."""
    reasons = {}
    for _, row in c60_rows(frame).iterrows():
        if row["status"] == "unsupported":
            reasons.setdefault(row["label"], row["message"] or "unsupported")
    return reasons
