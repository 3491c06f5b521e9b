"""Measurement of a run: what the harness computes from a trajectory and its scene, never
trusting an engine's own report. Dependencies point down this list:

- :mod:`.series`: per-sample metric kernels, ``(scene, trajectory) -> array over the samples``
  in the scene's units (gaps, penetration, clearance eccentricity, joint violation, energy,
  named outputs), and the scene scales they are judged against (body and shape sizes, energy
  scale);
- :mod:`.expectation_figures`: the figures of each expectation of the scene (apex errors,
  creep, period error, ...), one handler per expectation kind; figures only, no pass/fail;
- :mod:`.verdicts`: the harness's pass/fail criterion of each expectation kind, and which
  expectation figure is a run's analytic error;
- :mod:`.figures`: the per-run figures stored with every run (maxima of the series, every
  expectation figure as ``EXPECTATION.FIGURE``, the headline ``error``, solver statistics)
  and the run's verdict (ok, or diverged with the reason);
- :mod:`.headline`: which of those figures summarise a scene in the CLI tables, the stability
  suite and the report, with their labels.

How to add a metric
-------------------
1. Compute it over the samples in :mod:`.series`: a function ``(scene, trajectory)`` returning
   an array in the scene's units, with a numpydoc docstring giving its shape and unit.
2. Make it a per-run figure in :mod:`.figures`: ``out.put("name", value)`` in the group it
   belongs to (drift, stiction, energy, escape), a line in the module docstring's table, and a
   reason in ``reasons`` if a value of it means the run diverged.
3. If it measures an expectation (a new expectation kind is declared in
   :data:`clearbench.scenarios.expectations.EXPECTATION_KINDS`), add a handler to ``_HANDLERS`` in
   :mod:`.expectation_figures` and its pass/fail criterion to :func:`.verdicts.judge` (and to
   :data:`.verdicts.ANALYTIC_ERROR` if it is an error against an analytic solution).
4. To show it in tables and the report, give it a label in :data:`.headline.METRIC_LABELS`
   and, if it matters for some scenes, a place in :func:`.headline.scene_metric_names`.

Stored runs keep the figures they were measured with; ``clearbench regress`` notes a new
figure as "new metrics not in the baseline" until the baseline is updated (``--update``).
"""
