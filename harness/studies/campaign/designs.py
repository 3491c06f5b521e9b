"""Sample inputs of a campaign: sample i depends only on (seed, design, i).

A resumed or extended campaign therefore draws the same values for the samples it already has:
``samples = 2000`` after ``samples = 1000`` adds samples 1000..1999 and keeps the first 1000.

- ``monte-carlo``: sample i uses its own pseudo-random stream, numpy's PCG64 seeded with
  ``(seed, i)``: independent uniform numbers u in [0, 1)^d.
- ``sobol``: point i of the scrambled Sobol' sequence of dimension d (scipy.stats.qmc, the
  scrambling drawn from ``seed``). Its points fill [0, 1)^d evenly, so means and variances
  converge faster than with pseudo-random points (balance is best at powers of two).
- ``corners``: the 2^d combinations of the inputs' bounds (the study's worst cases, Figure 14),
  corner i taking input k at its upper bound when bit k of i is set.
- ``lhs`` (metamodel campaigns): block b = i // B of B points (B the metamodel's batch) is a
  Latin hypercube of its own, drawn from ``(seed, b)``: each batch stratifies every input, and
  point i depends on (seed, B, i) only, so an extended campaign keeps its earlier batches.

Uniform numbers map to each input's law by its inverse distribution function: the normal law
truncated to [lower, upper] (scipy.stats.truncnorm), or the uniform law on [lower, upper].
"""

from __future__ import annotations

import numpy as np
from scipy.stats import qmc, truncnorm

from clearbench.harness.studies.campaign.definition import CampaignDefinition, InputLaw


def unit_points(design: str, seed: int, dimension: int, start: int, count: int,
                block: int = 1) -> np.ndarray:
    """Points ``start .. start + count - 1`` of a design in [0, 1]^d, shape (count, d).

    For ``corners`` the points are 0 or 1 (lower or upper bound); ``block`` is the number of
    points of each Latin hypercube of the ``lhs`` design.
    """
    if count <= 0:
        return np.zeros((0, dimension))
    if design == "monte-carlo":
        return np.array([np.random.Generator(np.random.PCG64([seed, index])).random(dimension)
                         for index in range(start, start + count)])
    if design == "sobol":
        sampler = qmc.Sobol(dimension, scramble=True, seed=seed)
        if start:
            sampler.fast_forward(start)
        return sampler.random(count)
    if design == "lhs":
        first, last = start // block, (start + count - 1) // block
        blocks = [qmc.LatinHypercube(dimension, seed=np.random.default_rng([seed, b]))
                  .random(block) for b in range(first, last + 1)]
        return np.vstack(blocks)[start - first * block:start - first * block + count]
    if design == "corners":
        indices = np.arange(start, start + count)[:, None]
        return ((indices >> np.arange(dimension)[None, :]) & 1).astype(float)
    raise ValueError(f"unknown design {design!r}")


def to_law(law: InputLaw, u: np.ndarray) -> np.ndarray:
    """Map uniform numbers ``u`` (n,) in [0, 1] to values of ``law`` (n,) [its unit]."""
    if law.law == "uniform":
        return law.lower + u * (law.upper - law.lower)
    a = (law.lower - law.mean) / law.sigma
    b = (law.upper - law.mean) / law.sigma
    return truncnorm.ppf(u, a, b, loc=law.mean, scale=law.sigma)


def sample_inputs(definition: CampaignDefinition, start: int = 0,
                  count: int | None = None) -> np.ndarray:
    """Input values of samples ``start .. start + count - 1``, shape (count, d), in the order
    of ``definition.inputs`` [each input's unit]. ``count`` defaults to the rest of the
    campaign's samples."""
    if count is None:
        count = definition.samples - start
    u = unit_points(definition.design, definition.seed, definition.dimension, start, count,
                    definition.block)
    return np.column_stack([to_law(law, u[:, k]) for k, law in enumerate(definition.inputs)]) \
        if count > 0 else np.zeros((0, definition.dimension))


def scene_parameters(definition: CampaignDefinition, values: np.ndarray) -> dict:
    """Factory parameters of one sample: the fixed ``scene_parameters`` with each input's
    value set at its (dotted) parameter path, e.g. ``clearances.J1`` -> {"clearances": {"J1":
    value}}. Values are plain floats (run keys hash their JSON)."""
    parameters = {key: (dict(value) if isinstance(value, dict) else value)
                  for key, value in definition.scene_parameters.items()}
    for law, value in zip(definition.inputs, values, strict=True):
        head, _, rest = law.parameter.partition(".")
        if not rest:
            parameters[head] = float(value)
            continue
        target = parameters.setdefault(head, {})
        for part in rest.split(".")[:-1]:
            target = target.setdefault(part, {})
        target[rest.split(".")[-1]] = float(value)
    return parameters
