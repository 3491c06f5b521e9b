"""Measurement of a run: what the harness computes from a trajectory and its scene, never
trusting an engine's own report. Dependencies point down this list:

- :mod:`.series`: per-sample metric kernels, ``(scene, trajectory) -> array over the samples``
  in the scene's units (gaps, penetration, clearance eccentricity, joint violation, energy,
  named outputs), and the scene scales they are judged against (body and shape sizes, energy
  scale);
- :mod:`.quantities` and :mod:`.criteria`: the units of figures and the wording of a figure
  against its bound, the pieces every expectation kind is written with;
- :mod:`.kinds`: the expectation kinds, each one declared object (figure handler, units of
  its figures, criterion and its words, analytic-error figure, table columns) in one registry;
- :mod:`.expectation_figures`: the figures of each expectation of the scene (apex errors,
  creep, period error, ...) and of the implied checks, by their kinds' handlers; figures
  only, no pass/fail;
- :mod:`.verdicts`: the pass/fail of each expectation (its kind's criterion), a run's
  analytic error, and the verdict of a run;
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
3. If it measures an expectation, declare a kind in one module (:mod:`.kinds` says how):
   its scene side, figure handler, units, criterion, analytic-error figure and table
   columns in one :class:`~.kinds.MeasuredKind`, registered with one call.
4. To show it in tables and the report, give it a label in :data:`.headline.METRIC_LABELS`
   and, if it matters for some scenes, a place in :func:`.headline.scene_metric_names`.

Stored runs keep the figures they were measured with; ``clearbench regress`` notes a new
figure as "new metrics not in the baseline" until the baseline is updated (``--update``).
"""
