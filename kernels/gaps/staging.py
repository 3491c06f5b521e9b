"""Staging of the contacts a kernel finds: each in the ``out_frame`` slot of that contact (row 0:
the normal, row 1: the point on A, row [2, 0]: the gap), expanded into gaps, both points and
frames by :mod:`.dispatch`."""

from __future__ import annotations

from clearbench.kernels.jit import njit


@njit(cache=True, inline="always")
def stage_contact(stage, index, gap, point_a, normal):
    """Stage one contact in ``stage[index]`` (the out_frame slot): normal, point on A, gap."""
    for i in range(3):
        stage[index, 0, i] = normal[i]
        stage[index, 1, i] = point_a[i]
    stage[index, 2, 0] = gap


@njit(cache=True, inline="always")
def copy_staged(stage, source, target):
    """Move the staged contact of slot ``source`` to slot ``target`` (compaction)."""
    for i in range(3):
        for j in range(3):
            stage[target, i, j] = stage[source, i, j]


@njit(cache=True, inline="always")
def within_depth(depth, stage, k):
    """False if the staged contact ``k`` lies deeper than ``depth`` (> 0; 0: no bound)."""
    return not (depth > 0.0 and stage[k, 2, 0] < -depth)


@njit(cache=True, inline="always")
def copy_staged_from(source_stage, target_stage, target):
    """Copy the staged contact of ``source_stage[0]`` (a scratch stage) to slot ``target``."""
    for i in range(3):
        for j in range(3):
            target_stage[target, i, j] = source_stage[0, i, j]
