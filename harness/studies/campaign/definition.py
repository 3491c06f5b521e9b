"""A tolerance campaign as written in its TOML file, validated before any engine runs.

A campaign draws some parameters of a registered scene factory from statistical laws, runs the
scene once per sample in one engine, and summarises named outputs of every run (e.g. the mean of
the C-60's FC-1 over the last millisecond) against specification limits. The file format::

    name = "c60-paper"              # campaign name (letters, digits, - and _)
    description = "..."
    scene = "c60-on"                # a registered scene factory
    engine = "reference"            # ENGINE or ENGINE[PRESET]
    design = "sobol"                # "monte-carlo", "sobol" or "corners"
    samples = 1024
    seed = 2018
    record_every = 10               # steps between recorded samples (default 1)
    # time_step, horizon: optional, in the scene's time unit; timeout [s] per run
    [scene_parameters]              # fixed factory parameters (a named variant)
    handle_spring_arm = "source"

    [[inputs]]                      # one per random parameter
    name = "J1"
    parameter = "clearances.J1"     # factory parameter, dotted into a mapping parameter
    unit = "mm"                     # the scene's unit of that parameter (for the report)
    law = "normal"                  # "normal" (bounded to [lower, upper]) or "uniform"
    mean = 0.07
    sigma = 0.0175
    lower = 0.01
    upper = 0.13

    [[outputs]]                     # one per collected output
    name = "FC-1"
    output = "FC1_contact_force"    # a named output of the scene
    statistic = "mean"              # "mean", "min", "max" over the window, or "final"
    window = 1.0                    # the last `window` scene time units of the run
    unit = "N"
    lower_limit = 9.0               # specification limits (optional: omit when unpublished)
    upper_limit = 16.0
    limits_source = "paper, Section 4.2"
    paper = { mean = 13.66, sigma = 0.239, source = "Fig. 16(a)" }   # optional

Every error names the field (``inputs[2].sigma``) and the value, as the scene files do.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from clearbench.harness.run.engine_choice import RunInputError

#: Sampling designs. "monte-carlo": independent pseudo-random draws (the study's method);
#: "sobol": scrambled Sobol' points (quasi-Monte Carlo, scipy.stats.qmc); "corners": every
#: combination of the inputs' bounds (the study's worst-case analysis, Figure 14); "lhs":
#: Latin hypercubes of one metamodel batch each (metamodel campaigns only).
DESIGNS = ("monte-carlo", "sobol", "corners", "lhs")
#: What a campaign computes: "sampling" (statistics of the samples themselves) or "metamodel"
#: (a metamodel fitted on the samples, added in batches until its targets are met:
#: :mod:`clearbench.harness.studies.campaign.metamodel`).
METHODS = ("sampling", "metamodel")
#: Metamodels a metamodel campaign may choose from by validation.
METAMODELS = ("chaos", "kriging")
#: Interval targets of a metamodel campaign: half-widths of the 95 % intervals.
TARGETS = ("mean", "sigma", "cpk", "s1", "st")
LAWS = ("normal", "uniform")
STATISTICS = ("mean", "min", "max", "final")
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
_TOP_KEYS = {"name", "description", "scene", "engine", "design", "samples", "seed",
             "record_every", "time_step", "horizon", "timeout", "scene_parameters", "inputs",
             "outputs", "method", "metamodel"}
_METAMODEL_KEYS = {"initial", "batch", "candidates", "validation", "folds", "q2", "targets",
                   "bootstrap", "max_degree", "confirmation_runs"}
_INPUT_KEYS = {"name", "parameter", "unit", "law", "mean", "sigma", "lower", "upper"}
_OUTPUT_KEYS = {"name", "output", "statistic", "window", "unit", "lower_limit", "upper_limit",
                "limits_source", "paper"}


class CampaignError(RunInputError):
    """A campaign file holds a bad value: names the field (``inputs[2].sigma``) and the value,
    like every input error of a run."""


@dataclass(frozen=True)
class InputLaw:
    """A random factory parameter and its law (values in the scene's units).

    ``normal``: N(mean, sigma) bounded to [lower, upper] (the law truncated there, as the
    study's draws are); ``uniform``: U(lower, upper) (mean and sigma unused).
    """

    name: str
    parameter: str
    law: str
    lower: float
    upper: float
    mean: float = math.nan
    sigma: float = math.nan
    unit: str = ""


@dataclass(frozen=True)
class PaperFigures:
    """The published mean and standard deviation of an output, with where they come from."""

    mean: float
    sigma: float
    source: str = ""


@dataclass(frozen=True)
class OutputSpec:
    """How to collect one output from a run, and its specification limits.

    The value of a run is ``statistic`` of the scene output ``output`` over the last ``window``
    scene time units (``final``: the last sample). Limits are optional: without both, the
    capability indices are not computed and the report says the limits are not published.
    """

    name: str
    output: str
    statistic: str = "mean"
    window: float = 0.0
    unit: str = ""
    lower_limit: float | None = None
    upper_limit: float | None = None
    limits_source: str = ""
    paper: PaperFigures | None = None

    @property
    def has_limits(self) -> bool:
        return self.lower_limit is not None and self.upper_limit is not None


@dataclass(frozen=True)
class MetamodelSettings:
    """How a metamodel campaign fits, validates and stops (the ``[metamodel]`` table).

    ``initial`` design runs first, then ``batch`` more at a time until every output's Q2 is
    at least ``q2`` and every interval target is met, or the campaign's ``samples`` (the run
    budget) are used. ``targets`` maps ``mean`` and ``sigma`` to a 95 % half-width in units of
    the output's sigma, ``cpk``, ``s1`` and ``st`` to an absolute half-width. Q2 is estimated
    by ``validation``: ``"k-fold"`` with ``folds`` folds, or ``"leave-one-out"``.
    ``confirmation_runs`` true runs check each rare-event estimate near its most probable
    failure point.
    """

    initial: int = 64
    batch: int = 64
    candidates: tuple[str, ...] = METAMODELS
    validation: str = "k-fold"
    folds: int = 5
    q2: float = 0.95
    targets: Mapping = field(default_factory=dict)
    bootstrap: int = 100
    max_degree: int = 4
    confirmation_runs: int = 3


@dataclass(frozen=True)
class CampaignDefinition:
    """A validated campaign (see the module docstring for the file format)."""

    name: str
    scene: str
    engine: str
    design: str
    samples: int
    seed: int
    inputs: tuple[InputLaw, ...]
    outputs: tuple[OutputSpec, ...]
    description: str = ""
    scene_parameters: Mapping = field(default_factory=dict)
    record_every: int = 1
    time_step: float | None = None
    horizon: float | None = None
    timeout: float | None = None
    source: str = ""
    method: str = "sampling"
    metamodel: MetamodelSettings | None = None
    raw: Mapping = field(default_factory=dict, repr=False, compare=False)

    @property
    def block(self) -> int:
        """Points per Latin hypercube of the ``lhs`` design (a metamodel batch)."""
        return self.metamodel.batch if self.metamodel is not None else self.samples

    @property
    def dimension(self) -> int:
        return len(self.inputs)


def _number(field_name: str, value, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise CampaignError(field_name, value, "must be a number")
    number = float(value)
    if not math.isfinite(number):
        raise CampaignError(field_name, value, "must be finite")
    if positive and not number > 0:
        raise CampaignError(field_name, value, "must be > 0")
    return number


def _integer(field_name: str, value, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise CampaignError(field_name, value, "must be an integer")
    if value < minimum:
        raise CampaignError(field_name, value, f"must be >= {minimum}")
    return value


def _text(field_name: str, value, pattern: re.Pattern | None = None) -> str:
    if not isinstance(value, str) or not value.strip():
        raise CampaignError(field_name, value, "must be a non-empty string")
    if pattern is not None and not pattern.match(value):
        raise CampaignError(field_name, value,
                            "use letters, digits, '-', '_' and '.' (starting with a letter or "
                            "digit)")
    return value


def _unknown_keys(prefix: str, table: Mapping, allowed: set[str]) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        where = f"{prefix}.{unknown[0]}" if prefix else unknown[0]
        raise CampaignError(where, table[unknown[0]],
                            f"unknown key; allowed: {', '.join(sorted(allowed))}")


def _input_law(index: int, table) -> InputLaw:
    where = f"inputs[{index}]"
    if not isinstance(table, Mapping):
        raise CampaignError(where, table, "must be a table")
    _unknown_keys(where, table, _INPUT_KEYS)
    for key in ("name", "parameter", "law", "lower", "upper"):
        if key not in table:
            raise CampaignError(f"{where}.{key}", None, "is required")
    name = _text(f"{where}.name", table["name"], _NAME)
    parameter = _text(f"{where}.parameter", table["parameter"])
    law = table["law"]
    if law not in LAWS:
        raise CampaignError(f"{where}.law", law, f"must be one of {', '.join(LAWS)}")
    lower = _number(f"{where}.lower", table["lower"])
    upper = _number(f"{where}.upper", table["upper"])
    if not upper > lower:
        raise CampaignError(f"{where}.upper", upper, f"must be > lower ({lower:g})")
    mean = sigma = math.nan
    if law == "normal":
        for key in ("mean", "sigma"):
            if key not in table:
                raise CampaignError(f"{where}.{key}", None, "is required for a normal law")
        mean = _number(f"{where}.mean", table["mean"])
        sigma = _number(f"{where}.sigma", table["sigma"], positive=True)
        if not lower <= mean <= upper:
            raise CampaignError(f"{where}.mean", mean,
                                f"must lie within the bounds [{lower:g}, {upper:g}]")
    unit = str(table.get("unit", ""))
    return InputLaw(name, parameter, law, lower, upper, mean, sigma, unit)


def _paper(where: str, table) -> PaperFigures | None:
    if table is None:
        return None
    if not isinstance(table, Mapping):
        raise CampaignError(where, table, "must be a table {mean, sigma, source}")
    _unknown_keys(where, table, {"mean", "sigma", "source"})
    for key in ("mean", "sigma"):
        if key not in table:
            raise CampaignError(f"{where}.{key}", None, "is required")
    return PaperFigures(_number(f"{where}.mean", table["mean"]),
                        _number(f"{where}.sigma", table["sigma"], positive=True),
                        str(table.get("source", "")))


def _output_spec(index: int, table) -> OutputSpec:
    where = f"outputs[{index}]"
    if not isinstance(table, Mapping):
        raise CampaignError(where, table, "must be a table")
    _unknown_keys(where, table, _OUTPUT_KEYS)
    for key in ("name", "output"):
        if key not in table:
            raise CampaignError(f"{where}.{key}", None, "is required")
    name = _text(f"{where}.name", table["name"], _NAME)
    output = _text(f"{where}.output", table["output"])
    statistic = table.get("statistic", "mean")
    if statistic not in STATISTICS:
        raise CampaignError(f"{where}.statistic", statistic,
                            f"must be one of {', '.join(STATISTICS)}")
    window = 0.0
    if statistic != "final":
        if "window" not in table:
            raise CampaignError(f"{where}.window", None,
                                f"is required for the statistic {statistic!r}")
        window = _number(f"{where}.window", table["window"], positive=True)
    lower = upper = None
    if "lower_limit" in table:
        lower = _number(f"{where}.lower_limit", table["lower_limit"])
    if "upper_limit" in table:
        upper = _number(f"{where}.upper_limit", table["upper_limit"])
    if (lower is None) != (upper is None):
        missing = "upper_limit" if upper is None else "lower_limit"
        raise CampaignError(f"{where}.{missing}", None,
                            "give both limits or neither (capability needs both)")
    if lower is not None and not upper > lower:
        raise CampaignError(f"{where}.upper_limit", upper, f"must be > lower_limit ({lower:g})")
    return OutputSpec(name, output, statistic, window, str(table.get("unit", "")), lower, upper,
                      str(table.get("limits_source", "")), _paper(f"{where}.paper",
                                                                  table.get("paper")))


def _metamodel_settings(table, samples: int, design: str) -> MetamodelSettings:
    where = "metamodel"
    if not isinstance(table, Mapping):
        raise CampaignError(where, table, "must be a table")
    _unknown_keys(where, table, _METAMODEL_KEYS)
    batch = _integer(f"{where}.batch", table.get("batch", min(64, samples)), 1)
    initial = _integer(f"{where}.initial", table.get("initial", batch), 2)
    if initial > samples:
        raise CampaignError(f"{where}.initial", initial,
                            f"must be <= samples ({samples}), the run budget")
    if design == "lhs" and initial % batch:
        raise CampaignError(f"{where}.initial", initial,
                            f"the lhs design needs a multiple of batch ({batch})")
    candidates = table.get("candidates", list(METAMODELS))
    if (not isinstance(candidates, list) or not candidates
            or any(c not in METAMODELS for c in candidates)):
        raise CampaignError(f"{where}.candidates", candidates,
                            f"must be a non-empty list of {', '.join(METAMODELS)}")
    validation = table.get("validation", "k-fold")
    if validation not in ("k-fold", "leave-one-out"):
        raise CampaignError(f"{where}.validation", validation,
                            "must be 'k-fold' or 'leave-one-out'")
    folds = _integer(f"{where}.folds", table.get("folds", 5), 2)
    q2 = _number(f"{where}.q2", table.get("q2", 0.95))
    if not 0 < q2 < 1:
        raise CampaignError(f"{where}.q2", q2, "must lie in (0, 1)")
    targets = table.get("targets", {})
    if not isinstance(targets, Mapping):
        raise CampaignError(f"{where}.targets", targets, "must be a table")
    _unknown_keys(f"{where}.targets", targets, set(TARGETS))
    targets = {key: _number(f"{where}.targets.{key}", value, positive=True)
               for key, value in targets.items()}
    return MetamodelSettings(
        initial=initial, batch=batch, candidates=tuple(candidates), validation=validation,
        folds=folds, q2=q2, targets=targets,
        bootstrap=_integer(f"{where}.bootstrap", table.get("bootstrap", 100), 10),
        max_degree=_integer(f"{where}.max_degree", table.get("max_degree", 4), 1),
        confirmation_runs=_integer(f"{where}.confirmation_runs",
                                   table.get("confirmation_runs", 3), 0))


def _unique(kind: str, names: list[str]) -> None:
    seen = set()
    for index, name in enumerate(names):
        if name in seen:
            raise CampaignError(f"{kind}[{index}].name", name, "is used twice")
        seen.add(name)


def parse_campaign(data: Mapping, source: str = "") -> CampaignDefinition:
    """Validate a campaign given as a plain mapping (the parsed TOML).

    Raises
    ------
    CampaignError
        Naming the first field at fault and its value.
    """
    if not isinstance(data, Mapping):
        raise CampaignError("campaign", data, "must be a table")
    _unknown_keys("", data, _TOP_KEYS)
    for key in ("name", "scene", "engine", "design", "samples", "seed", "inputs", "outputs"):
        if key not in data:
            raise CampaignError(key, None, "is required")
    name = _text("name", data["name"], _NAME)
    scene = _text("scene", data["scene"])
    engine = _text("engine", data["engine"])
    design = data["design"]
    if design not in DESIGNS:
        raise CampaignError("design", design, f"must be one of {', '.join(DESIGNS)}")
    samples = _integer("samples", data["samples"], 1)
    seed = _integer("seed", data["seed"], 0)
    raw_inputs, raw_outputs = data["inputs"], data["outputs"]
    if not isinstance(raw_inputs, list) or not raw_inputs:
        raise CampaignError("inputs", raw_inputs, "must be a non-empty array of tables")
    if not isinstance(raw_outputs, list) or not raw_outputs:
        raise CampaignError("outputs", raw_outputs, "must be a non-empty array of tables")
    inputs = tuple(_input_law(i, table) for i, table in enumerate(raw_inputs))
    outputs = tuple(_output_spec(i, table) for i, table in enumerate(raw_outputs))
    _unique("inputs", [law.name for law in inputs])
    _unique("outputs", [spec.name for spec in outputs])
    for index, law in enumerate(inputs):
        for other in inputs[:index]:
            if other.parameter == law.parameter:
                raise CampaignError(f"inputs[{index}].parameter", law.parameter,
                                    f"is already drawn by input {other.name!r}")
    method = data.get("method", "sampling")
    if method not in METHODS:
        raise CampaignError("method", method, f"must be one of {', '.join(METHODS)}")
    metamodel = None
    if method == "metamodel":
        if design not in ("sobol", "lhs", "monte-carlo"):
            raise CampaignError("design", design,
                                "a metamodel campaign needs sobol, lhs or monte-carlo")
        metamodel = _metamodel_settings(data.get("metamodel", {}), samples, design)
    elif "metamodel" in data:
        raise CampaignError("metamodel", data["metamodel"],
                            "only with method = \"metamodel\"")
    elif design == "lhs":
        raise CampaignError("design", design,
                            "lhs only with method = \"metamodel\" (its point i depends on the "
                            "batch size; use sobol to extend a sampling campaign)")
    if design == "corners" and samples > 2 ** len(inputs):
        raise CampaignError("samples", samples,
                            f"the corners design has 2^{len(inputs)} = {2 ** len(inputs)} points")
    scene_parameters = data.get("scene_parameters", {})
    if not isinstance(scene_parameters, Mapping):
        raise CampaignError("scene_parameters", scene_parameters, "must be a table")
    for index, law in enumerate(inputs):
        head = law.parameter.split(".", 1)[0]
        if law.parameter in scene_parameters or (
                "." not in law.parameter and head in scene_parameters):
            raise CampaignError(f"inputs[{index}].parameter", law.parameter,
                                "is also fixed in scene_parameters")
    record_every = _integer("record_every", data.get("record_every", 1), 1)
    time_step = horizon = timeout = None
    if "time_step" in data:
        time_step = _number("time_step", data["time_step"], positive=True)
    if "horizon" in data:
        horizon = _number("horizon", data["horizon"], positive=True)
    if "timeout" in data:
        timeout = _number("timeout", data["timeout"], positive=True)
    return CampaignDefinition(
        name=name, scene=scene, engine=engine, design=design, samples=samples, seed=seed,
        inputs=inputs, outputs=outputs, description=str(data.get("description", "")),
        scene_parameters=dict(scene_parameters), record_every=record_every,
        time_step=time_step, horizon=horizon, timeout=timeout, source=source, method=method,
        metamodel=metamodel, raw=dict(data))


#: Campaign files shipped with clearbench, by name (``clearbench campaign run c60-paper``).
SHIPPED = {path.stem: path for path in sorted(Path(__file__).parent.glob("*.toml"))}


def load_campaign(path_or_name: str | Path) -> CampaignDefinition:
    """Read and validate a campaign file, or a shipped campaign by name.

    Raises
    ------
    CampaignError
        Missing or unreadable file (field ``file``), TOML syntax, or a bad value.
    """
    text = str(path_or_name)
    path = SHIPPED.get(text, Path(text))
    if not path.is_file():
        raise CampaignError("file", text, "no such campaign file; shipped campaigns: "
                            + ", ".join(SHIPPED))
    try:
        raw = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as error:
        raise CampaignError("file", text, f"not UTF-8 text ({error.reason} at byte "
                            f"{error.start})") from None
    try:
        data = tomllib.loads(raw)
    except tomllib.TOMLDecodeError as error:
        raise CampaignError("file", text, f"invalid TOML: {error}") from None
    return parse_campaign(data, source=str(path))


def with_overrides(definition: CampaignDefinition, **changes) -> CampaignDefinition:
    """The definition with top-level keys of its file changed (``samples``, ``engine``,
    ``design``, ...; None leaves a key as it is), validated again as a whole."""
    data = {**definition.raw, **{key: value for key, value in changes.items()
                                 if value is not None}}
    return parse_campaign(data, source=definition.source)
